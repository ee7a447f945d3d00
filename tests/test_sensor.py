"""The sensor's numbers of a V_OC(P) curve (tengsim.device.sensor), defined once: analytic curves give known
numbers; a curve that saturates reports its sensitivity below the saturation only; every n/a has its reason; the
design and the study report the same numbers for the same run."""
import math

import numpy as np
import pytest

from tengsim.device.sensor import NUMBERS, R2_LINEAR, SATURATION_BAND, describe, sensor_numbers

P = np.linspace(0.0, 40e3, 81)  # Pa, every 0.5 kPa
STEP = 40e3 / 400  # the even resampling of the range


def test_a_line_has_one_region_its_slope_and_the_whole_range_linear():
    V = 3.0 + 2e-3 * P  # 2 V/kPa on a 3 V baseline
    s = sensor_numbers(P, V)
    f = s.flat()
    assert len(s.regions) == 1 and s.regions[0].name == "whole range"
    assert f["sensitivity_V_per_Pa"] == pytest.approx(2e-3, rel=1e-12)
    assert f["sensitivity_rel_per_Pa"] == pytest.approx(2e-3 / 3.0, rel=1e-12)
    assert f["linear_range_Pa"] == pytest.approx(40e3) and f["linear_r2"] == pytest.approx(1.0)
    for k in ("knee_Pa", "saturation_Pa", "voc_hysteresis_V"):  # none, each with its reason
        assert math.isnan(f[k]) and s.reason(k), k
    assert "no knee" in s.reason("knee_Pa") and "does not level off" in s.reason("saturation_Pa")


def test_a_curve_that_saturates_at_2p5_kPa_reports_no_large_sensitivity_above_it():
    V = 10.0 * np.minimum(P, 2.5e3) / 2.5e3  # the cube's curve: 0 -> 10 V by 2.5 kPa, flat to 40 kPa
    P_fine = np.linspace(0, 40e3, 1601)  # sampled finely enough that 2.5 kPa is a sample of the resampling too
    s = sensor_numbers(P_fine, 10.0 * np.minimum(P_fine, 2.5e3) / 2.5e3)
    f = s.flat()
    # saturated where V_OC is within 2 % of its full-scale change (10 V) of its top: 9.8 V at 2.45 kPa
    p_sat = 2.5e3 * (1 - SATURATION_BAND)
    assert f["saturation_Pa"] == pytest.approx(p_sat, abs=STEP)
    assert [r.name for r in s.regions] == ["up to saturation", "saturated"]
    low, flat = s.regions
    assert low.sensitivity_V_per_Pa == pytest.approx(4e-3, rel=1e-9) and f["sensitivity_to_Pa"] == low.p_hi_Pa
    assert flat.p_lo_Pa == pytest.approx(p_sat, abs=STEP) and flat.p_hi_Pa == 40e3
    assert abs(flat.sensitivity_V_per_Pa) < 1e-3 * low.sensitivity_V_per_Pa  # no sensitivity over the rest
    assert f["linear_range_Pa"] <= low.p_hi_Pa and f["linear_r2"] >= R2_LINEAR
    assert math.isnan(f["sensitivity_rel_per_Pa"]) and "V_OC is 0 at 0 kPa" in s.reason("sensitivity_rel_per_Pa")
    # the same curve on the coarse samples: the same saturation, within the coarse samples' interpolation
    assert sensor_numbers(P, V).flat()["saturation_Pa"] == pytest.approx(p_sat, abs=0.5e3)


