"""Result status (tengsim.status): per-equilibrium and overall status, throw=, CLI warning lines, and the
under-resolution criterion (cohesive window ℓ < 1.2 dx at every contact edge, pixel snap number > 0.6, walled
faces known to worse than 1 %) checked on the LJ 9-3 sphere against
Maugis–Dugdale (λ = 1.157 μ) and JKR (1.5π).

Sphere units as in test_engine_adhesion: ℓ = sqrt(Rε), R = 1, κ = μ^{3/2}; pull-off ∬P = −π·P̄.
Runs here are small: cell 8–12, D step 0.25, one bisection level (pull-off agrees with a 0.05 step
to < 1 % at μ = 1 and exactly at μ = 3, where it sits at a jump).
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np
import pytest

from tengsim.run.plan import ContactPlan
import tengsim as ts
from tengsim import references as ref
from tengsim import status as st
from tengsim.cli.contact import write_contact
from tengsim.grid import Grid
from tengsim.laws import LJ93, Law, Repulsive
from tengsim.results.read import load_result
from tengsim.results import CURVE_COLUMNS, ContactResult

MD_TOL = 0.07  # the LJ sphere's grid-converged pull-off lies within 7 % of MD (test_engine_adhesion)
S0 = 16 / (9 * np.sqrt(3))  # LJ 9-3 tensile peak stress


@lru_cache(maxsize=None)
def sphere(mu, dx, cell, d_min, throw=False):
    path = ts.PathSpec(d_min, 0.5, 0.25, refine_levels=1)
    return ts.simulate(ContactPlan(ts.Paraboloid(1.0, cell), mu, dx, path), throw=throw)


def pulloff(res) -> float:
    """P̄ = −min ∬P / π over the retraction branch."""
    return -3 * res.pull_off_force


def md(mu):
    return ref.maugis_dugdale_pulloff_from_tabor(mu)


# ---- the law's cohesive window and the a-priori estimate ------------------------------------------

def test_cohesive_window_of_lj93():
    w = st.cohesive_window(LJ93())
    assert w.g_peak == pytest.approx(3 ** (1 / 6), rel=1e-8)
    assert w.sigma0 == pytest.approx(S0, rel=1e-10)
    assert w.g0 == pytest.approx(1.0, abs=1e-12)
    assert w.work == pytest.approx(1.0, rel=1e-12)
    assert w.h0 == pytest.approx(9 * np.sqrt(3) / 16, rel=1e-10)
    assert st.cohesive_window(Repulsive()) is None

    class Unhashable(Law):  # a user's law need not be hashable, nor declare its numbers
        g_safe = 0.6
        __hash__ = None

        def _raw(self, g, need_dp=True):
            return LJ93()._raw(g, need_dp)

    u = st.cohesive_window(Unhashable())  # the base class's numerical search, vs LJ93's closed forms
    for name in ("g_peak", "g0", "sigma0", "work"):
        assert getattr(u, name) == pytest.approx(getattr(w, name), rel=1e-9), name
    assert st.law_softening(Unhashable()) == pytest.approx(st.law_softening(LJ93()), rel=1e-9)

    class DuckLaw:  # no Law at all: only g_safe and evaluate (the LawLike protocol)
        g_safe = 0.6

        def evaluate(self, g):
            return LJ93().evaluate(g)

    d = st.cohesive_window(DuckLaw())
    for name in ("g_peak", "g0", "sigma0", "work"):
        assert getattr(d, name) == pytest.approx(getattr(w, name), rel=1e-9), name
    assert st.law_softening(DuckLaw()) == pytest.approx(st.law_softening(LJ93()), rel=1e-6)
    assert np.isnan(st.process_zone_estimate(Repulsive(), 1.0))


def test_status_reads_the_laws_declared_numbers():
    """The window and the softening are the law's own declarations (tengsim.laws.Law), not a search."""
    from tengsim.laws import Exponential, MaugisDugdale

    for law in (LJ93(), MaugisDugdale(smoothing=0.4, wall_stiffness=1e4), Exponential(range=0.5)):
        w = st.cohesive_window(law)
        assert (w.g_peak, w.g0, w.sigma0, w.work) == (law.g_peak, law.g_zero, law.max_tension, law.work)
        assert w.h0 == pytest.approx(law.cohesive_range, rel=1e-15)
        assert st.law_softening(law) == law.max_softening
    assert st.law_softening(Repulsive()) == 0.0
    assert st.law_softening(LJ93()) == pytest.approx(4.8 * 7.5 ** (-2 / 3), rel=1e-15)


