"""``tengsim contact … --relaxation FILE``: the physical run on a time axis (a thin shell over
:mod:`tengsim.visco`).  The history is ``--history FILE.csv`` (time in s, and an approach with a length unit
in its header, e.g. ``approach_nm``, or a pressure, e.g. ``pressure_kPa``) or a wave by options:
``--wave ramp_hold|triangle|square --wave-to VALUE --wave-time T [--cycles N]`` (VALUE a length: approach
control, a pressure: load control).  ``--dt`` (s) fixed steps, else 32 steps a segment.  The run's E* is the
relaxed solid's (E∞); the series' ratios E_i/E∞ and times τ_i apply.
"""
from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

from tengsim.errors import TengsimError

WAVES = ("ramp_hold", "triangle", "square")


def register_options(p) -> None:
    p.add_argument("--relaxation", help="a TOML file with a [relaxation] table: the run on a time axis")
    p.add_argument("--history", help="with --relaxation: CSV of time (s) and approach (length) or pressure")
    p.add_argument("--wave", choices=WAVES, help="with --relaxation: a history by options")
    p.add_argument("--wave-to", dest="wave_to", help="the wave's peak: a length (approach) or a pressure (load)")
    p.add_argument("--wave-time", dest="wave_time", help="the ramp time, each half of a triangle, or the period")
    p.add_argument("--cycles", type=int, default=1, help="periods of a square wave")
    p.add_argument("--dt", help="fixed time step (s); default 32 steps a segment")


def _history(args, sc):
    from tengsim.units import parse_quantity, quantity_dim
    from tengsim.visco import History, read_history, ramp_hold, square_wave, triangle

    if args.history and args.wave:
        raise TengsimError("give --history FILE or --wave, not both")
    if args.history:
        p = Path(args.history)
        try:
            head = next(csv.reader(p.read_text().splitlines()))
        except (OSError, StopIteration):
            raise TengsimError(f"cannot read history file {str(p)!r}") from None
        except (UnicodeDecodeError, csv.Error):
            raise TengsimError(f"history file {str(p)!r}: not a text (CSV) file") from None
        col = head[1].strip() if len(head) > 1 else ""
        unit = col.split("_", 1)[1] if "_" in col else ""
        h = read_history(p)
        if not unit:
            raise TengsimError(f"history file {str(p)!r}: name the unit in the header (approach_nm, pressure_kPa)")
        f = parse_quantity("1" + unit, "length" if h.kind == "approach" else "pressure", f"the unit of {col}")
        v = np.asarray(h.value) * f
        return History(h.t, tuple(v / sc.eps if h.kind == "approach" else v * sc.eps / sc.W), h.kind)
    if not args.wave:
        raise TengsimError("--relaxation needs a history: --history FILE.csv or --wave ... --wave-to ... --wave-time ...")
    if args.wave_to is None or args.wave_time is None:
        raise TengsimError("--wave needs --wave-to (a length or a pressure) and --wave-time (s)")
    dim = quantity_dim(args.wave_to)
    if dim not in ("length", "pressure"):
        raise TengsimError(f"--wave-to {args.wave_to}: give a length (approach) or a pressure (load)")
    kind = "approach" if dim == "length" else "pressure"
    peak = parse_quantity(args.wave_to, dim, "--wave-to")
    peak = peak / sc.eps if kind == "approach" else peak * sc.eps / sc.W
    T = parse_quantity(args.wave_time, "time", "--wave-time")
    if not T > 0:
        raise TengsimError(f"--wave-time must be > 0, got {args.wave_time}")
    start = -2.0 if kind == "approach" else 0.0
    if args.wave == "ramp_hold":
        return ramp_hold(start, peak, T, T, kind)
    if args.wave == "triangle":
        return triangle(start, peak, T, T, kind)
    return square_wave(start, peak, T, args.cycles, kind=kind)


def run(args, plan) -> int:
    """The viscoelastic run of ``plan`` (physical: its scaling gives the units); writes CSV or NetCDF."""
    from tengsim.relaxation import read_relaxation
    from tengsim.visco import FixedTimeSteps, SegmentSteps, simulate_history
    from tengsim.units import parse_quantity

    sc = plan.scaling
    if sc is None:
        raise TengsimError("--relaxation needs a physical run (--E-star, --W, ... in units)")
    from tengsim.io import check_output

    out = check_output(args.out, [x for x in (args.relaxation, args.history) if x])  # never an input, before work
    material = read_relaxation(args.relaxation)
    history = _history(args, sc)
    steps = FixedTimeSteps(parse_quantity(args.dt, "time", "--dt")) if args.dt else SegmentSteps(32)
    res = simulate_history(plan.shape, plan.tabor, plan.grid.dx, material, history, steps, boundary=plan.boundary,
                           law=plan.law, solver=plan.solver, tol=plan.solver_tol, kernel_params=plan.kernel_params,
                           grid=plan.grid)
    ds = res.to_xarray()
    ds["approach_m"] = ds["D"] * sc.eps
    ds["pressure_Pa"] = ds["mean_pressure"] * sc.W / sc.eps
    for k, v in {**sc.params(), "relaxation_file": str(args.relaxation)}.items():
        ds.attrs[k] = v if isinstance(v, (int, float, str)) else str(v)
    if out.suffix.lower() == ".nc":
        ds.to_netcdf(out)
    else:
        cols = ["time", "D", "approach_m", "F", "mean_pressure", "pressure_Pa", "area_fraction", "area_repulsive",
                "E_eff", "jump", "converged"]
        ds[cols[1:]].to_dataframe().reset_index()[cols].to_csv(out, index=False)
    if not args.quiet:
        j = res.jumps()
        print(f"tengsim: {len(res.t)} time steps to t = {res.t[-1]:g} s, A/S {res['area_fraction'].min():.4g} … "
              f"{res['area_fraction'].max():.4g}, {len(j)} jump(s)" + (f" (first at t = {j[0][0]:.4g} s)" if j else "")
              + f"; wrote {out}")
    return 0 if res.ok else 1