def test_a_snap_is_a_knee_of_its_own_with_a_line_each_side():
    """A contact snapping in (V_OC jumps between two states: the land of a pyramid array adhering) splits the
    curve at the snap, not at a least-squares knee inside the jump: each side keeps its own line (R² 1)."""
    P = np.array([0, 10, 20, 30, 40, 45, 60, 70, 80, 90, 100]) * 1e3  # states; the snap from 45 to 60 kPa
    V = np.where(P <= 45e3, 1.0 + 0.3e-3 * P, 90.0 + 0.1e-3 * (P - 60e3))  # 0.3 V/kPa, then 0.1 V/kPa
    s = sensor_numbers(P, V)
    f = s.flat()
    assert [r.name for r in s.regions][:3] == ["below the snap", "the snap", "above the snap"]
    assert f["knee_Pa"] == pytest.approx(45e3)
    assert f["sensitivity_V_per_Pa"] == pytest.approx(0.3e-3, rel=1e-6) and s.regions[0].r2 == pytest.approx(1.0)
    assert f["sensitivity_above_knee_V_per_Pa"] == pytest.approx(0.1e-3, rel=1e-6)
    assert s.regions[1].sensitivity_V_per_Pa == pytest.approx((90.0 - 14.5) / 15e3, rel=1e-6)
    assert f["linear_range_Pa"] == pytest.approx(45e3, abs=0.3e3)
    # saturated from the lowest pressure on (a flat top in contact at once): no snap, no division by a zero range
    flat = sensor_numbers([0.0, 1.0, 40e3], [0.0, 20.0, 20.0])
    assert "the snap" not in [r.name for r in flat.regions]
    # a steep but smooth rise (no two states farther apart than the rest) is no snap
    Q = np.linspace(0, 100e3, 401)
    assert "the snap" not in [r.name for r in sensor_numbers(Q, 1.0 + 0.3e-3 * Q + 50 * np.tanh(Q / 5e3)).regions]


def test_a_knee_splits_the_curve_into_two_regions_with_their_slopes():
    V = np.where(P < 10e3, 1.0 + 2e-3 * P, 21.0 + 0.5e-3 * (P - 10e3))  # 2 V/kPa, then 0.5 V/kPa above 10 kPa
    s = sensor_numbers(P, V)
    f = s.flat()
    assert [r.name for r in s.regions] == ["below the knee", "above the knee"]
    assert f["knee_Pa"] == pytest.approx(10e3, abs=STEP)
    assert f["sensitivity_V_per_Pa"] == pytest.approx(2e-3, rel=1e-6)
    assert f["sensitivity_above_knee_V_per_Pa"] == pytest.approx(0.5e-3, rel=1e-6)
    assert f["sensitivity_rel_per_Pa"] == pytest.approx(2e-3 / 1.0, rel=1e-6)
    assert f["linear_range_Pa"] == pytest.approx(10e3, abs=STEP) and f["linear_r2"] == pytest.approx(1.0)
    assert all(r.r2 == pytest.approx(1.0) for r in s.regions)
    assert math.isnan(f["saturation_Pa"])


def test_hysteresis_is_the_largest_gap_between_the_branches_over_the_full_scale_change():
    V = 1.0 + 2e-3 * P
    Vr = V + 4.0 * np.sin(np.pi * P / 40e3)  # 4 V apart at 20 kPa, together at the ends
    s = sensor_numbers(P, V, (P, Vr), (0.0, 40e3))
    assert s.voc_hysteresis_V == pytest.approx(4.0, rel=1e-6)
    assert s.voc_hysteresis_fraction == pytest.approx(4.0 / 80.0, rel=1e-6)
    far = sensor_numbers(P, V, (P + 50e3, Vr))
    assert math.isnan(far.voc_hysteresis_V) and "reaches no pressure" in far.reason("voc_hysteresis_V")


def test_every_na_has_a_reason_and_the_report_shows_it():
    flat = sensor_numbers(P, np.full(P.shape, 5.0))
    f = flat.flat()
    assert f["sensitivity_V_per_Pa"] == 0.0  # no response is an answer: 0 V/kPa
    for k in NUMBERS:
        if not math.isfinite(f[k]):
            assert flat.reason(k), k
    text = "\n".join(describe(flat))
    assert "n/a (" in text and "no response" in text and "n/a |" not in text
    none = sensor_numbers([1e3], [2.0])
    assert all(none.reason(k) for k in NUMBERS) and "2 are needed" in none.reason("sensitivity_V_per_Pa")


