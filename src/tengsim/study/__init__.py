"""Design studies: sweeps over patterns, sizes and materials on Dask, resumable (``tengsim sweep``).

spec (study file → points and ids), execute (Dask run, atomic per-point files, resume), observe
(per-point observables), dataset (study.nc / study.csv), plot (design maps), optimize.
"""
from tengsim.study.dataset import build_study
from tengsim.study.execute import run_study
from tengsim.study.hashing import point_id
from tengsim.study.spec import load_study, parse_study

__all__ = ["build_study", "load_study", "parse_study", "point_id", "run_study"]
