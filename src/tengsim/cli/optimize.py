"""``tengsim optimize STUDY.toml``: maximise or minimise an observable over the study's range axes.

Differential evolution (scipy) whose population is evaluated on Dask, each evaluation stored like a
sweep point in DIR/points/, so an interrupted optimisation resumes (--resume) without recomputing.
Only points whose run status is ok are candidates unless --accept names another status; the report
(DIR/optimum.json) gives the status of the optimum and of its nearest evaluated neighbours.
Exit code 0 with a candidate optimum, 1 when no evaluated point is one.
The study file's [objective] names the observable (maximize = "S_V_per_kPa") and optional bounds on
others (subject_to = { linear_range_Pa = { min = 1e4 } }); see docs/design.md.
"""
from __future__ import annotations

import sys

from tengsim.cli.sweep import add_study_options, load_study_args

SUMMARY = "optimise an observable over a study's range axes, on Dask"  # its line in `tengsim --help`


def register(sub):
    p = sub.add_parser("optimize", help=SUMMARY,
                       description=__doc__.split("\n\n", 1)[1])
    p.add_argument("study", help="study TOML file with range [axes] and an [objective] table")
    add_study_options(p)
    p.add_argument("--accept", action="append", default=[], metavar="STATUS",
                   help="take points of this run status as candidates too (under_resolved, out_of_law_range, "
                        "not_converged; repeat or comma-separate); by default only 'ok' points are")
    p.add_argument("--quiet", action="store_true", help="no progress output")
    p.set_defaults(func=run)


def run(args) -> int:
    from tengsim.study.optimize import optimize_study

    from tengsim.study.optimize import parse_accept

    parse_accept(args.accept)  # a bad status: one line, exit 2, before the study is read
    study, out = load_study_args(args)
    try:
        r = optimize_study(study, out, workers=args.workers, scheduler=args.scheduler, resume=args.resume,
                           quiet=args.quiet, accept=args.accept)
    except KeyboardInterrupt:
        print(f"tengsim: interrupted; evaluated points are kept in {out}/points; continue with --resume",
              file=sys.stderr)
        return 130
    return 0 if r["feasible"] else 1
