"""Observables of a design study on synthetic curves with known answers (docs/design.md definitions)."""
import math

import numpy as np
import pytest

from tengsim.grid import Grid
from tengsim.results import CURVE_COLUMNS, ContactResult
from tengsim.study.observe import observe, parse_observables
from tengsim.cases.paper.units import paper_scaling

EPS_0 = 8.8541878128e-12
SC = paper_scaling("A")
DEVICE = {"sigma": "5.84uC/m2", "eps_r": 2.40, "thickness": "400um"}
K_V = 5.84e-6 * 400e-6 / (2.40 * EPS_0)  # Eq. (12): V_OC = K_V · A/S


def synthetic(P_Pa, area, D_retract=None, F_retract=None, physical=True):
    """A ContactResult whose approach passes through pressures P_Pa with charged-area fractions ``area``."""
    F = np.asarray(P_Pa, float) / SC.pressure(1.0)
    L = SC.cell * np.sqrt(np.asarray(area, float))
    n = len(F)
    D = np.linspace(-1.0, 3.0, n)
    Dr = np.asarray(D_retract if D_retract is not None else D[::-1])
    Fr = np.asarray(F_retract if F_retract is not None else F[::-1])
    rows = {k: np.zeros(n + len(Dr)) for k in CURVE_COLUMNS}
    rows["branch"] = np.array(["approach"] * n + ["retraction"] * len(Dr))
    rows["D"] = np.r_[D, Dr]
    rows["F"] = np.r_[F, Fr]
    rows["contact_length"] = np.r_[L, L[::-1][: len(Dr)]]
    a = np.asarray(area, float)
    rows["charged_fraction"] = np.r_[a, a[::-1][: len(Dr)]]  # the 2-D charged area (the default definition)
    rows["converged"] = np.ones(n + len(Dr), bool)
    rows["jump"] = np.zeros(n + len(Dr), bool)
    params = {"shape": "Pyramid", "N": SC.N, "cell": SC.cell}
    if physical:
        params.update(SC.params())
    return ContactResult(table=rows, grid=Grid(8, 8, 1.0, 1.0), params=params)


def settings(**kw):
    return parse_observables(kw)


def test_linear_response_gives_exact_sensitivity_and_full_linear_range():
    P = np.linspace(0, 50e3, 51)
    A = 0.05 + 2e-6 * P  # A/S rises 0.002 per kPa
    o = observe(synthetic(P, A), DEVICE, settings())
    s, c = o["scalars"], o["curves"]
    assert s["S_V_per_kPa"] == pytest.approx(K_V * 2e-3, rel=1e-9)
    assert s["S_rel_per_kPa"] == pytest.approx(2e-3 / 0.05, rel=1e-9)  # (dV/dP)/V0, V0 at 0 kPa
    assert s["linear_range_Pa"] == pytest.approx(50e3) and s["linear_R2"] == pytest.approx(1.0)
    assert s["V_sat"] == pytest.approx(K_V * A[-1])
    assert math.isnan(s["P_sat_Pa"]) and math.isnan(s["knee_Pa"])  # a line neither saturates nor bends
    # read over a range of its own: the same line
    s10 = observe(synthetic(P, A), DEVICE, settings(fit_range=["0kPa", "10kPa"]))["scalars"]
    assert s10["S_V_per_kPa"] == pytest.approx(K_V * 2e-3, rel=1e-9) and s10["linear_range_Pa"] == pytest.approx(1e4)
    assert s["area_fraction_0"] == pytest.approx(0.05)
    want = (K_V * (0.05 + 2e-6 * np.array([1e3, 1e4]))).tolist() + [math.nan]  # 100 kPa: beyond the run
    assert c["V_OC_at"].tolist() == pytest.approx(want, nan_ok=True)
    grid = np.linspace(0, 150e3, 61)
    inside = grid <= 50e3
    np.testing.assert_allclose(c["V_OC"][inside], K_V * (0.05 + 2e-6 * grid[inside]), rtol=1e-9)
    assert np.all(np.isnan(c["V_OC"][~inside]))


def test_saturating_response_ends_linear_range_where_it_bends():
    P = np.linspace(0, 150e3, 301)
    A = np.minimum(0.02 + 4e-6 * P, 0.5)  # linear up to 120 kPa, then flat
    s = observe(synthetic(P, A), DEVICE, settings())["scalars"]
    assert s["S_V_per_kPa"] == pytest.approx(K_V * 4e-3, rel=1e-9)  # the rising region, up to saturation
    # saturated from where A/S is within 2 % of its full-scale change (0.48) of 0.5: 0.5 - 0.0096
    p_sat = (0.5 - 0.02 * 0.48 - 0.02) / 4e-6
    assert s["P_sat_Pa"] == pytest.approx(p_sat, abs=150e3 / 400)
    assert s["S_to_Pa"] == pytest.approx(p_sat, abs=150e3 / 400)
    assert s["linear_range_Pa"] == pytest.approx(s["S_to_Pa"], abs=150e3 / 400) and s["linear_R2"] >= 0.99
    assert s["V_sat"] == pytest.approx(K_V * 0.5)


