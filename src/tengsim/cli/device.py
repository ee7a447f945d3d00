"""``tengsim device``: the paper's dynamic cases (fig7, fig8), any configured device (run), load sweep."""
from __future__ import annotations

import json
import math
import sys
from pathlib import Path

from tengsim.errors import TengsimError, require

CONFIG_HELP = ("TOML or JSON file with optional tables [device] (DeviceParams fields, SI), [waveform] "
               "(kind = square|staircase|sine|table, ...), [run] (cycles, t_end, dt_out) and [solver] "
               "(method, rtol, atol)")


def register(subparsers) -> None:
    p = subparsers.add_parser("device", help="dynamic TENG output (paper Section 5)",
                              description="Open-circuit voltage, current and power of a contact-separation TENG.")
    sub = p.add_subparsers(dest="device_command", metavar="CASE")
    p.set_defaults(func=lambda args: (p.print_help(), 2)[1])

    def common(sp, default_cycles):
        sp.add_argument("--out", required=True, help="output file: .csv (one row per time, JSON sidecar) or .nc")
        sp.add_argument("--cycles", type=int, default=default_cycles, help="periods to run (default %(default)s)")
        sp.add_argument("--load-ohm", type=float, default=None, help="load R in ohm (0 = short, inf = open)")
        sp.add_argument("--damping", type=float, default=None, help="damping ratio zeta (default 0.7)")
        sp.add_argument("--force-model", choices=["field", "eq20", "none"], default=None,
                        help="electrostatic force (default field)")
        sp.add_argument("--initial-charge", choices=["zero", "rest"], default=None,
                        help="Q(0): zero (paper) or rest (V = 0, no start spike)")
        sp.add_argument("--dt", type=float, default=None, help="output time step in s")
        sp.add_argument("--config", default=None, help=CONFIG_HELP)
        sp.add_argument("--quiet", action="store_true", help="no progress or summary output")

    f7 = sub.add_parser("fig7", help="flat device, 10 N 5 Hz square wave (Fig. 7)")
    common(f7, 5)
    f7.set_defaults(func=_cmd_fig7)
    f8 = sub.add_parser("fig8", help="group-A device, 10-150 kPa staircase at 2 Hz (Fig. 8)")
    common(f8, 15)
    f8.add_argument("--quick", action="store_true", help="quick (coarse) contact-engine area table")
    f8.set_defaults(func=_cmd_fig8)
    rn = sub.add_parser("run", help="any device and waveform from --config")
    common(rn, 5)
    rn.add_argument("--t-end", type=float, default=None, help="run length in s (else cycles x period)")
    rn.set_defaults(func=_cmd_run)
    sw = sub.add_parser("sweep", help="load-resistance sweep of the Fig. 7 device (or --config)")
    sw.add_argument("--out", required=True, help="output .csv (one row per load)")
    sw.add_argument("--r-min", type=float, default=1e3)
    sw.add_argument("--r-max", type=float, default=1e10)
    sw.add_argument("--points", type=int, default=15)
    sw.add_argument("--cycles", type=int, default=3)
    sw.add_argument("--config", default=None, help=CONFIG_HELP)
    sw.add_argument("--quiet", action="store_true")
    sw.set_defaults(func=_cmd_sweep)


# --- config ---

def _read_config(path) -> dict:
    if path is None:
        return {}
    path = Path(path)
    require(path.is_file(), f"config file not found: {str(path)!r}")
    text = path.read_text()
    try:
        if path.suffix.lower() == ".json":
            cfg = json.loads(text)
        else:
            import tomllib

            cfg = tomllib.loads(text)
    except Exception as exc:  # noqa: BLE001 - any parse error is bad input
        raise TengsimError(f"malformed config {str(path)!r}: {exc}") from None
    require(isinstance(cfg, dict), f"config {str(path)!r} must be a mapping")
    unknown = sorted(set(cfg) - {"device", "waveform", "run", "solver"})
    require(not unknown, f"config {str(path)!r}: unknown table(s) {unknown}")
    for key in cfg:
        require(isinstance(cfg[key], dict), f"config {str(path)!r}: [{key}] must be a table")
    return cfg


def _params(base, cfg, args):
    from tengsim.device import DeviceParams

    d = base.to_dict() if base is not None else {}
    d.update(cfg.get("device", {}))
    if args.load_ohm is not None:
        d["load_ohm"] = args.load_ohm
    if getattr(args, "damping", None) is not None:
        d["damping_ratio"] = args.damping
    if getattr(args, "force_model", None) is not None:
        d["force_model"] = args.force_model
    if getattr(args, "initial_charge", None) is not None:
        d["initial_charge"] = args.initial_charge
    return DeviceParams.from_dict(d)


def _solver(cfg):
    from tengsim.device import SolverOptions

    try:
        return SolverOptions(**cfg.get("solver", {}))
    except TypeError as exc:
        raise TengsimError(f"[solver]: {exc}") from None


def _check_out(path) -> Path:
    out = Path(path)
    require(out.suffix.lower() in (".csv", ".nc"), f"--out must end in .csv or .nc, got {str(path)!r}")
    return out


