"""``tengsim device``: the paper's dynamic cases (fig7, fig8), any configured device (run), load sweep, the device
a design describes (design).

A thin shell: the config tables are read by :func:`tengsim.schema.read_config` and typed by the schema
of :mod:`tengsim.device.config`; the paper's devices come from :mod:`tengsim.cases.paper`.
``tengsim run FILE.toml`` with a [device] table calls :func:`run_config` with the whole file.
"""
from __future__ import annotations

import dataclasses
import json
import sys
from pathlib import Path

from tengsim.cli import device_inputs as given
from tengsim.errors import TengsimError, require

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
DEFAULT_CYCLES = {"fig7": 5, "run": 5, "sweep": 3, "design": 5}
MAX_SWEEP_POINTS = 10_000
"""The most loads one sweep may hold (each is a multi-cycle device run)."""

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


# --- the one path every device run takes ---

def execute(case: str, cfg: dict, cli: dict | None = None, quiet: bool = False, source: str | None = None) -> int:
    """Run device ``case`` (fig7, fig8, run, sweep) from config tables ``cfg`` and CLI values ``cli``."""
    from tengsim.device import config as dc

    cli = cli or {}
    dc.check_device_tables(cfg, source or "config")
    cfg = given.area_beside(cfg, source)
    ignored = []  # keys of the other command (run <-> sweep) in a config that serves both
    if "sweep" in cfg and case != "sweep":
        if case != "run":
            raise TengsimError(f"[sweep] is used only by the sweep case, not {case}")
        ignored.append("[sweep]")
    run = {**dc.parse_run(cfg.get("run", {}), case, ignored), **given.typed(dc.RUN_TABLE, cli.get("run", {}))}
    if case == "sweep" and "load_ohm" in cfg.get("device", {}):
        ignored.append("[device] load_ohm")
        cfg = {**cfg, "device": {k: v for k, v in cfg["device"].items() if k != "load_ohm"}}
    if ignored and not quiet:
        other = "run" if case == "sweep" else "sweep"
        print(f"tengsim: note: the {case} does not use {', '.join(ignored)} (used by `tengsim device {other}`)",
              file=sys.stderr)
    dev_cli = given.typed(dc.DEVICE_TABLE, cli.get("device", {}))
    solver = dc.parse_solver(cfg.get("solver", {}))
    out = given.out_path(run, case)
    given.guard(out, cfg, cli, source)
    given.warn_unconverged(cfg, cli, quiet)
    if case == "sweep":
        return _sweep(cfg, cli, run, dev_cli, solver, out, quiet, source)
    designed = None
    if case == "design":
        designed = _designed(cfg, cli, dev_cli)
        params, wf = designed.params, designed.waveform
    else:
        params, wf = _device_and_waveform(case, cfg, dev_cli)
        params = _viscoelastic(case, cfg, cli, params, wf)
    from tengsim.device import simulate
    from tengsim.device.config import check_pressures

    if case == "fig8":
        from tengsim.cases.paper import fig8_area_table, fig8_summary

        n = len(wf.amplitudes_Pa)
        cycles = run.get("cycles", n)
        require(cycles <= n, f"cycles = {cycles} but the staircase has {n} steps (give at most {n})")
        wf = dataclasses.replace(wf, amplitudes_Pa=wf.amplitudes_Pa[:cycles])
        check_pressures(params.area, wf, wf.duration, _area_source(cfg, cli))
        _note_paper_device(case, cfg, dev_cli, quiet)  # after every check: an error stays one line
        if "area" not in cfg.get("device", {}) and "area" not in dev_cli:  # the slow engine: after every check
            params = params.replace(area=fig8_area_table(bool(run.get("quick", False))))
        res = simulate(params, wf, wf.duration, dt_out=run.get("dt_out", 1e-4), options=solver, progress=not quiet)
        summary = {"area_model": _area_model(params), **fig8_summary(res)}
    else:
        t_end = run.get("t_end")
        if t_end is None:
            per = wf.period or wf.duration
            require(per is not None, "give --t-end (or [run] t_end) for a waveform with no period")
            t_end = run.get("cycles", DEFAULT_CYCLES[case]) * per
        check_pressures(params.area, wf, t_end, _area_source(cfg, cli),
                        " (--pressure)" if designed is not None else "")
        if designed is not None and not quiet:  # after every check: an error stays one line
            for line in designed.lines():
                print(f"tengsim: {line}", file=sys.stderr)
        for line in (designed.warnings() if designed is not None else []):
            print(f"tengsim: warning: {line}", file=sys.stderr)
        _note_paper_device(case, cfg, dev_cli, quiet)
        res = simulate(params, wf, t_end, dt_out=run.get("dt_out"), options=solver, progress=not quiet)
        skip = 1 if (wf.period and t_end >= 2 * wf.period - 1e-12) else 0
        if designed is not None:
            from tengsim.design.device import rest_gap_voltage
            from tengsim.io import jsonable

            summary = jsonable({"area_model": designed.area_model, **res.summary(skip),
                                **rest_gap_voltage(designed, res), "designed_device": designed.provenance()})
        elif case == "fig7":
            from tengsim.cases.paper import fig7_summary

            summary = {"area_model": _area_model(params), **fig7_summary(res, skip)}
        else:
            from tengsim.io import jsonable

            summary = jsonable({"area_model": _area_model(params), **res.summary(skip)})
    from tengsim.cli import device_field

    summary = {**summary, **device_field.field_summary(params, res, cli.get("air_pressure_Pa"))}
    if not quiet and device_field.warning(summary):
        print(device_field.warning(summary), file=sys.stderr)
    return _write(res, out, summary, quiet, {"case": case, "config": cfg, "config_file": source})