@pytest.mark.parametrize("mu", [3.0, 5.0, 8.0])
def test_estimate_is_md_zone_in_jkr_limit(mu):
    """π/(4κσ0²) equals the Maugis–Dugdale c − a at pull-off to 10 % (+8.6, +3.2, +1.2 %) for μ ≥ 3."""
    k = mu ** 1.5
    p = ref.maugis_dugdale_pulloff_point(ref.md_lambda_from_tabor(mu))
    c_minus_a = (p.m - 1) * p.A * (3 * np.pi * k / 4) ** (1 / 3)  # MD length scale (πWR²/K)^{1/3}, K = 4/(3κ)
    assert st.process_zone_estimate(LJ93(), k) == pytest.approx(np.pi / (4 * k * S0**2), rel=1e-9)
    assert st.process_zone_estimate(LJ93(), k) == pytest.approx(c_minus_a, rel=0.10)


def test_estimate_bounds_md_zone_below_jkr_limit():
    p = ref.maugis_dugdale_pulloff_point(ref.md_lambda_from_tabor(1.0))
    assert (p.m - 1) * p.A * (3 * np.pi / 4) ** (1 / 3) < st.process_zone_estimate(LJ93(), 1.0)


# ---- the measured window on synthetic profiles ----------------------------------------------------

