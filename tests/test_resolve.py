"""Automatic grid refinement (``resolve = "auto"``, tengsim.run.resolve; issue 22 item 1).

Fast: Richardson on synthetic sequences of known order; a cheap pyramid refinement (5 grids, about 2 s)
reaching ``ok``; ``max_pixels`` stopping it with ``under_resolved`` and its one line; the resolution table
through CSV and NetCDF (CF check) and ``tengsim plot``; the refusals.  Slow: the Maugis–Dugdale sphere of
the issue's done-when.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from tengsim.run import judge, resolve, simulate
from tengsim.cli.main import main
from tengsim.errors import TengsimError
from tengsim.results.read import load_result

PYR = ["contact", "pyramid", "--N", "0.946", "--cell", "3.78", "--tabor", "0.5", "--d-min", "-1", "--d-max", "2",
       "--d-step", "0.1", "--dx", "0.4", "--resolve", "auto", "--quiet"]
PYR_CFG = {"shape": "pyramid", "N": 0.946, "cell": 3.78, "tabor": 0.5, "d_min": -1.0, "d_max": 2.0, "d_step": 0.1,
           "dx": 0.4, "resolve": "auto"}


# ---- Richardson -------------------------------------------------------------------------------------
@pytest.mark.parametrize("p", [0.8, 1.0, 2.0, 3.0])
def test_richardson_recovers_a_known_order_on_uneven_grids(p):
    h = [0.42, 0.29, 0.18]  # ratios 1.45, 1.61: as the FFT-friendly pixel counts give them
    f = [2.0 + 0.7 * x**p for x in h]
    r = judge.richardson(h, f)
    assert r["observed"] and r["order"] == pytest.approx(p, rel=1e-8)
    assert r["extrapolated"] == pytest.approx(2.0, abs=1e-10)
    assert r["error"] == pytest.approx(2.0 - f[-1], rel=1e-8)


def test_richardson_two_grids_assume_first_order_and_odd_cases():
    r = judge.richardson([0.2, 0.1], [1.2, 1.1])  # order 1 assumed: error = Δ/(r − 1)
    assert not r["observed"] and r["order"] == 1.0 and r["error"] == pytest.approx(-0.1)
    r = judge.richardson([0.4, 0.2, 0.1], [1.0, 1.2, 1.1])  # not monotone: order 1, not measured
    assert not r["observed"] and r["order"] == 1.0
    r = judge.richardson([0.4, 0.2, 0.1], [1 + 0.4**6, 1 + 0.2**6, 1 + 0.1**6])  # clipped to P_MAX
    assert r["observed"] and r["order"] == judge.P_MAX
    assert math.isnan(judge.richardson([0.2], [1.0])["error"])
    assert math.isnan(judge.richardson([0.2, 0.1], [1.0, math.nan])["error"])


def test_relative_change_has_an_absolute_floor():
    assert judge.relative("jump_in_D", 0.005, 0.0) == pytest.approx(0.005)  # floor 1 ε
    assert judge.relative("pull_off_F", 1e-4, 0.0) == pytest.approx(0.01)  # floor 0.01
    assert judge.relative("pull_off_F", -0.05, -5.0) == pytest.approx(0.01)


# ---- a cheap refinement -----------------------------------------------------------------------------
@pytest.fixture(scope="module")
def refined(tmp_path_factory):
    d = tmp_path_factory.mktemp("resolve")
    assert main([*PYR, "--out", str(d / "r.nc")]) == 0
    load_result(d / "r.nc")[1].save(d / "r.csv")  # the same result as CSV (a CLI run writes it the same way)
    return d


def test_cheap_refinement_reaches_ok(refined):
    _, res = load_result(refined / "r.nc")
    p = res.params
    assert res.status == "ok" and p["resolve_status"] == "ok" and p["resolve"] == "auto"
    assert p["resolve_tol"] == 0.01 and p["max_pixels"] >= 9
    grids = p["resolve_grids"]
    assert len(grids) >= 3 and grids[0] == pytest.approx(0.42, rel=0.01)
    ratios = np.array(grids[:-1]) / np.array(grids[1:])
    assert np.all((ratios > 1.3) & (ratios < 1.7))  # √2 in dx, to the FFT-friendly pixel counts
    assert res.grid.dx == pytest.approx(grids[-1], rel=1e-12)  # the finest grid's curves
    tab = p["resolution"]
    assert tab["nx"][-1] == res.grid.nx and tab["status"][-1] == "ok" and len(tab["dx"]) == len(grids)
    assert all(s > 0 for s in tab["seconds"]) and all(c > 0 for c in tab["convolutions"])
    assert tab["pull_off_F"][-1] == pytest.approx(res.pull_off_force, rel=1e-12)
    for name in ("pull_off_F", "transition_D"):
        r = p["richardson"][name]
        assert r["rel_error"] <= 0.01 and r["change"] <= 0.01, name
    # the curves are exactly those of a plain run on the finest grid
    from tengsim.run.simulate import simulate as run_contact

    plain = run_contact({k: v for k, v in PYR_CFG.items() if k != "resolve"} | {"dx": grids[-1]})
    np.testing.assert_allclose(res.table["F"], plain.table["F"], rtol=0, atol=1e-9)


def test_csv_and_netcdf_carry_the_same_table(refined):
    _, a = load_result(refined / "r.nc")
    _, b = load_result(refined / "r.csv")
    ta, tb = a.params["resolution"], b.params["resolution"]
    assert set(ta) == set(tb) == {"dx", "nx", "ny", "seconds", "convolutions", "status", "pull_off_F",
                                  "jump_in_D", "jump_out_D", "transition_D"}
    assert ta == tb
    assert a.params["richardson"] == b.params["richardson"]
    import xarray as xr

    ds = xr.load_dataset(refined / "r.nc")
    assert ds["resolution_dx"].dims == ("level",) and ds.sizes["level"] == len(ta["dx"])
    assert ds["resolution_pull_off_F"].attrs["units"] == "1" and ds["resolution_seconds"].attrs["units"] == "s"
    assert "resolution" not in __import__("json").loads(ds.attrs["params"])  # stored once: as the variables
    for k, v in ds.variables.items():
        assert v.attrs.get("long_name"), k


def test_netcdf_with_the_table_passes_the_cf_check(refined, monkeypatch):
    runner = pytest.importorskip("compliance_checker.runner")
    cs = runner.CheckSuite()
    cs.load_all_available_checkers()
    results, errors = cs.run_all(cs.load_dataset(str(refined / "r.nc")), ["cf:1.10"], skip_checks=[])["cf:1.10"]
    failed = [(r.name, r.msgs) for r in results
              if (r.value[0] < r.value[1] if isinstance(r.value, tuple) else not r.value)]
    assert errors == {} and failed == []


def test_plot_shows_the_convergence(refined, capsys):
    assert main(["plot", str(refined / "r.csv"), "--out", str(refined / "f.png")]) == 0
    assert (refined / "f_resolution.png").stat().st_size > 1000


# ---- max_pixels -------------------------------------------------------------------------------------
def test_max_pixels_stops_with_under_resolved_and_one_line(tmp_path, capsys):
    out = tmp_path / "m.csv"
    assert main([*PYR, "--max-pixels", str(21 * 21), "--out", str(out)]) == 0
    err = capsys.readouterr().err
    lines = [ln for ln in err.splitlines() if "max_pixels" in ln]
    assert len(lines) == 1 and "dx = 0.18" in lines[0] and "needed" in lines[0]
    _, res = load_result(out)
    assert res.status == "under_resolved" and res.params["resolve_status"] == "under_resolved"
    assert res.params["resolution"]["nx"] == [9, 13, 21] and res.grid.nx == 21
    msg = res.params["resolve_message"]
    assert "\n" not in msg and "dx ≈" in msg
    need = float(msg.split("dx ≈ ")[1].split()[0])
    assert 0.01 < need < 0.18  # extrapolated from the observed convergence: finer than reached


def test_api_resolve_and_the_first_grid_above_max_pixels():
    from tengsim import ContactPlan, PathSpec, Pyramid, ResolveSettings, resolve as refined

    def plan(max_pixels):
        return ContactPlan(Pyramid(0.946, 3.78), 0.5, 0.4, PathSpec(-1.0, 2.0, 0.1),
                           resolve=ResolveSettings(max_pixels=max_pixels, dx=0.4))

    res = refined(plan(13 * 13))
    assert res.status == "under_resolved" and len(res.params["resolve_grids"]) == 2
    assert res.params["richardson"]["pull_off_F"]["observed"] is False  # two grids: order 1 assumed
    with pytest.raises(TengsimError, match="below the first grid's 9×9"):
        refined(plan(50))


def test_default_start_and_max_pixels():
    from tengsim.laws import MaugisDugdale
    from tengsim.shapes import Paraboloid

    from tengsim import status
    from tengsim.kernels import make_kernel

    shape, law = Paraboloid(1.0, 16.0), MaugisDugdale()
    dx = resolve.default_dx(shape, law, 1.0)
    # the pixel-snap bound of the MD law at μ = 1: s(dx) ∝ dx falls to the status' limit (0.6) at dx ≈ 0.07
    assert 0.06 < dx < 0.08
    s = status.pixel_snap_number(law, make_kernel("free", shape.grid(dx), 1.0))
    assert 0.8 * status.SNAP_LIMIT < s <= status.SNAP_LIMIT * 1.02
    assert resolve.default_max_pixels() >= 9


# ---- refusals ---------------------------------------------------------------------------------------
BASE = ["contact", "pyramid", "--N", "0.946", "--cell", "3.78", "--d-min", "-1", "--d-max", "0", "--d-step", "0.5",
        "--dx", "0.5", "--quiet"]


@pytest.mark.parametrize("extra, words", [
    (["--resolve-tol", "0.02"], "resolve_tol applies only with resolve = 'auto'"),
    (["--max-pixels", "100"], "max_pixels applies only with resolve = 'auto'"),
    (["--resolve", "auto", "--resolve-tol", "0"], "resolve_tol must be > 0 and < 0.5, got 0"),
    (["--resolve", "auto", "--resolve-tol", "1"], "resolve_tol must be > 0 and < 0.5, got 1"),
    (["--resolve", "auto", "--resolve-tol", "x"], "resolve_tol"),
    (["--resolve", "auto", "--max-pixels", "4"], "max_pixels must be >= 9"),
    (["--resolve", "auto", "--max-pixels", "10.5"], "max_pixels must be an integer"),
    (["--resolve", "maybe"], "resolve = 'maybe' is not one of off, auto"),
    (["--resolve", "auto", "--max-pixels", "50"], "max_pixels = 50 is below the first grid's"),
])
def test_bad_values_are_refused_with_one_line(tmp_path, capsys, extra, words):
    out = tmp_path / "bad.csv"
    assert main([*BASE, *extra, "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and words in err
    assert list(tmp_path.iterdir()) == []


def test_one_grid_run_contact_refuses_resolve_auto():
    from tengsim.run.simulate import simulate as run_contact

    with pytest.raises(TengsimError, match="run it with tengsim.resolve"):
        run_contact({**PYR_CFG, "d_max": 0.0})


# ---- the issue's done-when (slow) -------------------------------------------------------------------
@pytest.mark.slow
def test_md_sphere_converges_to_maugis(tmp_path):
    """`tengsim contact sphere --law md --tabor 1 --cell 16 --d-min -2 --d-max 0.5 --d-step 0.05 --resolve auto`:
    pull-off within 1 % of Maugis–Dugdale (λ = 1.157 μ), status ok, the grid sequence in the file."""
    from tengsim.references import maugis_dugdale_pulloff_from_tabor

    out = tmp_path / "md.csv"
    assert main(["contact", "sphere", "--law", "md", "--tabor", "1", "--cell", "16", "--d-min", "-2", "--d-max",
                 "0.5", "--d-step", "0.05", "--resolve", "auto", "--quiet", "--out", str(out)]) == 0
    _, res = load_result(out)
    md = -maugis_dugdale_pulloff_from_tabor(1.0) / 3  # F = ∬P/(3π), ∬P = −π P̄
    assert res.status == "ok" and len(res.params["resolve_grids"]) >= 2
    assert abs(res.pull_off_force / md - 1) < 0.01


# ---- sweeps -----------------------------------------------------------------------------------------
def test_sweep_passes_resolve_and_reports_status_and_dx(tmp_path, study_client):
    """"contact.resolve" = "auto" in [base.contact]: each point refined; a point stopped by max_pixels is
    under_resolved with its one line (dx reached, dx needed) in study.csv's message, an ok one names its dx."""
    import csv

    from tengsim.study import parse_study, run_study

    base = {k: v for k, v in PYR_CFG.items()}
    study = parse_study({"base": {"contact": base}, "axes": {"contact.max_pixels": [21 * 21, 10**6]}}, source="t")
    s = run_study(study, tmp_path / "out", client=study_client, quiet=True)
    assert (s["ok"], s["under_resolved"], s["failed"]) == (1, 1, 0)
    rows = {r["contact.max_pixels"]: r for r in csv.DictReader(open(tmp_path / "out" / "study.csv"))}
    low, high = rows[str(21 * 21)], rows[str(10**6)]
    assert low["status"] == "under_resolved" and "stopped by max_pixels = 441 at dx = 0.18" in low["message"]
    assert "needed" in low["message"]
    assert high["status"] == "ok" and "resolve auto: converged at dx = 0.0771" in high["message"]