def _device_and_waveform(case, cfg, dev_cli):
    """The case's device and waveform with the [device] and [waveform] tables and CLI values applied."""
    from tengsim.device import config as dc

    base_wf = None
    if case in ("fig7", "sweep"):
        from tengsim.cases.paper import fig7_params, fig7_waveform

        params = dc.parse_device(cfg.get("device", {}), fig7_params(), dev_cli)
        base_wf = fig7_waveform(area_m2=params.area_m2)
    elif case == "fig8":
        from tengsim.cases.paper import fig8_params, fig8_waveform
        from tengsim.device import ConstantArea

        params = dc.parse_device(cfg.get("device", {}), fig8_params(ConstantArea(1.0)), dev_cli)
        base_wf = fig8_waveform()
    else:
        require("device" in cfg, "device run needs a config with [device] and [waveform] (--config FILE)")
        params = dc.parse_device(cfg["device"], None, dev_cli)
        require("waveform" in cfg, "device run needs a [waveform] table in its config (kind = square, ...)")
    wf = dc.parse_waveform(cfg["waveform"], base_wf) if "waveform" in cfg else base_wf
    if case == "fig8":
        from tengsim.device import Staircase

        require(isinstance(wf, Staircase), f"fig8 needs [waveform] kind = 'staircase', got {wf.to_dict()['kind']!r} "
                "(use `tengsim device run` for other waveforms)")
    if case == "sweep":
        require(getattr(wf, "period", None) is not None, "a load sweep needs a periodic waveform")
    return params, wf


def _area_model(params) -> str:
    """The summary's ``area_model``: which A the device used (:func:`tengsim.device.params.area_model_label`)."""
    from tengsim.device.params import area_model_label

    return area_model_label(params.area)


def _viscoelastic(case, cfg, cli, params, wf):
    """``params`` with the viscoelastic A(t) of a design result with cycles given as the area (--area-from, [device]
    area), as `device design` takes it (:func:`tengsim.device.areas.area_cycle_for_waveform`): never its quasi-static
    A(P) in silence; a waveform that is none of its recorded presses is one line."""
    from tengsim.device.areas import area_cycle_for_waveform, design_visco_record

    raw = (cli or {}).get("device", {}).get("area") or (cfg.get("device") or {}).get("area")
    if not isinstance(raw, (str, Path)) or design_visco_record(raw) is None:
        return params
    rec = design_visco_record(raw)
    if case == "fig8":  # its staircase is no press a design records
        raise TengsimError(f"device fig8 --area-from {raw}: the design's viscoelastic cycles press to "
                           f"{rec['p_max_Pa'] / 1e3:.4g} kPa only, the staircase to {len(wf.amplitudes_Pa)} pressures: "
                           "run its square or sine press with `tengsim device design --area-from` (or `device run`), or "
                           "give a design without --relaxation for the quasi-static A(P)")
    cycle = area_cycle_for_waveform(raw, wf, float(params.area(rec["p_max_Pa"])),
                                    where=f"device {case} --area-from {raw}")
    return params.replace(area=cycle)


