"""Adaptive continuation in D (issue 14, Speed): group A at dx 0.3 reproduces the fixed-step curve.

Criteria (benchmarks/adaptive_path.py measures them on groups A, B, C at dx 0.2): F within 0.5 %
(|ΔF| / max(|F|, |pull-off F|), the adaptive curve interpolated by PCHIP at the fixed curve's D,
``tengsim.continuation.compare_paths``), jump D within the smallest step, at least 2× fewer solver calls
(defaults adapt_tol 0.15, adapt_h 0.5: 119 / 53 = 2.25× here, 2.46× at dx 0.2; checked at 2×).
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np
import pytest

import tengsim as ts
from tengsim.kernels import FreeKernel
from tengsim.continuation import PathSpec, compare_paths, run_path
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
    # every retraction row solved (retrace=False): the step control's own count of solves is compared
    res = run_path(shape.gap(grid), ts.LJ93(), FreeKernel(grid, sc.mu**1.5), solver, spec, retrace=False)
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


# ---- maps at requested D off the walk's rows (issue 21: nothing silently dropped) -------------------------

# a μ = 1 sphere jumps in between D = -1.625 and -1.609375 and out between -1.734375 and -1.75 (steps of
# 0.25/16); the midpoints of those jump intervals, a D off every row, and a D on the lattice
IN_JUMP_IN, IN_JUMP_OUT = -1.6171875, -1.7421875
MAPS = (-1.3, 0.1, IN_JUMP_IN, IN_JUMP_OUT, 0.25)


@lru_cache(maxsize=None)
def sphere_mu1(maps_at=(), adaptive=False, d_step=0.25, retrace=False):
    """The walk's own rows (``retrace`` False: every retraction row solved, so the rows of a run with and without
    maps are compared state for state; tests/test_retrace.py compares the retraced path with this one)."""
    shape = ts.Paraboloid(1.0, 8.0)
    grid = shape.grid(0.4)
    spec = PathSpec(-2.0, 0.5, d_step, adaptive=adaptive, maps_at=maps_at)
    return run_path(shape.gap(grid), ts.LJ93(), FreeKernel(grid, 1.0), ts.FastSolver(1e-8), spec,
                    retrace=retrace), grid


@pytest.mark.parametrize("adaptive", [False, True])
def test_maps_at_off_the_rows_are_kept_exactly_at_their_D(adaptive):
    """Every requested D gets its map on both branches, at exactly that D: off the rows the walk visits,
    an extra row (on_grid False) there; every other row is the run's without maps_at, state for state;
    the jumps stay one per branch, within the smallest step of where they were."""
    ref, grid = sphere_mu1((), adaptive)
    res, _ = sphere_mu1(MAPS, adaptive)
    assert res.all_converged
    assert sorted((m["branch"], float(m["D"])) for m in res.maps) == sorted(
        (b, d) for b in ("approach", "retraction") for d in MAPS)
    for m in res.maps:
        row = res.branch(m["branch"])
        i = int(np.flatnonzero(row["D"] == m["D"])[0])
        assert ts.force(m["P"], grid) == row["F"][i]  # the map is the row's state
    for br, sign in (("approach", 1), ("retraction", -1)):
        a, b = ref.branch(br), res.branch(br)
        extra = ~np.isin(b["D"], a["D"])
        assert sorted(b["D"][extra]) == sorted(d for d in MAPS if d not in a["D"])
        assert not b["on_grid"][extra].astype(bool).any()
        np.testing.assert_array_equal(b["F"][~extra], a["F"])  # the continuation never saw the extra states
        np.testing.assert_array_equal(b["on_grid"][~extra], a["on_grid"])
        assert np.all(sign * np.diff(b["D"]) > 0)  # path order
    assert [j.branch for j in res.jumps] == [j.branch for j in ref.jumps] == ["approach", "retraction"]
    for ja, jb in zip(ref.jumps, res.jumps):  # an extra row inside a jump interval narrows it
        lo, hi = sorted((ja.D_before, ja.D_after))
        assert lo - 1e-12 <= min(jb.D_before, jb.D_after) < max(jb.D_before, jb.D_after) <= hi + 1e-12
    assert {j.D_after for j in res.jumps} & {IN_JUMP_IN, IN_JUMP_OUT}  # (here it does)


def test_extra_map_rows_are_the_d_controlled_equilibria_there():
    """Away from the jumps, the state kept at a requested D off the lattice is the one a finer fixed run,
    whose lattice holds that D, reaches by its own warm starts: F to 1e-6 of the pull-off scale."""
    res, grid = sphere_mu1(MAPS, False)
    fine, _ = sphere_mu1((), False, 0.05)
    scale = abs(fine.pull_off_force)
    for m in res.maps:
        if m["D"] in (-1.3, 0.1):
            f = fine.branch(m["branch"])
            i = int(np.argmin(np.abs(f["D"] - m["D"])))
            assert abs(f["D"][i] - m["D"]) < 1e-12
            assert abs(ts.force(m["P"], grid) - f["F"][i]) < 1e-6 * scale


@pytest.mark.parametrize("spec, words", [
    (dict(d_min=-1.0, d_max=2.0, d_step=0.25, maps_at=(2.1,)), "maps_at D = 2.1 is outside the path's D range [-1, 2]"),
    (dict(d_min=-1.0, d_max=2.1, d_step=0.25, maps_at=(2.05,)),
     "maps_at D = 2.05 is outside the path's D range [-1, 2] (the last D of the d_step lattice below d_max = 2.1)"),
    (dict(d_min=-1.0, d_max=2.0, d_step=0.25, maps_at=(-1.5,)), "maps_at D = -1.5 is outside"),
    (dict(d_min=-1.0, d_max=2.0, d_step=0.25, maps_at=(float("nan"),)), "maps_at must be finite"),
])
def test_maps_at_outside_the_path_refused(spec, words):
    with pytest.raises(ts.TengsimError) as e:
        PathSpec(**spec)
    assert words in str(e.value) and "\n" not in str(e.value)
    PathSpec(-1.0, 2.0, 0.25, maps_at=(-1.0, 2.0, 1.1))  # the ends and a D between lattice points: accepted
