"""``tengsim plot RESULT``: redraw the figure of a saved contact result (.nc or .csv)."""
from __future__ import annotations

from pathlib import Path

from tengsim.errors import TengsimError


def register(sub):
    p = sub.add_parser("plot", help="redraw figures from a saved result",
                       description="Draw F(D), Λc(D), Λc(F) of a contact result (.nc or .csv written by "
                       "tengsim), or the time series of a device result.")
    p.add_argument("result", help="result file (.nc or .csv), or a study directory of tengsim sweep")
    p.add_argument("--out", help="figure file (.png/.pdf); default RESULT with .png")
    p.set_defaults(func=run)


def run(args) -> int:
    from tengsim.load import load_result

    src = Path(args.result)
    if src.is_dir():  # a study directory written by tengsim sweep: its design maps
        from tengsim.study.plot import plot_study

        out = Path(args.out) if args.out else src / "design.png"
        if out.suffix.lower() not in (".png", ".pdf", ".svg"):
            raise TengsimError(f"--out {out}: use a .png, .pdf or .svg file")
        for f in plot_study(src, out):
            print(f"wrote {f}")
        return 0
    out = Path(args.out) if args.out else src.with_suffix(".png")
    if out.suffix.lower() not in (".png", ".pdf", ".svg"):
        raise TengsimError(f"--out {out}: use a .png, .pdf or .svg file")
    kind, obj = load_result(src)
    if kind == "contact":
        from tengsim.plots import plot_curves

        plot_curves(obj, out, title=src.name)
    else:
        from tengsim.plots import plot_timeseries

        plot_timeseries(obj, out, title=src.name)
    print(f"wrote {out}")
    return 0
