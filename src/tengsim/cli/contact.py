"""``tengsim contact``: one approach–retraction run (a thin shell: options → one plan, :func:`tengsim.run.plan.plan_contact`
→ :func:`tengsim.run.simulate.simulate`, or :func:`tengsim.run.resolve.resolve` for ``--resolve auto`` → files)."""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from tengsim.errors import TengsimError

SUMMARY = 'one approach–retraction run of a micro-structure against a flat plate'  # its line in `tengsim --help`
_CLI_ONLY = ("out", "plot", "quiet")
_ALIASES = {"maps_at": ("--maps",)}


def register(sub):
    """The parser: every key of every shape and law (from the [contact] schema) as an option; the help
    pages (per shape, and the index) are :mod:`tengsim.cli.keyhelp`'s."""
    from tengsim.cli.keyhelp import CLI_ONLY_HELP, HelpAction
    from tengsim.run.keys import common_fields, contact_table, law_keys
    from tengsim.registry import SHAPES

    p = sub.add_parser("contact", help=SUMMARY, add_help=False)
    p.add_argument("-h", "--help", action=HelpAction)
    p.add_argument("shape", choices=SHAPES.names(), help="registered shape")
    p.add_argument("positional", nargs="?", metavar="INPUT", help=argparse.SUPPRESS)  # topography: FILE
    fields = {f.name: f for f in common_fields()}
    for s in SHAPES.names():
        for k, f in contact_table(s).fields.items():
            fields.setdefault(k, f)
    for k in law_keys():
        fields.setdefault(k, None)
    for k, f in fields.items():
        if k == "shape" or k in _CLI_ONLY:
            continue
        flag = {"nargs": "?", "const": "true"} if f is not None and f.kind == "bool" else {}  # --adaptive = true
        p.add_argument("--" + k.replace("_", "-"), *_ALIASES.get(k, ()), dest=k, help=argparse.SUPPRESS, **flag)
    p.add_argument("--out", required=True, help=CLI_ONLY_HELP["out"])
    p.add_argument("--plot", help=CLI_ONLY_HELP["plot"])
    p.add_argument("--quiet", action="store_true", help=CLI_ONLY_HELP["quiet"])
    p.add_argument("--resume", action="store_true", help=CLI_ONLY_HELP["resume"])
    from tengsim.cli import contact_visco

    contact_visco.register_options(p)  # --relaxation FILE: the run on a time axis
    p.set_defaults(func=run)


def run(args) -> int:
    from tengsim.run.keys import contact_keys
    from tengsim.run.plan import plan_contact

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
    plan = plan_contact({**cfg, "out": args.out})  # every option checked before anything is written (maps: .nc)
    if getattr(args, "relaxation", None):
        from tengsim.cli import contact_visco

        return contact_visco.run(args, plan)
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
    from tengsim.run.resolve import resolve
    from tengsim.run.simulate import simulate

    run_contact = simulate if plan.resolve is None else resolve  # one grid, or refined until converged
    if not parallel.is_root():  # mpiexec -n N: every process solves its slab, rank 0 alone writes and reports
        run_contact(plan)
        return 0
    line = None if args.quiet or plan.scaling is None else f"tengsim: {physical_line(plan, 'eps' in cfg)}"
    from tengsim.run.plan import chosen_solver

    why = chosen_solver(plan)[1] if plan.resolve is None else ""  # a refinement says it per grid (bar.say)
    if why and not args.quiet:  # the solver 'auto' chose on the grid solved, said before the run
        line = "\n".join(x for x in (line, f"tengsim: {why}") if x)
    stream = open_stream(out, args.resume, args.quiet)
    res = run_streamed(lambda bar: run_contact(plan, progress=_Announced(bar, line), sink=stream), stream,
                       args.quiet)
    if res is None:
        return 130
    return write_contact(res, out, args.plot, args.quiet, stream)


class _Announced:
    """The progress bar, saying ``line`` first once the run has started (its set-up passed: a bad input
    found while building the run stays the one line of its error)."""

    def __init__(self, bar, line):
        self.bar, self.line = bar, line

    def _say(self):
        if self.line:
            print(self.line, file=sys.stderr, flush=True)
            self.line = None

    def __call__(self, *args, **kwargs):
        self._say()
        return self.bar(*args, **kwargs)

    def monitor(self, *args, **kwargs):
        self._say()
        return self.bar.monitor(*args, **kwargs)

    def say(self, text):  # a refinement's own line (which solver 'auto' chose on a grid)
        self._say()
        print(f"tengsim: {text}", file=sys.stderr, flush=True)


