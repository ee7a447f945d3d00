"""``tengsim contact``: one approach–retraction run (thin shell over tengsim.contact.run_contact)."""
from __future__ import annotations

import sys
from pathlib import Path

from tengsim.errors import TengsimError


_CLI_ONLY = ("out", "plot", "quiet")
_ALIASES = {"maps_at": ("--maps",)}


def _option_help():
    """Common keys, per shape key its help text(s) and the shapes using it, and per law key its help text,
    laws and defaults, from the [contact] schema."""
    from tengsim.config import common_fields, contact_table, law_key_help, law_keys
    from tengsim.registry import SHAPES

    common = {f.name: f for f in common_fields()}
    laws = law_keys()
    per_key = {}
    for s in SHAPES.names():
        for k, f in contact_table(s).fields.items():
            if k not in common and k not in laws:
                per_key.setdefault(k, {}).setdefault(f.help or k, []).append(s)
    helps = {}
    for k, groups in per_key.items():
        if len(groups) == 1:
            (h, users), = groups.items()
            helps[k] = f"{h} [{', '.join(users)}]"
        else:
            helps[k] = "; ".join(f"{', '.join(users)}: {h}" for h, users in groups.items())
    for k, entries in laws.items():
        helps[k] = law_key_help(entries) + " (a plain number, no unit)"
    return common, helps


def register(sub):
    from tengsim.config import contact_table
    from tengsim.registry import SHAPES

    p = sub.add_parser(
        "contact",
        help="one approach–retraction run of a micro-structure against a flat plate",
        description="Solve the adhesive contact (paper Eq. 9) along an approach from --d-min to --d-max "
        "and a retraction back. Dimensionless input (the shape's own numbers, e.g. --N 0.946 --cell 3.78 "
        "--tabor 0.5) or physical input with units (e.g. pyramid --pitch 2um --base 1um --height 0.7um "
        "--E-star 0.59MPa --W 54mJ/m2 --tabor 0.5, or --eps instead of --tabor). Shapes: " + SHAPES.help(),
    )
    p.add_argument("shape", choices=SHAPES.names(), help="registered shape")
    p.add_argument("positional", nargs="?", metavar="INPUT",
                   help="the shape's positional input, for shapes that declare one (topography: FILE)")
    common, per_key = _option_help()
    bools = {f.name for s in SHAPES.names() for f in contact_table(s).fields.values() if f.kind == "bool"}
    for k, f in common.items():
        if k == "shape" or k in _CLI_ONLY:
            continue
        flag = {"nargs": "?", "const": "true"} if f.kind == "bool" else {}  # --adaptive alone means true
        p.add_argument("--" + k.replace("_", "-"), *_ALIASES.get(k, ()), dest=k, **flag,
                       help=f.describe().split(": ", 1)[1].replace("%", "%%"))
    for k, h in per_key.items():
        if k in _CLI_ONLY:
            continue
        flag = {"nargs": "?", "const": "true"} if k in bools else {}  # '--fill-missing' alone means true
        p.add_argument("--" + k.replace("_", "-"), dest=k, help=h.replace("%", "%%"), **flag)
    p.add_argument("--out", required=True, help="output file: .csv (curves) or .nc (everything)")
    p.add_argument("--plot", help="also draw F(D), Λc(D), Λc(F) to this .png/.pdf")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.add_argument("--resume", action="store_true",
                   help="continue the interrupted run of these settings from OUT.partial.csv (rows are written "
                   "there as they finish; the path is solved again from its start and each row already in the "
                   "file is checked, so the result equals an uninterrupted run's)")
    p.set_defaults(func=run)


def run(args) -> int:
    from tengsim.config import contact_keys, plan_contact

    keys = [k for k in contact_keys() if k not in _CLI_ONLY]
    cfg = {k: getattr(args, k) for k in keys if getattr(args, k, None) not in (None, "")}
    if getattr(args, "positional", None) is not None:
        from tengsim.registry import SHAPES

        key = getattr(SHAPES.get(args.shape), "positional", None)
        if key is None:
            raise TengsimError(f"shape {args.shape} takes no positional input (got {args.positional!r})")
        if cfg.get(key) not in (None, args.positional):
            raise TengsimError(f"{key} given twice: {args.positional!r} and --{key.replace('_', '-')} {cfg[key]!r}")
        cfg[key] = args.positional
    plan_contact({**cfg, "out": args.out})  # every option checked before anything is written (maps need .nc)
    out = Path(args.out)
    if out.suffix.lower() not in (".csv", ".nc"):
        raise TengsimError(f"--out {args.out}: use a .csv or .nc file")
    if args.plot and Path(args.plot).suffix.lower() not in (".png", ".pdf", ".svg"):
        raise TengsimError(f"--plot {args.plot}: use a .png, .pdf or .svg file")
    from tengsim.io import check_output

    check_output(out, cfg.values())  # never over an input (a topography file)
    if args.plot:
        check_output(args.plot, cfg.values(), what="--plot")
    from tengsim import parallel

    if not parallel.is_root():  # mpiexec -n N: every process solves its slab, rank 0 alone writes and reports
        run_contact(cfg)
        return 0
    stream = open_stream(out, args.resume, args.quiet)
    res = run_streamed(lambda bar: run_contact(cfg, progress=bar, sink=stream), stream, args.quiet)
    if res is None:
        return 130
    return write_contact(res, out, args.plot, args.quiet, stream)


