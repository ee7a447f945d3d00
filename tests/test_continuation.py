"""The continuation package (issue 28): one walker, the step control passed in.

Group B (the paper's pyramid, μ = 0.725) at dx 0.4 jumps in on the approach and out on the retraction
between D = -1 and 4 (at D ≈ 3.3 and 2.8); each path here takes about a second.
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np
import pytest

import tengsim as ts
from tengsim.cases.paper.units import paper_scaling
from tengsim.continuation import BRANCHES, FixedSteps, PathSpec, Walker, run_path, walk_states
from tengsim.kernels import FreeKernel
from tengsim.solvers import State


@lru_cache(maxsize=None)
def group_b():
    sc = paper_scaling("B")
    shape = ts.Pyramid(sc.N, sc.cell)
    grid = shape.grid(0.4)
    return shape.gap(grid), ts.LJ93(), FreeKernel(grid, sc.mu**1.5)


@lru_cache(maxsize=None)
def path(refine_levels):
    U0, law, kernel = group_b()
    return run_path(U0, law, kernel, ts.FastSolver(1e-6), PathSpec(-1.0, 4.0, 0.5, refine_levels=refine_levels))


@pytest.mark.parametrize("levels", [0, 3])
def test_fixed_steps_bisect_each_jump_to_the_smallest_step(levels):
    """Every jump is bracketed by d_step / 2^levels; rows off the d_step lattice exist only with bisection,
    and only around the jumps; the lattice rows are all there on both branches."""
    res = path(levels)
    h = 0.5 / 2**levels
    assert {j.branch for j in res.jumps} == set(BRANCHES)
    for j in res.jumps:
        assert abs(abs(j.D_after - j.D_before) - h) < 1e-12
    t = res.table
    for b in BRANCHES:
        on = np.asarray(t["D"])[(np.asarray(t["branch"]) == b) & np.asarray(t["on_grid"], bool)]
        assert sorted(np.round(on, 9)) == sorted(np.round(np.arange(-1.0, 4.0 + 1e-9, 0.5), 9))
    off = np.asarray(t["D"])[~np.asarray(t["on_grid"], bool)]
    assert (len(off) > 0) == (levels > 0)
    jumps = [(j.D_before, j.D_after) for j in res.jumps]
    assert all(min(abs(D - a) for a, _ in jumps) < 0.5 for D in off)  # bisection only near a jump


def test_bisection_keeps_the_branches_where_they_jump():
    """The finer bracket finds the same jumps (branch and direction) within the coarse bracket, and the
    states far from the jumps are the same equilibria (F to the solver tolerance)."""
    coarse, fine = path(0), path(3)
    assert [(j.branch, j.kind) for j in coarse.jumps] == [(j.branch, j.kind) for j in fine.jumps]
    for jc, jf in zip(coarse.jumps, fine.jumps):
        lo, hi = sorted((jc.D_before, jc.D_after))
        assert lo - 1e-12 <= min(jf.D_before, jf.D_after) and max(jf.D_before, jf.D_after) <= hi + 1e-12
    tc, tf = coarse.branch("approach"), fine.branch("approach")
    for D, F in zip(tc["D"], tc["F"]):
        if D <= coarse.jumps[0].D_before - 1e-9 or D >= coarse.jumps[0].D_after + 1e-9:
            (i,) = np.flatnonzero(np.abs(tf["D"] - D) < 1e-9)
            assert F == pytest.approx(tf["F"][i], rel=1e-4, abs=1e-6)


class _Stops:
    """A step control of the test's own (the walker's protocol, nothing imported): the stops, never refined."""

    predictor, c_max = True, 1.5

    def plan(self, walker, eq, D_from, stops, on_grid):
        todo = list(stops)[::-1]

        class Plan:
            predictor, c_max = self.predictor, self.c_max

            def next(self):
                return todo[-1] if todo else None

            def refine(self, Da, Db):
                return False

            def accept(self, Da, eqa, Db, eqb, jump):
                todo.pop()
                return [(Db, eqb, on_grid, jump)], ()

            def finish(self):
                return ()
        return Plan()


def test_a_step_control_is_passed_in_and_the_walker_is_the_one_loop():
    """A user's step control walks the same equilibria as FixedSteps(refine_levels=0), and both as
    walk_states (the same predictor and solve): iterations and F equal, on a smooth stretch (D -1 → 0)."""
    U0, law, kernel = group_b()
    Ds = np.linspace(-1.0, 0.0, 5)

    def walk(steps):
        rows = []
        w = Walker(U0, law, kernel, ts.FastSolver(1e-6), steps, lambda *r: rows.append(r))
        w.begin(Ds[0], w.solve(Ds[0], State.zero(kernel.grid.shape)))
        w.walk(Ds[1:])
        return [(D, eq.iterations, float(eq.P.sum())) for D, eq, *_ in rows]

    mine, fixed = walk(_Stops()), walk(FixedSteps(refine_levels=0))
    ref = [(D, eq.iterations, float(eq.P.sum())) for D, eq in walk_states(U0, law, kernel, ts.FastSolver(1e-6), Ds)]
    assert mine == fixed
    assert [r[:2] for r in mine] == [r[:2] for r in ref]
    assert np.allclose([r[2] for r in mine], [r[2] for r in ref], rtol=0, atol=0)


def test_the_walker_hands_its_equilibrium_over():
    """take() leaves the walker without a reference to the current equilibrium."""
    U0, law, kernel = group_b()
    w = Walker(U0, law, kernel, ts.FastSolver(1e-6), FixedSteps(0), lambda *r: None)
    w.begin(-1.0, w.solve(-1.0, State.zero(kernel.grid.shape)))
    last = w.walk([-0.5])
    assert w.take() is last and w.eq is None and w.hist[-1][0] == -0.5