def physical_line(plan, eps_given: bool) -> str:
    """The line a physical run starts with: its materials, ε and the Tabor number derived (or given), the grid."""
    from tengsim.units import format_si

    sc = plan.scaling
    how = "derived from ε, E*, W and the shape" if eps_given else "as given; ε derived from it"
    return (f"physical run: E* = {format_si(sc.E_star, 'Pa')}, W = {sc.W * 1e3:.4g} mJ/m2, ε = "
            f"{format_si(sc.eps, 'm')}, Tabor number μ = {sc.mu:.4g} ({how}), dx = "
            f"{format_si(plan.dx * sc.lateral, 'm')}")


def pull_off_text(res) -> str:
    """'pull-off ...': the most tensile force of the retraction (N per cell and nominal Pa in a physical run);
    under load control, where the retraction stopped at f_min before separating, says so instead."""
    from tengsim.units import format_si

    F, sc = res.pull_off_force, res.scaling
    if res.params.get("control") == "load":
        r = res.branch("retraction")
        if len(r["F"]) and not bool(r["jump"][-1]):  # no separation: the lowest load is f_min, not the pull-off
            fmin = float(res.params.get("f_min", 0.0))
            at = f"{format_si(sc.pressure(fmin), 'Pa')}" if sc is not None and sc.cell_area else f"F = {fmin:.4g}"
            return (f"pull-off not reached (the retraction ended at f_min = {at} still in contact; a lower "
                    f"f_min finds it)")
    if sc is None or not F == F:
        return f"pull-off F = {F:.4g}"
    p = f", {format_si(sc.pressure(F), 'Pa')} nominal" if sc.cell_area else ""
    return f"pull-off {format_si(sc.force(F), 'N')} per cell{p} (F = {F:.4g})"


def open_stream(out, resume: bool, quiet: bool = False):
    """The :class:`tengsim.results.RowStream` writing a run's rows to ``OUT.partial.csv`` as they finish:
    a new one (refused while a partial file of an interrupted run is there, so nothing finished is
    overwritten), or with ``resume`` one continuing that file."""
    from tengsim.results.read import read_partial
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
    if grids.is_file() and not part.is_file():  # a refinement: its finished grids are read by tengsim.run.resolve
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

        from tengsim.cli.keyhelp import title_keys

        plot_curves(res, plot, keys=title_keys(res.params))
    if not quiet:
        j = res.jumps
        print(f"wrote {out}: {len(res.table['D'])} equilibria, {pull_off_text(res)}, "
              f"{len(j)} jump(s), {res.seconds:.1f} s", file=sys.stderr)
    from tengsim.status import warning_lines

    for line in warning_lines(res):  # one line per problem kind; a warning, so the exit code stays 0
        print(f"tengsim: warning: {line} (see column 'status')", file=sys.stderr)
    if res.params.get("resolve_message"):  # resolve = auto stopped by max_pixels: the dx reached and needed
        print(f"tengsim: warning: {res.params['resolve_message']}", file=sys.stderr)
    elif res.params.get("resolve") == "auto" and not quiet:
        from tengsim.units import format_si

        lat = res.scaling.lateral if res.scaling is not None else None
        grids = ", ".join(format_si(d * lat, "m", 4) if lat else f"{d:.4g}" for d in res.params.get("resolve_grids", ()))
        print(f"tengsim: resolved: dx {grids}; status {res.params.get('resolve_status')}", file=sys.stderr)
    from tengsim.continuation.load import misses_in

    missed = misses_in(res.params)
    if missed:  # load control: which loads, and where the search for each ended
        print(f"tengsim: warning: {len(missed)} load(s) not met, first {missed[0]} (all: parameter "
              "'load_not_met')", file=sys.stderr)
    if res.params.get("maps_not_made"):  # load control: a requested map whose load has no state on a branch
        print(f"tengsim: warning: maps not made: {res.params['maps_not_made']}", file=sys.stderr)
    return 0