def _area_source(cfg, cli) -> str:
    """Where a run's area table came from, for its errors."""
    raw = (cli or {}).get("device", {}).get("area") or (cfg.get("device") or {}).get("area")
    return f"A/S(P) from {raw}" if isinstance(raw, str) else "the [device] area table"


def _designed(cfg, cli, dev_cli):
    """The designed device (:func:`tengsim.design.device.designed_device`) of ``device design``."""
    from tengsim.design.device import designed_device
    from tengsim.device import config as dc

    raw = cli.get("device", {}).get("area") or (cfg.get("device") or {}).get("area")
    require(isinstance(raw, str), "device design needs a design result: give --area-from DIR/design.nc (or [device] "
                                  "area = 'DIR/design.nc')")
    dev = {**dc.DEVICE_TABLE.parse({k: v for k, v in (cfg.get("device") or {}).items() if k != "area"},
                                   defaults=False), **{k: v for k, v in dev_cli.items() if k != "area"}}
    for opt in ("mass", "stiffness", "electrode_area"):
        key = given.OPTIONS[opt][1]
        if key in dev_cli and not dev_cli[key] > 0:
            raise TengsimError(f"--{opt.replace('_', '-')} must be > 0, got {cli['device'][key]!r}")
    wcli = given.typed(None, cli.get("waveform", {}))
    for opt in ("pressure", "frequency"):
        key = given.OPTIONS[opt][1]
        if key in wcli and not wcli[key] > 0:
            raise TengsimError(f"the {opt} must be > 0 {_unit_of(cli['waveform'][key], key)}, got "
                               f"{_as_given(cli['waveform'][key], key)}")
    return designed_device(raw, dev, cfg.get("waveform"), wcli.get("amplitude_Pa"), wcli.get("frequency_Hz"))


def _unit_of(raw, key: str) -> str:
    """The unit the user gave ``raw`` in ('-5kPa' → 'kPa'), or the key's SI unit for a bare number."""
    import re

    from tengsim.units import _NUM, _compact

    m = re.fullmatch(f"({_NUM})(.*)", _compact(raw)) if isinstance(raw, str) else None
    return m.group(2) if m and m.group(2) else key.rsplit("_", 1)[-1]


def _as_given(raw, key: str) -> str:
    """'-5 kPa' of '-5kPa': the value in the user's own unit."""
    import re

    from tengsim.units import _NUM, _compact

    m = re.match(_NUM, _compact(raw)) if isinstance(raw, str) else None
    return f"{m.group(0) if m else raw} {_unit_of(raw, key)}"


def _note_paper_device(case, cfg, dev_cli, quiet):
    """fig7/fig8/sweep with a design's area: the paper's device with the design's A/S, said once."""
    raw = (cfg.get("device") or {}).get("area")
    if quiet or case not in ("fig7", "fig8", "sweep") or not ("area" in dev_cli or isinstance(raw, str)):
        return
    print(f"tengsim: note: {case} is the paper's device (its σ, ε_r, T, rest gap, mass, spring and waveform) with "
          "this A/S(P); `tengsim device design --area-from DIR/design.nc` runs the device the design describes",
          file=sys.stderr)


def _write(result, out: Path, summary: dict, quiet: bool, provenance: dict) -> int:
    from tengsim.io import write_dataset, write_json

    if out.suffix.lower() == ".nc":
        ds = result.to_dataset()
        ds.attrs["summary"] = json.dumps(summary)
        ds.attrs["run"] = json.dumps(provenance, default=str)
        write_dataset(ds, out)
        where = f"{out}"
    else:
        result.write_csv(out)
        side = out.with_suffix(".json")
        write_json(side, {**result.header(), "summary": summary, "run": provenance})
        where = f"{out} (+ {side.name})"
    if not quiet:
        print(json.dumps(summary, indent=1))
        line = power_line(summary)
        if line:
            print(line)
        print(f"wrote {where}", file=sys.stderr)
    return 0