def _check_run_args(args):
    require(args.cycles is not None and args.cycles >= 1, f"--cycles must be >= 1, got {args.cycles!r}")
    if args.dt is not None:
        require(math.isfinite(args.dt) and args.dt > 0, f"--dt must be > 0, got {args.dt!r}")
    if args.load_ohm is not None:
        require(args.load_ohm >= 0, f"--load-ohm must be >= 0, got {args.load_ohm!r}")


def _write(result, out: Path, summary: dict, quiet: bool) -> int:
    from tengsim.io import write_dataset, write_json

    if out.suffix.lower() == ".nc":
        write_dataset(result.to_dataset(), out)
    else:
        result.write_csv(out)
        write_json(out.with_suffix(".json"), {**result.header(), "summary": summary})
    if not quiet:
        print(json.dumps(summary, indent=1, default=str))
    return 0


# --- commands ---

def _cmd_fig7(args) -> int:
    from tengsim.device import fig7_params, fig7_summary, fig7_waveform, simulate

    out = _check_out(args.out)
    _check_run_args(args)
    cfg = _read_config(args.config)
    params = _params(fig7_params(), cfg, args)
    wf = fig7_waveform(area_m2=params.area_m2)
    run = cfg.get("run", {})
    res = simulate(params, wf, args.cycles * wf.period, dt_out=args.dt or run.get("dt_out"),
                   options=_solver(cfg), progress=not args.quiet)
    skip = 1 if args.cycles > 1 else 0
    return _write(res, out, fig7_summary(res, skip), args.quiet)


def _cmd_fig8(args) -> int:
    from tengsim.device import ConstantArea, fig8_params, fig8_summary, fig8_waveform, simulate

    out = _check_out(args.out)
    _check_run_args(args)
    cfg = _read_config(args.config)
    dev = cfg.get("device", {})
    flat = fig8_params(ConstantArea(1.0))
    if "area" in dev:  # the config's own A(P) replaces the contact engine's
        params = _params(None if "mass_kg" in dev else flat, cfg, args)
    else:
        _params(flat, cfg, args)  # validate the overrides before the (slow) contact engine runs
        from tengsim.paper import area_table

        params = _params(fig8_params(area_table("A", quick=args.quick)), cfg, args)
    amps = fig8_waveform().amplitudes_Pa[: args.cycles]
    wf = fig8_waveform(amps)
    res = simulate(params, wf, wf.duration, dt_out=args.dt or cfg.get("run", {}).get("dt_out", 1e-4),
                   options=_solver(cfg), progress=not args.quiet)
    return _write(res, out, fig8_summary(res), args.quiet)


def _cmd_run(args) -> int:
    from tengsim.device import simulate, waveform_from_dict

    out = _check_out(args.out)
    _check_run_args(args)
    cfg = _read_config(args.config)
    require("device" in cfg and "waveform" in cfg, "device run needs --config with [device] and [waveform]")
    params = _params(None, cfg, args)
    wf = waveform_from_dict(cfg["waveform"])
    run = cfg.get("run", {})
    t_end = args.t_end or run.get("t_end")
    if t_end is None:
        per = wf.period or wf.duration
        require(per is not None, "give --t-end (or [run] t_end) for this waveform")
        t_end = int(run.get("cycles", args.cycles)) * per
    res = simulate(params, wf, t_end, dt_out=args.dt or run.get("dt_out"), options=_solver(cfg),
                   progress=not args.quiet)
    skip = 1 if (wf.period and t_end >= 2 * wf.period) else 0
    return _write(res, out, res.summary(skip), args.quiet)


def _cmd_sweep(args) -> int:
    import numpy as np

    from tengsim.device import fig7_params, fig7_waveform, resistance_sweep, waveform_from_dict
    from tengsim.io import write_csv, write_json

    out = Path(args.out)
    require(out.suffix.lower() == ".csv", f"--out must end in .csv, got {args.out!r}")
    require(0 < args.r_min < args.r_max and math.isfinite(args.r_max),
            f"need 0 < --r-min < --r-max, got {args.r_min!r}, {args.r_max!r}")
    require(args.points >= 2, f"--points must be >= 2, got {args.points!r}")
    require(args.cycles >= 2, f"--cycles must be >= 2, got {args.cycles!r}")
    cfg = _read_config(args.config)
    args.load_ohm = None
    params = _params(fig7_params(), cfg, args)
    wf = waveform_from_dict(cfg["waveform"]) if "waveform" in cfg else fig7_waveform(area_m2=params.area_m2)
    sw = resistance_sweep(params, wf, np.logspace(np.log10(args.r_min), np.log10(args.r_max), args.points),
                          cycles=args.cycles, options=_solver(cfg), progress=not args.quiet)
    head = {"params": params.to_dict(), "waveform": wf.to_dict(), "optimum_ohm": sw.optimum_ohm,
            "optimum_power_W": sw.optimum_power_W}
    write_csv(out, {"R": sw.load_ohm, "energy_per_cycle": sw.energy_per_cycle_J, "average_power": sw.average_power_W,
                    "peak_voltage": sw.peak_voltage_V, "peak_current": sw.peak_current_A}, head)
    write_json(out.with_suffix(".json"), head)
    if not args.quiet:
        print(f"optimum load {sw.optimum_ohm:.4g} ohm, mean power {sw.optimum_power_W:.4g} W", file=sys.stdout)
    return 0


__all__ = ["register"]
