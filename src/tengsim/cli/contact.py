"""``tengsim contact``: one approach–retraction run (thin shell over tengsim.config.run_contact)."""
from __future__ import annotations

import sys
from pathlib import Path

from tengsim.errors import TengsimError


def register(sub):
    p = sub.add_parser(
        "contact",
        help="one approach–retraction run of a micro-structure against a flat plate",
        description="Solve the adhesive contact (paper Eq. 9) along an approach from --d-min to --d-max "
        "and a retraction back. Dimensionless input (--N, --cell, --tabor) or physical input with "
        "units (--pitch 2um --base 1um --height 0.7um --E-star 0.59MPa --W 54mJ/m2 --tabor 0.5 or --eps).",
    )
    p.add_argument("shape", choices=["pyramid", "sphere", "cone", "hemisphere", "cube", "line"])
    p.add_argument("--N", help="pyramid N = n/(2ε)")
    p.add_argument("--cell", help="cell side L̄ (dimensionless)")
    p.add_argument("--tabor", help="Tabor parameter μ (default 0.5)")
    for k in ("pitch", "base", "height", "eps"):
        p.add_argument(f"--{k}", help=f"physical {k} with unit, e.g. 2um")
    p.add_argument("--E-star", dest="E_star", help="effective modulus, e.g. 0.59MPa")
    p.add_argument("--W", help="work of adhesion, e.g. 54mJ/m2")
    p.add_argument("--slope", help="cone slope")
    p.add_argument("--radius", help="hemisphere radius")
    p.add_argument("--half-width", dest="half_width", help="cube/line half width")
    p.add_argument("--dx", default="0.1", help="grid spacing in X units (default 0.1)")
    p.add_argument("--d-min", dest="d_min", default="-1")
    p.add_argument("--d-max", dest="d_max", default="4")
    p.add_argument("--d-step", dest="d_step", default="0.05")
    p.add_argument("--boundary", default="free", help="free (isolated cell, Eq. 9) or periodic")
    p.add_argument("--solver", default="fast", help="fast (L-BFGS) or vsr (the paper's relaxation)")
    p.add_argument("--tol", default="1e-6", help="max residual of Eq. (9) in ε (default 1e-6)")
    p.add_argument("--law", default="lj93", help="lj93 (paper) or repulsive")
    p.add_argument("--maps", dest="maps_at", default="", help="comma-separated D values whose maps go in the .nc")
    p.add_argument("--out", required=True, help="output file: .csv (curves) or .nc (everything)")
    p.add_argument("--plot", help="also draw F(D), Λc(D), Λc(F) to this .png/.pdf")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=run)


def run(args) -> int:
    from tengsim.config import run_contact
    from tengsim.progress import Progress

    out = Path(args.out)
    if out.suffix.lower() not in (".csv", ".nc"):
        raise TengsimError(f"--out {args.out}: use a .csv or .nc file")
    if args.plot and Path(args.plot).suffix.lower() not in (".png", ".pdf", ".svg"):
        raise TengsimError(f"--plot {args.plot}: use a .png, .pdf or .svg file")
    from tengsim.io import check_writable

    check_writable(out)
    if args.plot:
        check_writable(args.plot)
    keys = ["shape", "N", "cell", "tabor", "pitch", "base", "height", "eps", "E_star", "W", "slope",
            "radius", "half_width", "dx", "d_min", "d_max", "d_step", "boundary", "solver", "tol",
            "law", "maps_at"]
    cfg = {k: getattr(args, k) for k in keys if getattr(args, k) not in (None, "")}
    bar = Progress(args.quiet)
    try:
        res = run_contact(cfg, progress=bar)
    finally:
        bar.close()
    return write_contact(res, out, args.plot, args.quiet)


def write_contact(res, out, plot=None, quiet=False) -> int:
    res.save(out)
    if plot:
        from tengsim.plots import plot_curves

        plot_curves(res, plot)
    if not quiet:
        j = res.jumps
        print(f"wrote {out}: {len(res.table['D'])} equilibria, pull-off F = {res.pull_off_force:.4g}, "
              f"{len(j)} jump(s), {res.seconds:.1f} s", file=sys.stderr)
    from tengsim.status import warning_lines

    for line in warning_lines(res):  # one line per problem kind; a warning, so the exit code stays 0
        print(f"tengsim: warning: {line} (see column 'status')", file=sys.stderr)
    return 0
