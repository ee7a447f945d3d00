"""``tengsim optimize STUDY.toml``: maximise or minimise an observable over the study's range axes.

Differential evolution (scipy) whose population is evaluated on Dask, each evaluation stored like a
sweep point in DIR/points/, so an interrupted optimisation resumes (--resume) without recomputing.
The study file's [objective] names the observable (maximize = "S_V_per_kPa") and optional bounds on
others (subject_to = { P_sat_Pa = { min = 1e5 } }); see docs/design.md.
"""
from __future__ import annotations

import sys

from tengsim.errors import TengsimError


def register(sub):
    p = sub.add_parser("optimize", help="optimise an observable over a study's range axes, on Dask",
                       description=__doc__.split("\n\n", 1)[1])
    p.add_argument("study", help="study TOML file with range [axes] and an [objective] table")
    p.add_argument("--out", help="directory (default: the study file's name without .toml)")
    p.add_argument("--workers", type=int, help="number of local worker processes")
    p.add_argument("--scheduler", help="address of a running dask scheduler")
    p.add_argument("--resume", action="store_true", help="continue in --out, reusing stored evaluations")
    p.add_argument("--quiet", action="store_true", help="no progress output")
    p.set_defaults(func=run)


def run(args) -> int:
    from pathlib import Path

    from tengsim.study.optimize import optimize_study
    from tengsim.study.spec import load_study

    if args.workers is not None and args.scheduler is not None:
        raise TengsimError("give either --workers or --scheduler, not both")
    if args.workers is not None and args.workers < 1:
        raise TengsimError(f"--workers must be >= 1, got {args.workers}")
    study = load_study(args.study)
    out = args.out or str(Path(args.study).with_suffix(""))
    try:
        r = optimize_study(study, out, workers=args.workers, scheduler=args.scheduler, resume=args.resume,
                           quiet=args.quiet)
    except KeyboardInterrupt:
        print(f"tengsim: interrupted; evaluated points are kept in {out}/points; continue with --resume",
              file=sys.stderr)
        return 130
    return 0 if r["feasible"] else 1