def power_line(summary: dict) -> str:
    """'power: peak 12.3 µW, mean 4.56 µW (W: 1.23e-05, 4.56e-06)' from a run's summary ('' if it has none)."""
    from tengsim.units import format_si

    peak, mean = summary.get("peak_power_W"), summary.get("average_power_W")
    if peak is None:
        return ""
    if mean is None:
        return f"power: peak {format_si(peak, 'W')} ({peak:.4g} W); mean: no settled cycle"
    return f"power: peak {format_si(peak, 'W')}, mean {format_si(mean, 'W')} (W: {peak:.4g}, {mean:.4g})"


def _sweep(cfg, cli, run, dev_cli, solver, out, quiet, source) -> int:
    import numpy as np

    from tengsim.device import config as dc
    from tengsim.device import resistance_sweep
    from tengsim.io import write_csv, write_json

    sw_cfg = {**dc.SWEEP_TABLE.parse(cfg.get("sweep", {})), **given.typed(dc.SWEEP_TABLE, cli.get("sweep", {}))}
    r_min, r_max, points = sw_cfg["r_min_ohm"], sw_cfg["r_max_ohm"], sw_cfg["points"]
    require(0 < r_min < r_max, f"need 0 < r_min < r_max, got {r_min!r}, {r_max!r}")
    require(points >= 2, f"points must be >= 2, got {points!r}")
    from tengsim.resources import check_count

    check_count(points, "the load sweep's points", MAX_SWEEP_POINTS)  # before a load array is made
    cycles = run.get("cycles", DEFAULT_CYCLES["sweep"])
    require(cycles >= 2, f"cycles must be >= 2 for a sweep (the first is dropped), got {cycles!r}")
    params, wf = _device_and_waveform("sweep", cfg, dev_cli)
    params = _viscoelastic("sweep", cfg, cli, params, wf)
    loads = np.logspace(np.log10(r_min), np.log10(r_max), points)
    from tengsim.device.config import check_pressures

    check_pressures(params.area, wf, cycles * wf.period, _area_source(cfg, cli))
    _note_paper_device("sweep", cfg, dev_cli, quiet)
    sw = resistance_sweep(params, wf, loads, cycles=cycles, steady=sw_cfg["steady"], dt_out=run.get("dt_out"),
                          options=solver, progress=not quiet)
    from tengsim.io import jsonable

    k_opt = int(np.nanargmax(sw.average_power_W))  # the optimum's row
    head = jsonable({"area_model": _area_model(params), "params": params.to_dict(), "waveform": wf.to_dict(),
                     "optimum_ohm": sw.optimum_ohm,
                    "optimum_power_W": sw.optimum_power_W,
                    "optimum_peak_power_W": float(sw.peak_power_W[k_opt]), "optimum_at_edge": sw.optimum_at_edge,
                    "run": {"case": "sweep", "cycles": cycles, "config": cfg, "config_file": source}})
    write_csv(out, {"R": sw.load_ohm, "energy_per_cycle": sw.energy_per_cycle_J, "average_power": sw.average_power_W,
                    "peak_voltage": sw.peak_voltage_V, "peak_current": sw.peak_current_A,
                    "peak_power": sw.peak_power_W}, head)
    side = out.with_suffix(".json")
    write_json(side, head)
    if sw.optimum_at_edge:
        print(f"tengsim: warning: the mean power is largest at the edge of the swept range (R = "
              f"{sw.optimum_ohm:.4g} ohm): no optimum inside {r_min:.3g}..{r_max:.3g} ohm; widen the range",
              file=sys.stderr)
    if not quiet:
        what = "largest mean power in the range (at its edge)" if sw.optimum_at_edge else "optimum load"
        print(f"{what}: R = {sw.optimum_ohm:.4g} ohm, "
              + power_line({"peak_power_W": sw.peak_power_W[k_opt], "average_power_W": sw.optimum_power_W}))
        print(f"wrote {out} (+ {side.name})", file=sys.stderr)
    return 0


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
