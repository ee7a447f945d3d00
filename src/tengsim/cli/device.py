"""``tengsim device``: the paper's dynamic cases (fig7, fig8), any configured device (run), load sweep, the device
a design describes (design).

A thin shell, argv -> plan -> files: the config file is read by :func:`tengsim.schema.read_config`, the options
gathered by :mod:`tengsim.cli.device_inputs`; :func:`tengsim.cases.device_plan.plan_device` checks them all,
:func:`tengsim.cases.device_run.run_device` runs the plan and :func:`~tengsim.cases.device_run.write_device` writes
it (imported when a case runs: ``import tengsim.cli.device`` imports no case).
``tengsim run FILE.toml`` with a [device] table calls :func:`run_config` with the whole file.
"""
from __future__ import annotations

import json
import sys

from tengsim.cli import device_inputs as given

SUMMARY = 'dynamic TENG output (paper Section 5)'  # its line in `tengsim --help`

PRECEDENCE = "A value given as a CLI option wins over the config file, which wins over the case's default."
CONFIG_HELP = ("TOML or JSON file with tables [device], [waveform], [run], [solver] (and [sweep] for sweep); "
               "`tengsim device fields` lists every key. " + PRECEDENCE)
DESCRIPTION = (
    "Open-circuit voltage, current and power of a contact-separation TENG (paper Section 5). "
    "Cases: fig7 and fig8 are the paper's devices, run is the [device] of --config as given, sweep is a "
    "load-resistance sweep, design is the device a `tengsim design` result describes (--area-from DIR/design.nc). "
    "A config file (--config, or `tengsim run FILE` with [run] case = ...) may hold "
    "[device] (DeviceParams fields, SI or with units), [waveform] (kind and its fields; without kind it "
    "changes the case's waveform), [run] (case, out, cycles, t_end, dt_out, quick), [solver] (method, rtol, "
    "atol, max_step) and [sweep] (r_min_ohm, r_max_ohm, points, steady). Every table given is used or "
    "refused by name; `tengsim device fields` lists every key with its unit and default. " + PRECEDENCE)
DESIGN_HELP = ("The device a design describes, in one step: `tengsim device design --area-from d1/design.nc "
               "--out dev.csv`. From the design it takes σ, ε_r, T, the rest gap d0 and A/S(P) (approach); what the "
               "design does not know (mass, stiffness, electrode area, load, waveform) comes from the options, the "
               "config's [device] and [waveform], or the paper's Fig. 8 device, and the run says which values were "
               "defaults. The waveform (default: a 2 Hz square wave pressing to the design's p_max) must stay inside "
               "the design's pressures. A design with viscoelastic cycles (`tengsim design ... --relaxation FILE`) "
               "drives the device with the contact's own A/S(t) at the waveform's frequency (within the cycles'; "
               "the summary's area_model says which A was used). " + CONFIG_HELP)
AREA_FROM_HELP = ("charged-area model from a result on file: a design result DIR/design.nc (or DIR) of "
                  "`tengsim design`, or a physical load-controlled `tengsim contact` result (.nc/.csv); the "
                  "approach branch (overrides [device] area)")


def register(subparsers) -> None:
    from tengsim.device.params import FORCE_MODELS, INITIAL_CHARGES

    p = subparsers.add_parser("device", help=SUMMARY, description=DESCRIPTION)
    sub = p.add_subparsers(dest="device_command", metavar="CASE")
    p.set_defaults(func=lambda args: (p.print_help(), 2)[1])

    def common(sp, default_cycles, sweep=False):
        sp.add_argument("--out", help=("output .csv (one row per load, .json sidecar)" if sweep else
                                        "output file: .csv (one row per time, .json sidecar) or .nc")
                        + "; overrides [run] out")
        sp.add_argument("--cycles", help=f"periods to run (overrides [run] cycles; default {default_cycles})")
        sp.add_argument("--dt", help="output time step in s or with a unit, e.g. 0.1ms (overrides [run] dt_out)")
        sp.add_argument("--config", default=None, help=CONFIG_HELP)
        sp.add_argument("--quiet", action="store_true", help="no progress or summary output")
        sp.add_argument("--area-from", metavar="DESIGN", help=AREA_FROM_HELP)
        if sweep:
            return
        sp.add_argument("--load-ohm", help="load R in ohm or with a unit, e.g. 10MOhm (0 = short, inf = open)")
        sp.add_argument("--damping", help="damping ratio zeta (default 0.7)")
        sp.add_argument("--force-model", choices=FORCE_MODELS, default=None, help="electrostatic force (default field)")
        sp.add_argument("--initial-charge", choices=INITIAL_CHARGES, default=None,
                        help="Q(0): zero (paper) or rest (V = 0, no start spike)")
        from tengsim.cli import device_field

        device_field.add_options(sp)

    f7 = sub.add_parser("fig7", help="flat device, 10 N 5 Hz square wave (Fig. 7)", description=CONFIG_HELP)
    common(f7, 5)
    f7.add_argument("--t-end", help="run length in s or with a unit (overrides [run] t_end; default cycles x period)")
    f7.set_defaults(func=lambda a: execute("fig7", given.read(a.config), given.options(a), a.quiet, a.config))
    f8 = sub.add_parser("fig8", help="group-A device, 10-150 kPa staircase at 2 Hz (Fig. 8)", description=CONFIG_HELP)
    common(f8, "all 15 steps")
    f8.add_argument("--quick", action="store_true", default=None,
                    help="quick (coarse) contact-engine area table (overrides [run] quick)")
    f8.set_defaults(func=lambda a: execute("fig8", given.read(a.config), given.options(a), a.quiet, a.config))
    rn = sub.add_parser("run", help="any device and waveform from --config", description=CONFIG_HELP)
    common(rn, 5)
    rn.add_argument("--t-end", help="run length in s or with a unit (overrides [run] t_end; default cycles x period)")
    rn.set_defaults(func=lambda a: execute("run", given.read(a.config), given.options(a), a.quiet, a.config))
    sw = sub.add_parser("sweep", help="load-resistance sweep of the Fig. 7 device (or --config)",
                        description=CONFIG_HELP)
    common(sw, 3, sweep=True)
    sw.add_argument("--r-min", help="smallest load in ohm or with a unit (overrides [sweep] r_min_ohm; default 1e3)")
    sw.add_argument("--r-max", help="largest load in ohm or with a unit (overrides [sweep] r_max_ohm; default 1e10)")
    sw.add_argument("--points", help="loads, log-spaced (overrides [sweep] points; default 15)")
    sw.set_defaults(func=lambda a: execute("sweep", given.read(a.config), given.options(a), a.quiet, a.config))
    dz = sub.add_parser("design", help="the device a design describes (σ, ε_r, T, rest gap, A/S(P) from "
                        "--area-from DIR/design.nc)", description=DESIGN_HELP)
    common(dz, 5)
    dz.add_argument("--t-end", help="run length in s or with a unit (overrides [run] t_end; default cycles x period)")
    dz.add_argument("--pressure", help="pressure while pressed, e.g. 20kPa (default: the design's p_max); inside the "
                                       "design's pressures")
    dz.add_argument("--frequency", help="square-wave frequency, e.g. 2Hz (default 2 Hz, the paper's Fig. 8)")
    dz.add_argument("--mass", help="moving plate mass, e.g. 13.45g (default: the paper's Fig. 8 device, 13.45 g)")
    dz.add_argument("--stiffness", help="spring stiffness, e.g. 5.12kN/m (default 5.12 kN/m, Fig. 8)")
    dz.add_argument("--electrode-area", help="electrode area S, e.g. 4cm2 (a bare number is m², as every bare "
                    "number is SI; default 4 cm², Fig. 8's)")
    dz.set_defaults(func=lambda a: execute("design", given.read(a.config), given.options(a), a.quiet, a.config))
    fl = sub.add_parser("fields", help="list every config table and key (from the dataclasses)")
    fl.set_defaults(func=_cmd_fields)