def test_process_zone_width_on_a_linear_opening():
    """Flat contact (g = 1) to x = a, then g = 1 + s (x − a): ℓ = (g0 + h0 − g*)/s, any dx."""
    w = st.cohesive_window(LJ93())
    for dx, s, a in [(0.1, 2.0, 1.03), (0.05, 0.7, 0.51), (0.3, 1.0, 2.0)]:
        n = 81
        x = (np.arange(n) - n // 2) * dx
        g = 1.0 + s * np.maximum(np.abs(x) - a, 0.0)
        H = np.repeat((g - 1.0)[:, None], 5, axis=1)
        ell = st.process_zone_width(H, dx, (n // 2, 2), LJ93())
        assert ell == pytest.approx((w.g_end - w.g_peak) / s, rel=1e-9)
    # no contact on the row (gap open at the apex): not judged
    H = np.full((21, 3), 2.0)
    assert np.isnan(st.process_zone_width(H, 0.1, (10, 1), LJ93()))
    assert np.isnan(st.process_zone_width(np.zeros((21, 3)), 0.1, (10, 1), Repulsive()))


def _table(**cols):
    n = len(cols["D"])
    base = dict(branch=np.array(["approach"] * n), converged=np.ones(n, bool),
                in_law_range=np.ones(n, bool), process_zone=np.full(n, np.nan))
    base.update(cols)
    return base


def test_classify_worst_first_and_overall():
    t = _table(D=np.arange(5.0), converged=np.array([1, 0, 1, 1, 0], bool),
               in_law_range=np.array([1, 1, 0, 1, 0], bool),
               process_zone=np.array([0.5, 0.01, 0.01, 0.01, np.nan]))
    s = st.classify(t, dx=0.1)
    assert list(s) == ["ok", "not_converged", "out_of_law_range", "under_resolved", "not_converged"]
    assert st.overall(s) == "not_converged"
    assert st.overall(s[[0, 3]]) == "under_resolved"
    assert st.overall(["ok", "ok"]) == "ok"
    # just above the threshold (1.2 dx) is resolved, just below is not; zero means "not measured" (older files)
    t2 = _table(D=np.arange(3.0), process_zone=np.array([0.1201, 0.1199, 0.0]))
    assert list(st.classify(t2, 0.1)) == ["ok", "under_resolved", "ok"]


def _fake_result(flag_rows):
    n = 6
    rows = []
    for i in range(n):
        rows.append(dict(branch="approach" if i < 3 else "retraction", D=[0.0, 0.5, 1.0, 1.0, 0.5, 0.0][i],
                         F=0.0, contact_length=0.0, area_repulsive=0.0, converged=i not in flag_rows["nc"],
                         residual=0.0, iterations=1, n_conv=1, on_grid=True, jump=False, min_gap=0.0,
                         max_pressure=0.0, min_pressure=0.0, energy=0.0, seconds=0.0,
                         in_law_range=i not in flag_rows["out"],
                         process_zone=0.01 if i in flag_rows["coarse"] else float("nan")))
    res = ContactResult.from_rows(rows, [], Grid(5, 5, 0.1, 0.1), params={"tol": 1e-6, "g_safe": 0.6})
    return st.attach(res, LJ93(), 1.0)


def test_write_contact_prints_one_line_per_kind_naming_where(tmp_path, capsys):
    res = _fake_result({"nc": {4}, "out": {1, 2}, "coarse": {3, 4, 5}})
    assert res.status == "not_converged"
    assert write_contact(res, tmp_path / "r.csv", quiet=True) == 0  # a warning, not an error
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 3 and all(l.startswith("tengsim: warning: ") for l in err)
    assert "not converged" in err[0] and "1 of 6 equilibria (retraction D 0.5)" in err[0]
    assert "out of the law's range" in err[1] and "2 of 6 equilibria (approach D 0.5…1)" in err[1]
    assert "under-resolved" in err[2] and "retraction D 1…0" in err[2] and "dx = 0.1" in err[2]
    assert "Traceback" not in "".join(err)
    # the CSV carries the per-row status; load_result gives it back
    kind, back = load_result(tmp_path / "r.csv")
    assert list(back.table["status"]) == list(res.table["status"])
    assert back.status == "not_converged"


def test_clean_result_has_no_warning(tmp_path, capsys):
    res = _fake_result({"nc": set(), "out": set(), "coarse": set()})
    assert res.status == "ok" and "warning" not in res.params
    assert res.raise_for_status() is res
    assert write_contact(res, tmp_path / "r.csv", quiet=True) == 0
    assert capsys.readouterr().err == ""


def test_status_column_in_netcdf(tmp_path):
    res = _fake_result({"nc": set(), "out": {1}, "coarse": set()})
    res.save(tmp_path / "r.nc")
    _, back = load_result(tmp_path / "r.nc")
    assert list(back.table["status"]) == list(res.table["status"])
    assert back.status == "out_of_law_range"
    import xarray as xr

    assert xr.load_dataset(tmp_path / "r.nc").attrs["status"] == "out_of_law_range"
    assert "status" in CURVE_COLUMNS and "process_zone" in CURVE_COLUMNS


# ---- the criterion on the sphere against MD and JKR -----------------------------------------------

def test_coarse_sphere_mu3_is_flagged_and_wrong():
    """The users' case: μ = 3, dx 0.4 pulls off ~46 % above MD with every row converged → flagged."""
    res = sphere(3.0, 0.4, 8.0, -4.5)
    assert res.all_converged
    assert res.status == "under_resolved"
    assert res.params["status"] == "under_resolved"
    assert pulloff(res) > (1 + MD_TOL) * md(3.0)   # measured +46 %
    assert pulloff(res) > (1 + MD_TOL) * 1.5       # and far from the JKR limit
    i = np.argmin(np.where(res.table["branch"] == "retraction", res.table["F"], np.inf))
    assert res.table["status"][i] == "under_resolved"  # the pull-off row itself
    assert res.table["process_zone"][i] < 0.75 * res.grid.dx
    assert "under-resolved" in res.params["warning"]


def test_throw_raises_with_the_result():
    with pytest.raises(st.ResultStatusError) as exc:
        sphere(1.0, 0.6, 12.0, -2.5, throw=True)
    assert isinstance(exc.value, ts.TengsimError)
    assert exc.value.result.status == "under_resolved"
    assert "under-resolved" in str(exc.value) and "retraction D" in str(exc.value)
    assert sphere(1.0, 0.2, 12.0, -2.5, throw=True).status == "ok"  # a resolved run returns


@pytest.mark.parametrize("mu, dx, cell, d_min, flagged", [
    (0.5, 0.4, 12.0, -1.5, False),   # ℓ/dx = 1.6, +4.9 % vs MD (grid-converged +5.2 %)
    (1.0, 0.2, 12.0, -2.5, False),   # ℓ/dx = 1.8, +4.8 % (converged +4.9 %)
    (1.0, 0.6, 12.0, -2.5, True),    # ℓ/dx = 0.57, +13.7 %
    (0.5, 0.8, 12.0, -1.5, True),    # ℓ/dx = 0.64, +10.9 %
])
def test_flag_matches_pulloff_error(mu, dx, cell, d_min, flagged):
    """Flagged runs are off MD by more than the 7 % tolerance; resolved runs are within it."""
    res = sphere(mu, dx, cell, d_min)
    assert res.all_converged
    err = pulloff(res) / md(mu) - 1
    if flagged:
        assert res.status == "under_resolved"
        assert abs(err) > MD_TOL
    else:
        assert res.status == "ok"
        assert abs(err) < MD_TOL


def test_measured_zone_tracks_md_zone():
    """At a resolved pull-off the measured window ℓ is 0.6–0.8 of MD's c − a (μ = 1: 0.349 vs 0.465)."""
    res = sphere(1.0, 0.2, 12.0, -2.5)
    r = res.table["branch"] == "retraction"
    i = np.flatnonzero(r)[np.argmin(res.table["F"][r])]
    p = ref.maugis_dugdale_pulloff_point(ref.md_lambda_from_tabor(1.0))
    c_minus_a = (p.m - 1) * p.A * (3 * np.pi / 4) ** (1 / 3)
    assert 0.6 < res.table["process_zone"][i] / c_minus_a < 0.8


@pytest.mark.slow
def test_mu3_grid_sequence():
    """μ = 3 (ℓ ≈ 0.09), cell 10: dx 0.1 within 7 % of MD and 4 % of JKR (+2.4 %, +3.3 %), but flagged since
    issue 22 item 2 (ℓ = 0.9 dx < 1.2 dx, s = 0.66 > 0.6: the calibration's μ = 3 sphere at dx 0.089 moves its
    jump-out D by 0.016 ε from dx 0.049, benchmarks/results/status_calibration.md);
    dx 0.2 and 0.3 flagged and more than 2.5 % off the dx 0.1 run (measured +3.4 %, +19 %), dx 0.3
    also more than 7 % off MD (+21 %).  (dx 0.2 gives +5.9 % over MD in a cell of 10 but +8.3 % in a
    cell of 12: an under-resolved pull-off depends on where the lattice meets the edge.)  About 3 min."""
    fine, mid, coarse = (sphere(3.0, dx, 10.0, -4.5) for dx in (0.1, 0.2, 0.3))
    assert fine.status == "under_resolved"
    assert fine.params["pixel_snap_number"] > st.SNAP_LIMIT
    assert abs(pulloff(fine) / md(3.0) - 1) < MD_TOL
    assert pulloff(fine) == pytest.approx(1.5, rel=0.04)
    for res in (mid, coarse):
        assert res.status == "under_resolved"
        assert abs(pulloff(res) / pulloff(fine) - 1) > 0.025
    assert pulloff(coarse) / md(3.0) - 1 > MD_TOL


@pytest.mark.slow
@pytest.mark.parametrize("dx", [0.3, 0.2])
def test_mu5_coarse_grids_are_flagged(dx):
    """μ = 5 (ℓ ≈ 0.05, a-priori 0.067): dx 0.3 and 0.2 are flagged; pull-off +57 % / +39 % over MD."""
    res = sphere(5.0, dx, 10.0, -6.0)
    assert res.status == "under_resolved"
    assert pulloff(res) / md(5.0) - 1 > MD_TOL


def test_older_files_without_status_columns(tmp_path):
    """A result written before the status columns existed loads, gets a status from its columns, and saves."""
    res = _fake_result({"nc": {2}, "out": set(), "coarse": set()})
    t = {k: v for k, v in res.table.items() if k not in ("status", "process_zone")}
    old = ContactResult(table=t, grid=res.grid, params=res.params)
    old.save(tmp_path / "old.nc")
    _, back = load_result(tmp_path / "old.nc")
    assert back.status == "not_converged"
    assert list(back.table["status"]) == ["ok", "ok", "not_converged", "ok", "ok", "ok"]  # worked out on load
    back.save(tmp_path / "again.csv")


# ---- pixel snap: a law softening faster than one pixel is stiff ------------------------------------

def test_pixel_snap_number_values():
    """s = max dP/dg × pixel compliance: MD (smoothing 0.2) at μ = 3, dx 0.05 is 2.0 (the run that pinned
    its edge, +8.2 % pull-off, docs/validation.md); smoothing 0.6 0.67; LJ93 at μ = 0.5, dx 0.1 0.05;
    no tension, no snap; s grows about as dx (pixel compliance of the half-space ∝ κ dx)."""
    from tengsim.laws import MaugisDugdale
    from tengsim.kernels import make_kernel

    def s(law, mu, dx):
        return st.pixel_snap_number(law, make_kernel("free", Grid.square(2.0, dx), mu ** 1.5))

    dx1, dx2 = Grid.square(2.0, 0.1).dx, Grid.square(2.0, 0.05).dx  # the grid rounds dx to its pixel count

    assert s(MaugisDugdale(), 3.0, 0.05) == pytest.approx(2.0, rel=0.02)
    assert s(MaugisDugdale(smoothing=0.6), 3.0, 0.05) == pytest.approx(0.67, rel=0.02)
    assert s(LJ93(), 0.5, 0.1) == pytest.approx(0.05, rel=0.1)
    assert s(Repulsive(), 3.0, 0.05) == 0.0
    assert s(MaugisDugdale(), 3.0, 0.1) / s(MaugisDugdale(), 3.0, 0.05) == pytest.approx(dx1 / dx2, rel=0.02)
    # the softening is the md ramp's σ0/smoothing (its steepest part, a smoothstep: 1.5×)
    assert st.law_softening(MaugisDugdale(smoothing=0.4)) == pytest.approx(1.5 * MaugisDugdale().tension / 0.4,
                                                                           rel=1e-3)


def test_snapping_run_is_under_resolved_with_its_own_line(tmp_path):
    """MD at μ = 3, dx 0.09, cell 3 (s = 4.1): rows with a contact edge are under-resolved although the
    process zone (every contact edge) is wider than 1.2 dx; the line names the snap and the dx
    that brings s to SNAP_LIMIT = 0.6; the status and the line survive a NetCDF round trip.  μ = 1 with
    the same law at dx 0.1 (s = 0.82) is under-resolved: the calibration's MD sphere at s = 0.79 pulls off
    1.7 % from its finest grid (+1.2 % over Maugis; this test asked 'ok' before issue 22 item 2, when the
    limit was s = 1); at dx 0.07 (s = 0.57; +0.9 % from the finest) it is ok."""
    from tengsim.laws import MaugisDugdale

    res = ts.simulate(ContactPlan(ts.Paraboloid(1.0, 3.0), 3.0, 0.09, ts.PathSpec(-1.0, 0.5, 0.25), law=MaugisDugdale()))
    s = res.params["pixel_snap_number"]
    assert s > 3
    assert res.status == "under_resolved"
    pz = res.table["process_zone"][res.table["status"] == "under_resolved"]
    assert len(pz) and np.all(pz > st.RESOLUTION * res.grid.dx)  # not the process-zone criterion
    (line,) = st.warning_lines(res)
    assert "snap" in line and f"refine dx to about {res.grid.dx * 0.6 / s:.3g}" in line
    assert 0.012 < res.grid.dx * 0.6 / s < 0.015
    f = tmp_path / "snap.nc"
    res.save(f)
    back = load_result(f)[1]
    assert back.status == "under_resolved" and st.warning_lines(back) == [line]
    soft = ts.simulate(ContactPlan(ts.Paraboloid(1.0, 6.0), 1.0, 0.1, ts.PathSpec(-1.0, 1.0, 0.25), law=MaugisDugdale()))
    assert 0.6 < soft.params["pixel_snap_number"] < 1 and soft.status == "under_resolved"
    (line,) = st.warning_lines(soft)
    assert "snap" in line and "process zone" not in line
    finer = ts.simulate(ContactPlan(ts.Paraboloid(1.0, 6.0), 1.0, 0.07, ts.PathSpec(-1.0, 1.0, 0.25), law=MaugisDugdale()))
    assert finer.params["pixel_snap_number"] < 0.6 and finer.status == "ok"
    assert np.isfinite(finer.table["process_zone"]).sum() > 10  # rows with an edge were judged


# ---- issue 22 item 2: every contact edge, walls, and the thresholds calibrated on grid convergence --------
# (benchmarks/status_calibration.py, docs/statuses.md "Calibration against grid convergence")

def _radial(dx, centres, n=81):
    """A gap with conical openings around several contact spots: g = 1 + s (r − a) outside each, the
    smallest over the spots; centres: [(x, y, a, s)]."""
    x = (np.arange(n) - n // 2) * dx
    X, Y = np.meshgrid(x, x, indexing="ij")
    g = np.full(X.shape, np.inf)
    for cx, cy, a, s in centres:
        g = np.minimum(g, 1.0 + s * np.maximum(np.hypot(X - cx, Y - cy) - a, 0.0))
    return g - 1.0


def test_edge_scan_finds_the_narrowest_spot_off_the_apex_row():
    """Two spots: the apex row crosses only the wide one (slope 1: ℓ = 0.85); the edge scan finds the
    narrow one (slope 4: ℓ = 0.21) off that row, to 10 % (the lattice meets a round edge unevenly)."""
    w = st.cohesive_window(LJ93())
    dx = 0.05
    H = _radial(dx, [(0.0, 0.0, 0.6, 1.0), (0.0, 1.4, 0.4, 4.0)], n=81)
    apex = (40, 40)
    assert st.process_zone_width(H, dx, apex, LJ93()) == pytest.approx((w.g_end - w.g_peak) / 1.0, rel=0.05)
    assert st.edge_process_zone(H, dx, LJ93()) == pytest.approx((w.g_end - w.g_peak) / 4.0, rel=0.10)


@pytest.mark.parametrize("theta", [0.0, np.pi / 6, np.pi / 4, 1.2])
def test_edge_scan_measures_normal_to_a_tilted_edge(theta):
    """A straight edge at any angle to the grid: the width normal to it, Δ/s, to 3 %."""
    w = st.cohesive_window(LJ93())
    dx, s, n = 0.05, 1.5, 61
    x = (np.arange(n) - n // 2) * dx
    X, Y = np.meshgrid(x, x, indexing="ij")
    H = s * np.maximum(X * np.cos(theta) + Y * np.sin(theta) - 0.2, 0.0)
    assert st.edge_process_zone(H, dx, LJ93()) == pytest.approx((w.g_end - w.g_peak) / s, rel=0.03)


def _cube_state(dx, edge_gap):
    """A cube face (half width 1, height 5, cell 3) in contact at g = 1, its edge pixels at ``edge_gap``."""
    from tengsim.shapes.flat_topped import Cube

    shape = Cube(1.0, 5.0, 3.0)
    grid = shape.grid(dx)
    U0 = shape.gap(grid)
    H = U0.copy()
    face = U0 == 0
    inner = ndimage_erode(face)
    H[face & ~inner] = edge_gap - 1.0
    return U0, H, grid


def ndimage_erode(mask):
    from scipy import ndimage

    return ndimage.binary_erosion(mask)


@pytest.mark.parametrize("dx", [0.2, 0.1, 0.05])
def test_wall_edges_are_judged_by_the_crack_tip_zone(dx):
    """A cube's edge is a wall: no dx makes the gap open gradually there.  The old apex-row window shrinks
    with dx (below 0.75 dx: flagged on every grid, whatever E*); the edge scan gives the crack-tip zone
    WALL_FACTOR × ℓ_D = 0.7 π/(4κσ0²), which depends on E* (κ) and not on dx, once the edge pixel is
    past the tensile peak; an edge still below the peak is not judged."""
    U0, H, grid = _cube_state(dx, edge_gap=1.3)
    for mu in (1.0, 2.4):
        k = mu**1.5
        scan = st.EdgeScan(U0, LJ93(), grid.dx, grid.dy, k)
        assert scan(H) == pytest.approx(st.WALL_FACTOR * st.process_zone_estimate(LJ93(), k), rel=1e-12)
    apex = (grid.nx // 2, grid.ny // 2)
    assert st.process_zone_width(H, grid.dx, apex, LJ93()) < 0.75 * grid.dx  # the old criterion: flagged at any dx
    U0, H, grid = _cube_state(dx, edge_gap=1.05)  # edge below g* = 1.12: the zone has not formed
    assert np.isnan(st.EdgeScan(U0, LJ93(), grid.dx, grid.dy, 1.0)(H))


def test_face_uncertainty_of_walled_faces():
    """Pixel-centre sampling leaves each wall within half a pixel: a square face n pixels wide is known to
    2/n of its area, a ridge to 1/n; a smooth shape has no walls (0), nor the paraboloid's far corners."""
    from tengsim.shapes.flat_topped import Cube, Line

    for shape, per_width in ((Cube(1.0, 5.0, 3.0), 2.0), (Line(1.0, 5.0, 3.0), 1.0)):
        for dx in (0.2, 0.05):
            grid = shape.grid(dx)
            U0 = shape.gap(grid)
            n = int((U0[:, grid.ny // 2] == 0).sum())
            assert st.EdgeScan(U0, LJ93(), grid.dx).face == pytest.approx(per_width / n, rel=1e-12)
    for shape in (ts.Paraboloid(1.0, 12.0), ts.Paraboloid(1.0, 5.0)):
        grid = shape.grid(0.4)
        assert st.EdgeScan(shape.gap(grid), LJ93(), grid.dx).face == 0.0


def test_row_status_thresholds():
    """snap s > SNAP_LIMIT = 0.6 and face uncertainty > FACE_LIMIT = 1 % flag a judged row; rows with no
    contact edge (NaN zone) are not judged."""
    assert (st.SNAP_LIMIT, st.FACE_LIMIT, st.RESOLUTION) == (0.6, 0.01, 1.2)
    for snap, face, want in [(0.59, 0.0, "ok"), (0.61, 0.0, "under_resolved"), (0.0, 0.0099, "ok"),
                             (0.0, 0.0101, "under_resolved")]:
        assert st.row_status(True, True, 1.0, 0.1, snap, face) == want
        assert st.row_status(True, True, float("nan"), 0.1, snap, face) == "ok"
    t = _table(D=np.arange(3.0), process_zone=np.array([1.0, np.nan, 1.0]))
    assert list(st.classify(t, 0.1, 0.7, 0.0)) == ["under_resolved", "ok", "under_resolved"]
    assert list(st.classify(t, 0.1, 0.0, 0.05)) == ["under_resolved", "ok", "under_resolved"]


def _pulloff_run(shape, mu, dx, path, boundary="free", law=None):
    res = ts.simulate(ContactPlan(shape, mu, dx, ts.PathSpec(*path[:3], refine_levels=path[3]), boundary=boundary, law=law))
    return res


def test_cube_coarse_grids_that_move_are_flagged():
    """Calibration (cube, LJ 9-3, μ = 2.4, half width 1, cell 3): dx 0.2 and 0.1 pull off 17 % and 3.7 %
    away from dx 0.05 (the face is rasterised to 11 and 23 pixels); both are flagged (face uncertainty
    18 % and 8.7 %), not by the crack-tip zone (0.7 ℓ_D = 0.14 ≥ 1.2 dx at dx 0.1).  Old criterion: the
    apex-row window ∝ dx flagged every grid.  About 3 s."""
    from tengsim.shapes.flat_topped import Cube

    runs = {dx: _pulloff_run(Cube(1.0, 5.0, 3.0), 2.4, dx, (-5.0, 0.3, 0.5, 3)) for dx in (0.2, 0.1, 0.05)}
    fine = runs[0.05].pull_off_force
    for dx in (0.2, 0.1):
        r = runs[dx]
        assert abs(r.pull_off_force / fine - 1) > 0.01
        assert r.status == "under_resolved"
        assert "flat face bounded by walls" in r.params["warning"]
        assert "process zone" not in r.params["warning"] or dx == 0.2
    zone = np.nanmin(runs[0.1].table["process_zone"])
    assert zone == pytest.approx(st.WALL_FACTOR * st.process_zone_estimate(LJ93(), 2.4**1.5), rel=1e-9)


@pytest.mark.slow
def test_issue_md_sphere_dx02_is_flagged(tmp_path, capsys):
    """Issue 22's case: `tengsim contact sphere --law md --tabor 1 --cell 16 --d-min -2 --d-max 0.5
    --d-step 0.05 --dx 0.2` is under_resolved (pixel snap number 1.71 > 0.6; its pull-off is 8 % from the
    finest grid of the calibration's MD sphere), with the snap line naming the dx to reach.  About 50 s."""
    from tengsim.cli.main import main

    out = tmp_path / "md.csv"
    rc = main(["contact", "sphere", "--law", "md", "--tabor", "1", "--cell", "16", "--d-min", "-2", "--d-max", "0.5",
               "--d-step", "0.05", "--dx", "0.2", "--out", str(out), "--quiet"])
    assert rc == 0 and out.exists()
    err = capsys.readouterr().err
    assert "under-resolved" in err and "snap" in err
    import re

    assert float(re.search(r"refine dx to about ([0-9.]+)", err).group(1)) == pytest.approx(0.2 * 0.6 / 1.71, rel=0.03)
    _, res = load_result(out)
    assert res.status == "under_resolved"
    assert res.params["pixel_snap_number"] == pytest.approx(1.71, rel=0.02)