def test_load_control_skips_states_where_force_falls_back():
    P = np.array([-2e3, 0.0, 5e3, 3e3, 8e3, 12e3])  # the 3 kPa state comes after 5 kPa: a device jumps ahead
    A = np.array([0.01, 0.02, 0.05, 0.2, 0.21, 0.22])
    c = observe(synthetic(P, A), DEVICE, settings(pressures=["4kPa"], grid_max="12kPa", grid_num=13))["curves"]
    # between 0 and 5 kPa on the load-control path: linear in A from 0.02 to 0.05
    assert c["V_OC_at"][0] == pytest.approx(K_V * (0.02 + 0.03 * 4 / 5))


def test_pull_off_and_hysteresis_in_physical_units():
    P = np.linspace(0, 20e3, 11)
    A = 0.1 + 1e-6 * P
    res = synthetic(P, A, F_retract=np.r_[P[::-1] / SC.pressure(1.0) - 0.3])
    s = observe(res, DEVICE, settings())["scalars"]
    assert s["pull_off_F"] == pytest.approx(-0.3)
    assert s["pull_off_Pa"] == pytest.approx(SC.pressure(-0.3))
    assert s["hysteresis"] == pytest.approx(0.3 * 4.0)  # ∮ F dD of a 0.3 offset over D ∈ [-1, 3]
    assert s["hysteresis_J_m2"] == pytest.approx(SC.pressure(1.0) * SC.eps * 1.2)


def test_dimensionless_run_has_no_pressure_observables():
    P = np.linspace(0, 20e3, 11)
    s = observe(synthetic(P, 0.1 + 1e-6 * P, physical=False), DEVICE, settings())
    for k in ("pull_off_Pa", "S_V_per_kPa", "S_rel_per_kPa", "linear_range_Pa", "V_sat", "hysteresis_J_m2"):
        assert math.isnan(s["scalars"][k]), k
    assert not math.isnan(s["scalars"]["pull_off_F"]) and not math.isnan(s["scalars"]["area_fraction_0"])
    assert np.all(np.isnan(s["curves"]["V_OC"]))


def test_area_fraction_per_shape_family():
    from tengsim.run.area import area_fraction, family

    L = np.array([0.0, 1.0, 2.0, 10.0])
    for shape, fam, want in [("Pyramid", "square", (L / 4) ** 2), ("Cube", "square", (L / 4) ** 2),
                             ("Cone", "disc", math.pi / 4 * (L / 4) ** 2),
                             ("Hemisphere", "disc", math.pi / 4 * (L / 4) ** 2),
                             ("Line", "line", L / 4)]:
        res = ContactResult(table={"F": np.zeros(4)}, grid=Grid(3, 3, 1.0, 1.0), params={"shape": shape, "cell": 4.0})
        assert family(res.params) == fam
        np.testing.assert_allclose(area_fraction(res, L), np.clip(want, 0, 1), rtol=1e-12)
    res = ContactResult(table={}, grid=Grid(3, 3, 1.0, 1.0), params={"shape": "Pyramid", "config": {"shape": "cone"}})
    assert family(res.params) == "disc"  # the run's [contact] shape name wins over the class name


def test_physical_scale_of_any_shape_from_its_columns():
    """Any physical run: Pa per unit F from pressure_Pa (or F_N / cell area), metres per unit D = eps_m."""
    from tengsim.run.simulate import simulate as run_contact
    from tengsim.run.area import physical_scale

    res = run_contact({"shape": "cone", "slope": 1.0, "pitch": "2um", "height": "0.4um", "E_star": "1MPa",
                       "W": "54mJ/m2", "eps": "0.1um", "dx": "0.2um", "d_min": -1.0, "d_max": 2.0,
                       "d_step": 1.0})
    k_p, k_D = physical_scale(res)
    assert k_D == pytest.approx(1e-7)
    F = np.asarray(res.table["F"])
    np.testing.assert_allclose(k_p * F, res.table["pressure_Pa"], rtol=1e-9, atol=1e-9)
    # 3π W ℓ²/ε per cell / cell area, with ℓ = ε/slope (cone) and cell area pitch²
    assert k_p == pytest.approx(3 * math.pi * 54e-3 * (1e-7) ** 2 / 1e-7 / (2e-6) ** 2, rel=1e-9)
    del res.table["pressure_Pa"]
    assert physical_scale(res)[0] == pytest.approx(k_p, rel=1e-9)  # from F_N and cell_area_m2


def test_study_reader_gives_the_observables_of_the_full_result(tmp_path):
    """The study table reads point files with a light reader; it must hand observe every column the
    full reader does (a missing charged_fraction made the study's V_sat the paper's Λc² one)."""
    from tengsim.results import load_result
    from tengsim.study.dataset import _light_result

    P = np.linspace(0.0, 60e3, 7)
    area = 0.05 + 0.3 * P / P[-1]
    synthetic(P, area).save(tmp_path / "p.nc")
    settings = parse_observables({})
    full = observe(load_result(tmp_path / "p.nc")[1], DEVICE, settings)
    light = observe(_light_result(tmp_path / "p.nc")[0], DEVICE, settings)
    assert light["notes"] == full["notes"]
    for k, v in full["scalars"].items():
        assert light["scalars"][k] == pytest.approx(v, nan_ok=True), k
    assert light["scalars"]["V_sat"] == pytest.approx(K_V * area[-1], rel=1e-9)
