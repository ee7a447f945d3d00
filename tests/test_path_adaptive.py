"""Adaptive continuation in D (issue 14, Speed): group A at dx 0.3 reproduces the fixed-step curve.

Criteria (benchmarks/adaptive_path.py measures them on groups A, B, C at dx 0.2): F within 0.5 %
(|ΔF| / max(|F|, |pull-off F|), the adaptive curve interpolated by PCHIP at the fixed curve's D,
``tengsim.path.compare_paths``), jump D within the smallest step, at least 2× fewer solver calls
(defaults adapt_tol 0.15, adapt_h 0.5: 119 / 53 = 2.25× here, 2.46× at dx 0.2; checked at 2×).
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np
import pytest

import tengsim as ts
from tengsim.kernels import FreeKernel
from tengsim.path import PathSpec, compare_paths, run_path
from tengsim.cases.paper.units import paper_scaling


class Counting:
    def __init__(self, inner):
        self.inner, self.name, self.tol, self.solves = inner, inner.name, inner.tol, 0

    def solve(self, problem, start):
        self.solves += 1
        return self.inner.solve(problem, start)


@lru_cache(maxsize=None)
def group_a(adaptive: bool):
    sc = paper_scaling("A")
    shape = ts.Pyramid(sc.N, sc.cell)
    grid = shape.grid(0.3)
    spec = (PathSpec(-1.0, 4.6, 0.8, refine_levels=7, adaptive=True) if adaptive
            else PathSpec(-1.0, 4.6, 0.1))
    solver = Counting(ts.FastSolver(1e-6))
    res = run_path(shape.gap(grid), ts.LJ93(), FreeKernel(grid, sc.mu**1.5), solver, spec)
    return res, solver.solves


def test_adaptive_reproduces_fixed_curve_with_half_the_solves():
    fixed, n_fixed = group_a(False)
    adapt, n_adapt = group_a(True)
    assert fixed.all_converged and adapt.all_converged
    cmp = compare_paths(fixed, adapt)
    assert cmp["n_compared"] >= 0.9 * len(fixed.table["D"])
    assert cmp["max_rel_dF"] < 0.005
    assert cmp["max_rel_dF_same_D"] < 1e-4          # equal D: the same equilibria (solver tolerance)
    smallest = 0.1 / 2**4
    assert len(cmp["jumps_ref"]) == len(cmp["jumps_other"])
    assert not cmp["max_jump_dD"] > smallest
    # the issue asks 2×: measured here 119 / 53 = 2.25× (2.46× at dx 0.2, benchmarks/results)
    assert n_fixed >= 2.0 * n_adapt
    assert adapt.pull_off_force == pytest.approx(fixed.pull_off_force, rel=5e-3)


def test_adaptive_rows_stay_on_the_lattice_and_on_grid_means_d_step():
    adapt, _ = group_a(True)
    D, on = adapt.table["D"], adapt.table["on_grid"]
    k = (D + 1.0) / (0.8 / 2**7)
    assert np.allclose(k, np.round(k), atol=1e-6)
    grid_D = -1.0 + 0.8 * np.arange(8)
    for br in ("approach", "retraction"):
        b = adapt.branch(br)
        assert np.allclose(np.sort(b["D"][b["on_grid"].astype(bool)]), grid_D)
    # path order: monotone D on each branch
    assert np.all(np.diff(adapt.branch("approach")["D"]) > 0)
    assert np.all(np.diff(adapt.branch("retraction")["D"]) < 0)
    assert on.dtype == bool


def test_fixed_default_is_unchanged():
    """adaptive=False takes the old code path: same rows as a spec without the new fields."""
    assert PathSpec(-1, 1, 0.5).extra_params() == {}
    assert PathSpec(-1, 1, 0.5, adaptive=True).extra_params()["adaptive"] is True


def test_adaptive_spec_validation():
    with pytest.raises(ts.TengsimError, match="adapt_tol"):
        PathSpec(-1, 1, 0.5, adaptive=True, adapt_tol=0)
    with pytest.raises(ts.TengsimError, match="adapt_h"):
        PathSpec(-1, 1, 0.5, adaptive=True, adapt_h=-1)
