"""benchmarks/run_benchmarks.py --vsr-mode full counted no convolution (the run solved the mirror block, whose
kernel the counter did not watch) and divided by it: the VSR run now solves the fast run's full grid and its
convolutions are counted (the counter, or the solver's own count where the counter saw none)."""
from __future__ import annotations

import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "benchmarks"))

import run_benchmarks as rb  # noqa: E402

from tengsim.kernels import FreeKernel  # noqa: E402
from tengsim.continuation import PathSpec
from tengsim.run.plan import ContactPlan
from tengsim.run.simulate import simulate
from tengsim.shapes import Pyramid  # noqa: E402
from tengsim.solvers import make_solver  # noqa: E402


def test_vsr_full_run_counts_its_convolutions():
    vsr = make_solver("vsr", tol=1e-5, max_iter=20000)
    cnt = rb.ConvCounter(FreeKernel)
    try:
        res = simulate(ContactPlan(Pyramid(2.0, 4.0), 0.5, 0.25, PathSpec(-0.5, 0.5, 0.25, refine_levels=0), boundary="free", solver=vsr, solver_tol=1e-5, symmetry="off"))
    finally:
        cnt.restore()
    nc = np.asarray(res.table["n_conv"])
    assert cnt.n > 0 and len(nc) >= 5
    assert rb.vsr_conv_total(cnt.n, nc) == cnt.n
    assert rb.vsr_conv_total(0, nc) == int(nc.sum()) > 0