def run_contact(cfg: dict, progress=None, sink=None):
    """:func:`tengsim.resolve.run_contact` (one grid, or refined with resolve = 'auto'), transition D judged
    with the shape's full-contact length, A/S at ``resolve_pressures`` (:func:`tengsim.study.observe.contact_hooks`)."""
    from tengsim.resolve import run_contact as run
    from tengsim.study.observe import contact_hooks

    return run(cfg, progress=progress, sink=sink, **contact_hooks(cfg))


def open_stream(out, resume: bool, quiet: bool = False):
    """The :class:`tengsim.results.RowStream` writing a run's rows to ``OUT.partial.csv`` as they finish:
    a new one (refused while a partial file of an interrupted run is there, so nothing finished is
    overwritten), or with ``resume`` one continuing that file."""
    from tengsim.load import read_partial
    from tengsim.results import RowStream, partial_path

    from tengsim.results import checkpoint_path

    part, grids = partial_path(out), checkpoint_path(out)
    maps = Path(out).suffix.lower() == ".nc"
    if not resume:
        for f in (part, grids):
            if f.exists():
                raise TengsimError(f"{f} holds an interrupted run of --out {out}: add --resume to continue it, "
                                   "or delete it to start afresh")
        return RowStream(out, maps=maps)
    if grids.is_file() and not part.is_file():  # a refinement: its finished grids are read by tengsim.resolve
        if not quiet:
            print(f"tengsim: resuming {grids}: its finished grids are kept, the refinement goes on",
                  file=sys.stderr)
        return RowStream(out, maps=maps)
    if not part.is_file():
        raise TengsimError(f"--resume: no partial file {part} to continue (a run writes it as it goes and "
                           "removes it once the result is saved)")
    header, cols = read_partial(part)
    stream = RowStream(out, resume=(header, cols), maps=maps)
    if not quiet:
        print(f"tengsim: resuming {part}: its {stream.n_old} finished equilibria are solved again and checked, "
              "then the run goes on", file=sys.stderr)
    return stream


def run_streamed(call, stream, quiet: bool):
    """``call(progress_bar)`` with rows streaming to ``stream``; on Ctrl-C, says what was kept and returns None."""
    from tengsim.progress import Progress

    bar = Progress(quiet)
    try:
        return call(bar)
    except KeyboardInterrupt:
        bar.close()
        stream.close()
        from tengsim.results import checkpoint_path

        if stream.path.exists():
            print(f"tengsim: interrupted; {stream.n_written} finished equilibria kept in {stream.path} "
                  "(continue with --resume)", file=sys.stderr)
        elif checkpoint_path(stream.out).exists():
            print(f"tengsim: interrupted; the refinement's finished grids are kept in {checkpoint_path(stream.out)} "
                  "(continue with --resume)", file=sys.stderr)
        else:
            print("tengsim: interrupted; no partial output was written", file=sys.stderr)
        return None
    except TengsimError as exc:  # a run that fails part way keeps what it finished, and says so
        if stream.n > stream.n_old:
            raise TengsimError(f"{exc} ({stream.n_written} finished equilibria are kept in {stream.path})") from None
        raise
    finally:
        bar.close()
        stream.close()


def write_contact(res, out, plot=None, quiet=False, stream=None) -> int:
    res.save(out)
    if stream is not None:
        stream.finish()  # the whole result is saved: the partial file goes
    if plot:
        from tengsim.plots import plot_curves

        plot_curves(res, plot)
    if not quiet:
        j = res.jumps
        si = f" ({res.scaling.force(res.pull_off_force):.4g} N per cell)" if res.scaling is not None else ""
        print(f"wrote {out}: {len(res.table['D'])} equilibria, pull-off F = {res.pull_off_force:.4g}{si}, "
              f"{len(j)} jump(s), {res.seconds:.1f} s", file=sys.stderr)
    from tengsim.status import warning_lines

    for line in warning_lines(res):  # one line per problem kind; a warning, so the exit code stays 0
        print(f"tengsim: warning: {line} (see column 'status')", file=sys.stderr)
    if res.params.get("resolve_message"):  # resolve = auto stopped by max_pixels: the dx reached and needed
        print(f"tengsim: warning: {res.params['resolve_message']}", file=sys.stderr)
    elif res.params.get("resolve") == "auto" and not quiet:
        grids = ", ".join(f"{d:.4g}" for d in res.params.get("resolve_grids", ()))
        print(f"tengsim: resolved: dx {grids}; status {res.params.get('resolve_status')}", file=sys.stderr)
    missed = [m for m in str(res.params.get("load_not_met") or "").split("; ") if m]
    if missed:  # load control: which loads, and where the search for each ended
        print(f"tengsim: warning: {len(missed)} load(s) not met, first {missed[0]} (all: parameter "
              "'load_not_met')", file=sys.stderr)
    if res.params.get("maps_not_made"):  # load control: a requested map whose load has no state on a branch
        print(f"tengsim: warning: maps not made: {res.params['maps_not_made']}", file=sys.stderr)
    return 0
