"""The retraction where it retraces the approach (tengsim.continuation.retrace): rows taken from the approach
give the same path as every row solved — the same jumps, pull-off force, hysteresis and retraction curve — and
a path without an approach jump solves no retraction row at all."""
from __future__ import annotations

from functools import lru_cache

import numpy as np
import pytest

import tengsim as ts
from tengsim.continuation import PathSpec, run_path
from tengsim.continuation.retrace import Retrace
from tengsim.kernels import FreeKernel, PeriodicKernel

MAPS = (-1.3, 0.1, -1.6171875, -1.7421875, 0.25)  # off the rows, inside both jump intervals, on the lattice


@lru_cache(maxsize=None)
def sphere(retrace: bool, adaptive: bool, maps_at=()):
    """A μ = 1 LJ sphere (free cell 8): a jump in, a jump out and a hysteresis loop between them."""
    shape = ts.Paraboloid(1.0, 8.0)
    grid = shape.grid(0.4)
    spec = PathSpec(-2.0, 0.5, 0.25, adaptive=adaptive, maps_at=maps_at)
    return run_path(shape.gap(grid), ts.LJ93(), FreeKernel(grid, 1.0), ts.FastSolver(1e-8), spec,
                    retrace=retrace), grid


@pytest.mark.parametrize("adaptive", [False, True])
@pytest.mark.parametrize("maps_at", [(), MAPS])
def test_retraced_path_is_the_solved_path(adaptive, maps_at):
    ref, grid = sphere(False, adaptive, maps_at)
    res, _ = sphere(True, adaptive, maps_at)
    assert ref.all_converged and res.all_converged
    copied = res.params["retraction_rows_copied"]
    assert copied > 0 and "retraction_rows_copied" not in ref.params
    scale = abs(ref.pull_off_force)
    assert res.pull_off_force == pytest.approx(ref.pull_off_force, rel=1e-6)
    assert [j.branch for j in res.jumps] == [j.branch for j in ref.jumps] == ["approach", "retraction"]
    for a, b in zip(ref.jumps, res.jumps):  # the same interval, or one inside the other (where rows differ)
        lo, hi = sorted((a.D_before, a.D_after))
        lo2, hi2 = sorted((b.D_before, b.D_after))
        assert max(lo, lo2) < min(hi, hi2)
    # the loop's energy within the uncertainty each run gives it (its rows differ in D: the quadrature's)
    assert abs(res.loop_energy.estimate - ref.loop_energy.estimate) <= max(res.loop_energy.bound,
                                                                          ref.loop_energy.bound)
    r, s = ref.branch("retraction"), res.branch("retraction")
    common, i, j = np.intersect1d(r["D"], s["D"], return_indices=True)
    assert len(common) >= 0.6 * len(r["D"])
    np.testing.assert_allclose(s["F"][j], r["F"][i], rtol=0, atol=1e-5 * scale)
    assert np.all(np.diff(s["D"]) < 0)  # path order
    # a copied row is the approach's row at its D, number for number, solved by nothing
    a = res.branch("approach")
    zero = (s["n_conv"] == 0) & (s["iterations"] == 0)
    assert zero.sum() == copied
    for D, F in zip(s["D"][zero], s["F"][zero]):
        assert F == a["F"][np.flatnonzero(a["D"] == D)[0]]
    # every requested D keeps its map on both branches, at exactly that D, the state of its row
    assert sorted((m["branch"], float(m["D"])) for m in res.maps) == sorted(
        (b, d) for b in ("approach", "retraction") for d in maps_at)
    for m in res.maps:
        row = res.branch(m["branch"])
        k = int(np.flatnonzero(row["D"] == m["D"])[0])
        assert ts.force(m["P"], grid) == row["F"][k]


def test_no_approach_jump_no_retraction_solve():
    """A repulsive periodic wavy contact (no adhesion, no jump): the whole retraction is the approach reversed
    and costs nothing; with every row solved it is the same to the solver's tolerance."""
    n = 32
    x = np.arange(n) / n
    U0 = 2.0 * (1 - np.cos(2 * np.pi * x))[:, None] * np.ones(n)[None, :] + 0.5 * (1 - np.cos(2 * np.pi * x))[None, :]
    grid = ts.Grid(n, n, 8.0 / n, 8.0 / n)
    law = ts.Repulsive()
    spec = PathSpec(-1.0, 2.0, 0.25)
    runs = {rt: run_path(U0, law, PeriodicKernel(grid, 1.0), ts.FastSolver(1e-8), spec, retrace=rt)
            for rt in (True, False)}
    res, ref = runs[True], runs[False]
    a, s = res.branch("approach"), res.branch("retraction")
    assert res.all_converged and not res.jumps
    assert res.params["retraction_rows_copied"] == len(s["D"]) - 1
    np.testing.assert_array_equal(s["D"], a["D"][::-1])
    np.testing.assert_array_equal(s["F"], a["F"][::-1])
    assert np.all(s["n_conv"][1:] == 0)
    assert res.params["n_conv_spent"] < ref.params["n_conv_spent"]
    r = ref.branch("retraction")
    np.testing.assert_allclose(s["F"], r["F"], rtol=1e-5, atol=1e-8 * np.max(np.abs(r["F"])))


