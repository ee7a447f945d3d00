"""A design's report and design.nc state the air-breakdown cap on σ A/S and whether the design exceeds it."""
import pytest
import xarray as xr

from tengsim.design.breakdown import AREA_M2, design_breakdown
from tengsim.device import DeviceParams
from tengsim.device.breakdown import sigma_breakdown

TINY = {"shape": "pyramid", "pitch": "1um", "base": "0.5um", "height": "0.2um", "E_star": "5MPa", "W": "20mJ/m2",
        "eps": "50nm", "p_max": "20kPa", "p_step": "10kPa", "tol": 0.05, "maps": False,
        "sigma": "8uC/m2", "eps_r": 3.0, "T": "200um", "gap": "0.2mm"}


def test_design_states_the_breakdown_cap(tmp_path):
    from tengsim.design import plan_design, run_design, write_design

    out = tmp_path / "d"
    write_design(run_design(plan_design(TINY)), out, figures=False)
    with xr.open_dataset(out / "design.nc") as ds:
        a = dict(ds.attrs)
        a_max = float(ds["charged_area_fraction"].values[0].max())
    p = DeviceParams(mass_kg=0.01, stiffness_N_per_m=5e3, area_m2=AREA_M2, thickness_m=200e-6, gap_m=0.2e-3,
                     eps_r=3.0, sigma_C_per_m2=8e-6, field="finite", electrode_shape="disk")
    cap = sigma_breakdown(p).sigma_breakdown_C_m2  # the device layer's, on its own gap grid
    assert a["sigma_breakdown_C_m2"] == pytest.approx(cap, rel=1e-2)
    assert a["sigma_area_fraction_C_m2"] == pytest.approx(8e-6 * a_max, rel=1e-9)
    assert a["breakdown_exceeded"] in (0, False)  # 8 uC/m2 x A/S <= 8 uC/m2, far below the cap
    text = (out / "report.md").read_text()
    assert "Air breakdown (Paschen" in text and "below it" in text
    # V_OC with both field models: Eq. 17's plates, and the finite field of the device design's 4 cm² square,
    # here against the device layer's own spline table of that field at the rest gap (xb = 1)
    from tengsim.device.field import bar_field

    square = DeviceParams(mass_kg=0.01, stiffness_N_per_m=5e3, area_m2=AREA_M2, thickness_m=200e-6, gap_m=0.2e-3,
                          eps_r=3.0, sigma_C_per_m2=8e-6, field="finite", electrode_shape="square")
    ratio = float(bar_field(square).voc(1.0))
    assert 0.8 < ratio < 1.0  # fringing: below the parallel plates at a gap of 1 % of the electrode
    assert a["voc_finite_at_p_max_V"] == pytest.approx(a["voc_eq17_at_p_max_V"] * ratio, rel=2e-3)
    assert "field: finite" in text and "field: parallel" in text and "voc_finite_at_p_max_V" in a["field_models"]


def test_a_charge_above_the_cap_is_flagged():
    b = design_breakdown(500e-6, 3.0, 200e-6, 0.2e-3, 0.5)  # calibrate's upper bound, half the area charged
    assert b["breakdown_exceeded"] and b["sigma_area_fraction_C_m2"] == pytest.approx(250e-6)
    assert 30e-6 < b["sigma_breakdown_C_m2"] < 200e-6


def test_calibrate_flags_a_fitted_sigma_above_the_cap():
    from types import SimpleNamespace as NS

    from tengsim.calibrate.write import breakdown_warning

    plan = NS(eps_r=3.0, T=200e-6, gap=0.2e-3)
    cap = design_breakdown(1.0, 3.0, 200e-6, 0.2e-3, 1.0)["sigma_breakdown_C_m2"]
    high = NS(problem=NS(fixed={}, plans=[plan]), fit=NS(best={"sigma": 2 * cap}))
    lines = breakdown_warning(high)
    assert len([ln for ln in lines if ln]) == 1 and "above the air-breakdown cap" in lines[-1]
    low = NS(problem=NS(fixed={}, plans=[plan]), fit=NS(best={"sigma": 0.5 * cap}))
    assert breakdown_warning(low) == []


def test_comparison_ranks_by_the_charge_held_when_a_design_exceeds_the_cap():
    from types import SimpleNamespace as NS

    from tengsim.design.compare import compare_table, ranked

    def design(name, sigma, gap, a):
        return NS(plan=NS(name=name, shape="pyramid", sigma=sigma, eps_r=3.0, T=200e-6, gap=gap),
                  summary={"area_at_p_max": a})

    wide = design("wide", 100e-6, 0.2e-3, 0.9)  # 90 uC/m2 over a cap of about 66 at a 0.2 mm gap
    narrow = design("narrow", 100e-6, 0.05e-3, 0.8)  # 80 uC/m2 under a cap of about 106 at 50 um
    assert wide.plan.sigma * 0.9 > design_breakdown(1, 3.0, 200e-6, 0.2e-3, 1)["sigma_breakdown_C_m2"]
    assert [r.plan.name for r in ranked([wide, narrow])] == ["narrow", "wide"]  # by the charge held
    t = compare_table([wide, narrow])
    assert t["held_charge_C_m2"][0] == pytest.approx(80e-6) and t["held_charge_C_m2"][1] == t["sigma_breakdown_C_m2"][1]
    low = [design("wide", 10e-6, 0.2e-3, 0.9), design("narrow", 10e-6, 0.05e-3, 0.8)]
    assert [r.plan.name for r in ranked(low)] == ["wide", "narrow"]  # none capped: by A/S, as before