def test_the_numbers_do_not_depend_on_where_the_curve_was_sampled():
    curve = lambda p: 12.0 * (1 - np.exp(-p / 8e3))  # noqa: E731
    a = sensor_numbers(P, curve(P)).flat()
    dense = np.linspace(0, 40e3, 4001)
    b = sensor_numbers(dense, curve(dense)).flat()
    for k in ("sensitivity_V_per_Pa", "saturation_Pa", "knee_Pa"):
        assert a[k] == pytest.approx(b[k], rel=0.02), k


TINY = {"shape": "pyramid", "pitch": "1um", "base": "0.5um", "height": "0.2um", "E_star": "5MPa", "W": "20mJ/m2",
        "eps": "50nm", "p_max": "20kPa", "p_step": "10kPa", "tol": 0.05, "maps": False}


@pytest.fixture(scope="module")
def tiny():
    from tengsim.design import plan_design, run_design

    return run_design(plan_design(TINY))


def test_the_design_and_the_study_report_the_same_sensor_numbers(tiny, tmp_path):
    from tengsim.design import write_design
    from tengsim.study.observe import observe, parse_observables

    s, p = tiny.summary, tiny.plan
    dev = {"sigma": p.sigma, "eps_r": p.eps_r, "thickness": p.T}
    settings = parse_observables({"fit_range": [p.pressures[0], p.pressures[-1]]})
    o = observe(tiny.finest, dev, settings)["scalars"]
    assert math.isfinite(s["sensitivity_V_per_Pa"]) and math.isfinite(s["linear_range_Pa"])
    assert o["S_V_per_kPa"] == pytest.approx(1e3 * s["sensitivity_V_per_Pa"], rel=1e-9)
    assert o["linear_range_Pa"] == pytest.approx(s["linear_range_Pa"], rel=1e-9)
    assert o["linear_R2"] == pytest.approx(s["linear_r2"], rel=1e-9)
    assert o["P_sat_Pa"] == pytest.approx(s["saturation_Pa"], rel=1e-9, nan_ok=True)
    # design.nc and the report carry the same numbers, n/a with its reason
    write_design(tiny, tmp_path, figures=False)
    import xarray as xr

    ds = xr.load_dataset(tmp_path / "design.nc")
    assert ds.attrs["sensitivity_V_per_Pa"] == pytest.approx(s["sensitivity_V_per_Pa"])
    assert ds.attrs["linear_range_Pa"] == pytest.approx(s["linear_range_Pa"])
    assert ds["sensor_region_sensitivity"].values[0] == pytest.approx(s["sensitivity_V_per_Pa"])
    for k in NUMBERS:
        v = ds.attrs[k]
        assert isinstance(v, float) or v.startswith("n/a: "), (k, v)
    report = (tmp_path / "report.md").read_text()
    assert "## As a pressure sensor" in report and f"{s['sensitivity_V_per_Pa'] * 1e3:.4g} V/kPa" in report
    assert "| n/a |" not in report and "n/a (" in report  # every n/a of the report with its reason
    for k, v in ds.attrs.items():
        assert v != "n/a", k


def test_no_second_definition_of_sensitivity_in_the_sources():
    """Only tengsim.device.sensor fits a line to V_OC(P): no other module calls polyfit on a V_OC curve."""
    from pathlib import Path

    import tengsim

    root = Path(tengsim.__file__).parent
    hits = [str(f.relative_to(root)) for f in root.rglob("*.py")
            if "polyfit" in f.read_text() and f.name != "sensor.py"]
    # analysis.py fits the contact's own profile, calibrate/fit.py the log-log trade-off between two fitted
    # parameters along the region that fits: neither is a line through V_OC(P)
    assert set(hits) <= {"analysis.py", "calibrate/fit.py"}, hits