class _Rec:
    def __init__(self):
        self.rows = []


def test_a_row_of_another_branch_is_not_taken_for_the_approachs():
    """The branch test (energy, force, charged area): a row whose energy differs by 1e-5 (relative) or whose
    force differs by 1 % of the path's scale is another equilibrium; within 1e-9 and 1e-5 it is the same."""
    rec = _Rec()
    tr = Retrace(rec)

    def row(D, F, E, c, jump=False):
        return dict(D=D, F=F, energy=E, charged_fraction=c, jump=jump)

    for k, D in enumerate((0.0, 0.1, 0.2, 0.3)):
        rec.rows.append(row(D, -1.0 + k, -5.0 + k, 0.1 * k, jump=(k == 1)))
        tr.rows.append(len(rec.rows) - 1)
        tr.by_D[round(D, 9)] = k
    tr.kept.put(1, ts.State(np.arange(4.0), -np.arange(4.0)))
    same = row(0.3, 2.0 + 1e-5, -2.0 * (1 + 1e-9), 0.3)
    assert tr._same(same, 3)
    assert not tr._same(row(0.3, 2.0, -2.0 * (1 + 1e-5), 0.3), 3)
    assert not tr._same(row(0.3, 2.0 + 0.02, -2.0, 0.3), 3)
    assert not tr._same(row(0.3, 2.0, -2.0, 0.32), 3)
    assert not tr._same(row(0.3, 2.0, float("nan"), 0.3), 3)
    # from the top it copies down to the jump's row (position 1, its state kept), not past it
    assert tr.lower(3) == 1
    tr.kept.pop(1)
    assert tr.lower(3) is None


def test_the_kept_states_come_back_from_disk_bit_for_bit_in_reused_slots():
    from tengsim.continuation.retrace import Spill

    rng = np.random.default_rng(0)
    spill = Spill()
    states = {k: ts.State(rng.standard_normal((5, 7)), rng.standard_normal((5, 7)).astype(np.float32))
              for k in range(4)}
    for k in (0, 1, 2):
        spill.put(k, states[k])
    spill.pop(1)
    spill.put(("above", 3), states[3])  # takes the freed slot
    assert 1 not in spill and ("above", 3) in spill and 0 in spill
    for key, k in ((0, 0), (2, 2), (("above", 3), 3)):
        got = spill.get(key)
        assert got.q.dtype == states[k].q.dtype and got.w.dtype == np.float32
        np.testing.assert_array_equal(got.q, states[k].q)
        np.testing.assert_array_equal(got.w, states[k].w)
    assert spill._file.seek(0, 2) == 3 * 35 * (8 + 4)  # three slots: the freed one was reused


def test_approach_stops_past_its_force():
    """``PathSpec(stop_force=...)``: the approach's rows are the full path's up to the step after its first row
    past the force (every map's D passed first), the retraction walks back from there, the progress ends at its
    total, and the lattice rows keep ``on_grid``."""
    shape = ts.Paraboloid(1.0, 8.0)
    grid = shape.grid(0.4)
    seen = []

    def run(stop, maps_at=()):
        spec = PathSpec(-2.0, 4.0, 0.25, adaptive=True, maps_at=maps_at, stop_force=stop)
        return run_path(shape.gap(grid), ts.LJ93(), FreeKernel(grid, 1.0), ts.FastSolver(1e-8), spec,
                        progress=lambda b, D, done, total: seen.append((done, total)))

    full = run(None)
    a_full = full.branch("approach")
    stop = 0.5 * float(np.max(a_full["F"]))
    assert stop > 0
    seen.clear()
    res = run(stop)
    a = res.branch("approach")
    k = int(np.flatnonzero(a["F"] >= stop)[0])
    assert len(a["D"]) == k + 2 < len(a_full["D"])  # the row past the force, and the step after it
    np.testing.assert_array_equal(a["D"][:k + 1], a_full["D"][:k + 1])
    np.testing.assert_array_equal(a["F"][:k + 1], a_full["F"][:k + 1])
    r = res.branch("retraction")
    assert r["D"][0] == a["D"][-1] and r["F"][0] == a["F"][-1] and r["D"][-1] == -2.0
    assert res.all_converged
    assert seen[-1][0] == seen[-1][1]  # the progress ends at its own total
    lattice = np.isclose(((r["D"] + 2.0) / 0.25) % 1.0, 0.0) | np.isclose(((r["D"] + 2.0) / 0.25) % 1.0, 1.0)
    np.testing.assert_array_equal(r["on_grid"].astype(bool), lattice)
    # a map asked above the force's D: the approach goes on to it
    late = float(a_full["D"][-3])
    res2 = run(stop, (late,))
    assert np.max(res2.branch("approach")["D"]) >= late
    assert sorted((m["branch"], float(m["D"])) for m in res2.maps) == [("approach", late), ("retraction", late)]
    with pytest.raises(ts.TengsimError, match="stop_force"):
        PathSpec(-2.0, 2.0, 0.25, stop_force=float("nan"))
