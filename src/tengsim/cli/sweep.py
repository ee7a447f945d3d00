"""``tengsim sweep STUDY.toml``: a design study over any contact/device parameters, on Dask, resumable.

The study file holds a ``[base.contact]`` table (exactly a ``tengsim run`` [contact] table) and
``[axes]`` ("contact.N" = [..], ranges {start, stop, num, scale}, zip groups); a "contact.shape" axis
takes per-shape tables [base.shapes.<name>] and '=' expressions over [contact] keys and [base.var]
variables ("var.aspect" axes); see docs/design.md.
Every finished point is written at once to DIR/points/<id>.nc; DIR/study.nc and DIR/study.csv are
rebuilt at the end.  A point's status is its run's (ok, under_resolved, out_of_law_range,
not_converged) or failed.  A killed sweep continues with --resume and never recomputes a sound finished
point; a point file that is unreadable or does not match its id and digest is reported and computed
again.  Exit code 0 when every point finished, 1 when some failed (see study.csv), 2 for a bad study
file.
"""
from __future__ import annotations

import math
import sys

from tengsim.errors import TengsimError

SUMMARY = 'design study: a grid or sample of runs on Dask, resumable'  # its line in `tengsim --help`


def register(sub):
    p = sub.add_parser("sweep", help=SUMMARY,
                       description=__doc__.split("\n\n", 1)[1])
    p.add_argument("study", help="study TOML file ([base.contact], [axes], optional [base.shapes.<name>], [base.var], "
                   "[study], [observables])")
    add_study_options(p)
    p.add_argument("--retry-failed", dest="retry_failed", action="store_true",
                   help="with --resume: compute again every point not finished 'ok' (failed points, and "
                        "finished points of another status)")
    p.add_argument("--quiet", action="store_true", help="no progress output")
    p.set_defaults(func=run)


def add_study_options(p) -> None:
    """--out, --workers | --scheduler and --resume: shared by ``tengsim sweep`` and ``tengsim optimize``."""
    p.add_argument("--out", help="study directory (default: the study file's name without .toml)")
    g = p.add_argument_group("where the points run (default: a LocalCluster with one worker per core)")
    g.add_argument("--workers", help="number of local worker processes")
    g.add_argument("--scheduler", help="address of a running dask scheduler, e.g. tcp://host:8786")
    p.add_argument("--resume", action="store_true", help="continue the study in --out (reuse finished points)")


def load_study_args(args):
    """(study, output directory) from the parsed options, after checking --workers / --scheduler."""
    from pathlib import Path

    from tengsim.study.spec import load_study

    if args.workers is not None and args.scheduler is not None:
        raise TengsimError("give either --workers or --scheduler, not both")
    if args.workers is not None:
        args.workers = _workers(args.workers)
    study = load_study(args.study)
    return study, args.out or str(Path(args.study).with_suffix(""))


def _workers(text) -> int:
    """--workers as a count from 1 to :func:`tengsim.resources.max_workers`, refused before any start."""
    from tengsim.errors import shown
    from tengsim.resources import max_workers
    from tengsim.units import read_number

    try:
        n = read_number(text, "--workers")
    except TengsimError:
        raise
    except ValueError:
        n = math.nan
    if not (n == n and n == int(n) and n >= 1):
        raise TengsimError(f"--workers must be a whole number >= 1, got {shown(text)}")
    if n > max_workers():
        raise TengsimError(f"--workers {int(n)} is more than {max_workers()} (4 local processes per core); "
                           "use --scheduler for a cluster")
    return int(n)


def run(args) -> int:
    from tengsim.study.execute import run_study

    study, out = load_study_args(args)
    try:
        s = run_study(study, out, workers=args.workers, scheduler=args.scheduler, resume=args.resume,
                      retry_failed=args.retry_failed, quiet=args.quiet)
    except KeyboardInterrupt:
        print(f"tengsim: interrupted; finished points are kept in {out}/points; continue with --resume",
              file=sys.stderr)
        return 130
    return 0 if s["failed"] == 0 else 1