def test_needed_dx_is_not_extrapolated_absurdly_far():
    """A change of 600 % between two grids (a jump on one grid only) extrapolates to a dx thousands of times
    finer; the message then says only 'below dx/8', not the absurd number."""
    from tengsim.run.judge import GridRecord

    levels = [GridRecord(0.2, 5, 5, 1.0, 10, "ok", {"pull_off": 1.0}),
              GridRecord(0.14, 7, 7, 2.0, 20, "ok", {"pull_off": 7.0})]
    rich = {"pull_off": {"order": 0.5, "rel_error": 6.0}}
    need = resolve._dx_needed(levels, rich, {"pull_off": 6.0}, 0.01)
    assert need < 0.14 / resolve.NEED_FLOOR  # the raw estimate is far below the floor


# ---- A/S at named pressures (physical runs) ---------------------------------------------------------
PHYS = ["contact", "pyramid", "--E-star", "0.59MPa", "--W", "54mJ/m2", "--eps", "0.37um", "--pitch", "5um",
        "--base", "2.5um", "--height", "1.75um", "--d-min", "-1", "--d-max", "9", "--d-step", "0.333", "--quiet"]


def test_resolve_pressures_are_judged_and_written(tmp_path, capsys):
    """resolve_pressures: A/S at each pressure is an observable of every grid (the resolution table), equal to
    the study layer's A/S of that grid's result at that pressure, and it can stop the refinement."""
    from tengsim.run.area import area_at, area_name

    out = tmp_path / "rp.nc"
    assert main([*PHYS, "--resolve", "auto", "--dx", "0.45um", "--max-pixels", "2500", "--resolve-pressures",
                 "1kPa,100kPa", "--out", str(out)]) == 0
    _, res = load_result(out)
    table = res.params["resolution"]
    for p in (1e3, 1e5):
        col = np.asarray(table[area_name(p)], float)
        assert len(col) == len(res.params["resolve_grids"]) >= 2 and np.all((col > 0) & (col <= 1))
        cfg = res.params["config"]
        assert area_at([p], cfg)(res)[area_name(p)] == pytest.approx(col[-1], rel=1e-9)
    assert res.params["config"]["resolve_pressures"] in ("1kPa,100kPa", ["1kPa", "100kPa"], ("1kPa", "100kPa"))


