"""``tengsim plot RESULT``: redraw the figures of a saved result.

A contact result (.nc or .csv) gives F(D), Λc(D), Λc(F), and, when it holds maps (``--maps``), a
second figure ``<out stem>_maps<suffix>`` of the pressure and gap maps, and for a refined run
(``--resolve auto``) ``<out stem>_resolution<suffix>``, its observables against dx; a device time series gives
its traces; a load sweep (``tengsim device sweep``) its power and energy against R; a study folder
is drawn by ``tengsim.study.plot``.
"""
from __future__ import annotations

from pathlib import Path

from tengsim.errors import TengsimError

SUMMARY = 'redraw figures from a saved result'  # its line in `tengsim --help`

FIGURE_SUFFIXES = (".png", ".pdf", ".svg")


def register(sub):
    p = sub.add_parser("plot", help=SUMMARY,
                       description="Draw a saved tengsim result: F(D), Λc(D), Λc(F) of a contact result "
                       "(.nc or .csv) and its pressure/gap maps (second figure OUT_maps.png, .nc with "
                       "--maps only), the time series of a device result, power and energy against R of a "
                       "load sweep, or a study folder.")
    p.add_argument("result", help="result file (.nc or .csv) or a study folder")
    p.add_argument("--out", help="figure file (.png/.pdf/.svg); default RESULT with .png")
    p.add_argument("--no-maps", action="store_true", help="do not draw the saved maps of a contact result")
    p.set_defaults(func=run)


def _plot_study(src: Path, out):
    """Design maps of a study folder written by ``tengsim sweep`` (default ``DIR/design.png``)."""
    from tengsim.study.plot import plot_study

    return plot_study(src, out or src / "design.png")


def _device_period(src: Path, obj):
    """The waveform period (s) of a device result: from its .json sidecar (a .csv) or its attributes (a
    .nc); None when it has none (then the plot is not clipped to the settled cycles)."""
    import json

    try:
        if src.suffix.lower() == ".csv":
            wf = json.loads(src.with_suffix(".json").read_text(encoding="utf-8")).get("waveform", {})
        else:
            wf = json.loads(getattr(obj, "attrs", {}).get("waveform", "{}"))
        f = float(wf.get("frequency_Hz") or 0.0)
    except (OSError, ValueError, TypeError, AttributeError):
        return None
    return 1.0 / f if f > 0 else None


def run(args) -> int:
    from tengsim.results.read import load_result

    src = Path(args.result)
    out = Path(args.out) if args.out else None
    if out is not None and out.suffix.lower() not in FIGURE_SUFFIXES:
        raise TengsimError(f"--out {out}: use a .png, .pdf or .svg file")
    if src.is_dir():
        written = _plot_study(src, out)
        for w in written or ():
            print(f"wrote {w}")
        return 0
    out = out or src.with_suffix(".png")
    from tengsim.io import check_output

    check_output(out, [src])
    kind, obj = load_result(src)
    from tengsim.results.read import incomplete_note

    note = incomplete_note(kind, obj)
    if note:  # a partial file of a run cut short: drawn, and said so
        import sys

        print(f"tengsim: warning: {src}: {note}", file=sys.stderr)
    from tengsim import plots

    written = [out]
    if kind == "contact":
        maps_out = out.with_name(f"{out.stem}_maps{out.suffix}")
        from tengsim.cli.keyhelp import title_keys

        keys = title_keys(obj.params)
        plots.plot_curves(obj, out, title=src.name, keys=keys)
        if obj.maps and not args.no_maps:
            plots.plot_maps(obj, maps_out, title=src.name, keys=keys)
            written.append(maps_out)
        if isinstance(obj.params.get("resolution"), dict):  # resolve = auto: the convergence over the grids
            res_out = out.with_name(f"{out.stem}_resolution{out.suffix}")
            plots.plot_resolution(obj, res_out, title=src.name)
            written.append(res_out)
    elif kind == "sweep":
        plots.plot_sweep(obj, out, title=src.name)
    else:
        plots.plot_timeseries(obj, out, title=src.name, period=_device_period(src, obj))
    for w in written:
        print(f"wrote {w}")
    return 0