# --- argv -> plan -> run -> files ---

def execute(case: str, cfg: dict, cli: dict | None = None, quiet: bool = False, source: str | None = None) -> int:
    """Run device ``case`` (fig7, fig8, run, sweep, design) from config tables ``cfg`` and CLI values ``cli``:
    :func:`tengsim.cases.device_plan.plan_device`, :func:`tengsim.cases.device_run.run_device`, then
    :func:`~tengsim.cases.device_run.write_device`; the plan's and the run's lines go to stderr."""
    from tengsim.cases.device_plan import plan_device
    from tengsim.cases.device_run import LoadSweepRun, run_device, write_device

    plan = plan_device(case, cfg, cli, source, quiet)
    _say(plan.messages)
    run = run_device(plan)
    if isinstance(run, LoadSweepRun):
        where = write_device(run)
        _say(run.messages)
        if not quiet:
            sw, k_opt = run.sweep, run.optimum_row
            what = "largest mean power in the range (at its edge)" if sw.optimum_at_edge else "optimum load"
            print(f"{what}: R = {sw.optimum_ohm:.4g} ohm, "
                  + power_line({"peak_power_W": sw.peak_power_W[k_opt], "average_power_W": sw.optimum_power_W}))
            print(f"wrote {where}", file=sys.stderr)
        return 0
    _say(run.messages)
    where = write_device(run)
    if not quiet:
        print(json.dumps(run.summary, indent=1))
        line = power_line(run.summary)
        if line:
            print(line)
        print(f"wrote {where}", file=sys.stderr)
    return 0


def _say(lines) -> None:
    for line in lines:
        print(line, file=sys.stderr)


def power_line(summary: dict) -> str:
    """'power: peak 12.3 µW, mean 4.56 µW (W: 1.23e-05, 4.56e-06)' from a run's summary ('' if it has none)."""
    from tengsim.units import format_si

    peak, mean = summary.get("peak_power_W"), summary.get("average_power_W")
    if peak is None:
        return ""
    if mean is None:
        return f"power: peak {format_si(peak, 'W')} ({peak:.4g} W); mean: no settled cycle"
    return f"power: peak {format_si(peak, 'W')}, mean {format_si(mean, 'W')} (W: {peak:.4g}, {mean:.4g})"


def _cmd_fields(args) -> int:
    from tengsim.device.config import fields_help

    print(fields_help())
    return 0


def run_config(cfg_tables: dict, args) -> int:
    """``tengsim run FILE.toml`` with a [device] table: the file is a device config whose [run] names the
    case (fig7, fig8, run, sweep; default run) and the output (``out``); ``args.quiet`` is honoured."""
    from tengsim.device import config as dc

    source = str(getattr(args, "config", "") or "") or None
    dc.check_device_tables(cfg_tables, source or "config")
    run = cfg_tables.get("run", {})
    case = dc.RUN_TABLE.fields["case"].parse(run["case"], "[run] ") if isinstance(run, dict) and "case" in run \
        else "run"
    return execute(case, cfg_tables, {}, bool(getattr(args, "quiet", False)), source)


__all__ = ["register", "execute", "run_config", "PRECEDENCE"]