def test_area_observer_is_nan_outside_the_run_and_for_dimensionless():
    from tengsim.run.area import area_at, area_name

    res = simulate.simulate({**PYR_CFG, "resolve": "off", "dx": 0.2})
    assert math.isnan(area_at([1e4])(res)[area_name(1e4)])  # no physical scale
    assert area_name(1e4) == "A_S_at_10000Pa" and area_name(2.5e3) == "A_S_at_2500Pa"


@pytest.mark.parametrize("extra, words", [
    (["--resolve-pressures", "10kPa"], "resolve_pressures applies only with resolve = 'auto'"),
    (["--resolve", "auto", "--resolve-pressures", "5um"], "is a length, expected a pressure"),
    (["--resolve", "auto", "--resolve-pressures=-3kPa"], "resolve_pressures must be pressures > 0"),
])
def test_resolve_pressures_refused_with_one_line(tmp_path, capsys, extra, words):
    out = tmp_path / "bad.csv"
    assert main([*PHYS, *extra, "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and words in err
    assert list(tmp_path.iterdir()) == []


def test_resolve_pressures_refused_in_a_dimensionless_run(tmp_path, capsys):
    assert main([*BASE, "--resolve", "auto", "--resolve-pressures", "10kPa", "--out", str(tmp_path / "b.csv")]) == 2
    assert "applies only to a physical run" in capsys.readouterr().err


def test_the_api_converges_a_s_at_resolve_pressures_without_any_hook(monkeypatch):
    """The refinement of a plan wires the A/S observer of its resolve_pressures (tengsim.run.area.area_at)
    itself: no caller passes it."""
    from tengsim.run import simulate
    from tengsim.run.area import area_name

    one_grid = simulate.simulate({**PYR_CFG, "resolve": "off", "dx": 0.4})
    monkeypatch.setattr(simulate, "_one_grid", lambda plan, **k: one_grid)  # every grid: no solve
    res = resolve.resolve({"shape": "pyramid", "E_star": "0.59MPa", "W": "54mJ/m2", "eps": "0.37um",
                               "pitch": "5um", "base": "2.5um", "height": "1.75um", "d_min": -1, "d_max": 2,
                               "d_step": 0.5, "resolve": "auto", "resolve_pressures": "10kPa",
                               "max_pixels": 40 * 40})
    assert area_name(1e4) in res.params["resolution"]


def test_study_points_converge_their_observable_pressures():
    """A physical study point with resolve = 'auto' gets the study's [observables] pressures as
    resolve_pressures (so its id covers them); a dimensionless one and resolve = 'off' do not."""
    from tengsim.study import parse_study

    phys = {"shape": "pyramid", "E_star": "0.59MPa", "W": "54mJ/m2", "eps": "0.37um", "pitch": "5um",
            "base": "2.5um", "height": "1.75um", "d_min": -1, "d_max": 2, "d_step": 0.5, "resolve": "auto"}
    st = parse_study({"base": {"contact": phys}, "axes": {"contact.W": ["54mJ/m2", "60mJ/m2"]},
                      "observables": {"pressures": ["2kPa", "20kPa"]}}, source="t")
    assert all(p.contact["resolve_pressures"] == ["2000Pa", "20000Pa"] for p in st.points)
    st2 = parse_study({"base": {"contact": {**phys, "resolve": "off"}}, "axes": {"contact.W": ["54mJ/m2"]}},
                      source="t")
    assert "resolve_pressures" not in st2.points[0].contact
    st3 = parse_study({"base": {"contact": dict(PYR_CFG)}, "axes": {"contact.dx": [0.4]}}, source="t")
    assert "resolve_pressures" not in st3.points[0].contact
    own = parse_study({"base": {"contact": {**phys, "resolve_pressures": ["5kPa"]}},
                       "axes": {"contact.W": ["54mJ/m2"]}}, source="t")
    assert own.points[0].contact["resolve_pressures"] == ["5kPa"]


def test_why_names_the_observable_that_moved_most():
    assert resolve._why({}) == "one grid only"
    assert resolve._why({"pull_off_F": 0.02, "jump_in_D": 0.001}) == \
        "pull_off_F changed 2.00% between the last two grids"
    assert resolve._why({"pull_off_F": 0.02, "transition_D": math.inf}) == \
        "transition_D exists on one of the last two grids only (NaN on the other)"


# ---- edges kept in place ------------------------------------------------------------------------------
def test_finer_grids_keep_a_shapes_edges_where_they_fell_in_the_first_grids_pixels():
    """A pyramid of base half the cell (edge at cell/4): plain √2 refinement from 45² goes 65², 99², 143²,
    225², the edge alternating between a quarter and three quarters of a pixel; the kept sequence is
    45², 65², 105², 165², 245², the edge a quarter pixel past a pixel centre on each.  A shape without edges
    (paraboloid), an edge no grid in reach can keep, and the pixel cap get the plain grid."""
    from tengsim.grid import Grid
    from tengsim.run.grids import FACTOR, PHASE_TOL, aligned, edge_phases
    from tengsim.shapes import Cone, Cube, Hemisphere, Paraboloid, Pyramid

    pyr = Pyramid(N=10.0, cell=40.0)
    g = pyr.grid(40.0 / 45)
    phases = edge_phases(pyr, g)
    assert g.nx == 45 and phases == pytest.approx((0.25,))
    plain, kept = [g.nx], [g.nx]
    gp = gk = g
    for _ in range(4):
        gp = pyr.grid(gp.dx / FACTOR)
        plain.append(gp.nx)
        gk = aligned(pyr, pyr.grid(gk.dx / FACTOR), phases, 10**8)
        kept.append(gk.nx)
        assert isinstance(gk, Grid) and gk.nx * gk.dx == pytest.approx(40.0, rel=1e-12)
        assert min(abs(edge_phases(pyr, gk)[0] - 0.25), 1 - abs(edge_phases(pyr, gk)[0] - 0.25)) <= PHASE_TOL
    assert plain == [45, 65, 99, 143, 225] and kept == [45, 65, 105, 165, 245]
    assert [round(edge_phases(pyr, Grid(n, n, 40.0 / n, 40.0 / n))[0], 2) for n in plain] == [0.25, 0.25, 0.75, 0.75, 0.25]
    # every shape with a kink declares it; a smooth one does not
    assert Cone(slope=1.0, cell=10.0, height=2.5).edge_offsets() == (2.5,)
    assert Cone(slope=1.0, cell=10.0).edge_offsets() == ()
    assert Hemisphere(radius=2.5, cell=10.0).edge_offsets() == (2.5,)
    assert Cube(half_width=1.5, height=5.0, cell=6.0).edge_offsets() == (1.5,)
    sph = Paraboloid(1.0, 16.0)
    g1 = sph.grid(16.0 / 45)
    assert edge_phases(sph, g1) == () and aligned(sph, sph.grid(g1.dx / FACTOR), (), 10**8).nx == 65
    # the cap: no kept grid above max_pixels, so the plain one
    assert aligned(pyr, pyr.grid(40.0 / 99), phases, 100 * 100).nx == 99


def test_a_refinement_records_its_edge_phases():
    res = resolve.resolve({**PYR_CFG, "max_pixels": 13 * 13})
    assert res.params["resolve_edge_phases"] == pytest.approx([0.2524], abs=1e-3)
    assert res.params["resolution"]["nx"] == [9, 13]
