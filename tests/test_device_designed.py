"""`tengsim device design --area-from DIR/design.nc`: the device a design describes, in one step.  It carries the
design's σ, ε_r, T, rest gap and A/S(P); its V_OC at the rest gap is the design's Eq. 17 V_OC at the pressure it was
pressed to; what the design does not know comes from stated defaults, named as such; a waveform leaving the area
table's pressures is refused in one line, nothing written."""
import json

import numpy as np
import pytest
import xarray as xr

from tengsim.cli.main import main

TINY = {"shape": "pyramid", "pitch": "1um", "base": "0.5um", "height": "0.2um", "E_star": "5MPa", "W": "20mJ/m2",
        "eps": "50nm", "p_max": "20kPa", "p_step": "10kPa", "tol": 0.05, "maps": False,
        "sigma": "8uC/m2", "eps_r": 3.0, "T": "200um", "gap": "0.2mm"}  # a device of its own, not the paper's


@pytest.fixture(scope="module")
def d1(tmp_path_factory):
    from tengsim.design import plan_design, run_design, write_design

    out = tmp_path_factory.mktemp("designed") / "d1"
    write_design(run_design(plan_design(TINY)), out, figures=False)
    return out


def _eq17(d1, pressure):
    with xr.open_dataset(d1 / "design.nc") as ds:
        P = ds["pressure"].values
        v = ds["voc_eq17"].values[0]  # approach
    return float(np.interp(pressure, P, v))


def test_its_default_field_is_finite_a_square_of_the_electrode_area(d1, tmp_path, capsys):
    from tengsim.device import EPS0
    from tengsim.device.field import gap_coefficients

    out = tmp_path / "dev.csv"
    assert main(["device", "design", "--area-from", str(d1 / "design.nc"), "--load-ohm", "1MOhm", "--out",
                 str(out)]) == 0
    err = capsys.readouterr().err
    assert "field model finite: a square electrode of area S (side 20 mm" in err
    side = json.loads(out.with_suffix(".json").read_text())
    s = side["summary"]
    assert s["field_model"] == "finite" and side["params"]["field"] == "finite"
    assert s["electrode"] == {"shape": "square", "size_m": pytest.approx(0.02), "area_m2": pytest.approx(4e-4)}
    v = gap_coefficients("square", 0.02, 200e-6, 3.0, [s["gap_at_rest_m"]])[1][0]
    ratio = v * EPS0 * 4e-4 / s["gap_at_rest_m"]  # finite V_OC over the parallel plates' at the rest gap
    assert 0.9 < ratio < 0.99  # 0.2 mm on 2 cm: fringing
    assert s["voc_at_rest_gap_V"] == pytest.approx(ratio * _eq17(d1, 20e3), rel=0.01)
    assert s["voc_at_max_gap_V"]["finite"] < s["voc_at_max_gap_V"]["parallel"]
    assert 0 < s["sigma_breakdown_C_m2"] < 1e-3 and s["breakdown_exceeded"] is False  # 8 uC/m2 is held


@pytest.mark.parametrize("pressure", [None, "10kPa"])
def test_its_voc_at_the_rest_gap_is_the_designs_eq17(d1, tmp_path, capsys, pressure):
    out = tmp_path / "dev.csv"
    argv = ["device", "design", "--area-from", str(d1 / "design.nc"), "--load-ohm", "1MOhm", "--out", str(out),
            "--field", "parallel"]  # Eq. 17 is the parallel plates' (the finite default: the test below)
    assert main(argv + (["--pressure", pressure] if pressure else [])) == 0
    err = capsys.readouterr().err
    side = json.loads(out.with_suffix(".json").read_text())
    s = side["summary"]
    p = 20e3 if pressure is None else 10e3
    assert s["pressed_to_Pa"] == pytest.approx(p)
    want = _eq17(d1, p)
    assert want > 1.0
    assert s["voc_at_rest_gap_V"] == pytest.approx(want, rel=0.01)
    assert s["design_voc_eq17_V"] == pytest.approx(want, rel=1e-9)
    # the same from the time series: the last released row, the plate back at its rest gap
    rows = [ln for ln in out.read_text().splitlines() if not ln.startswith("#")]
    t = np.genfromtxt(rows, delimiter=",", names=True)
    rest = np.flatnonzero(t["P_a"] <= 0)[-1]
    assert float(t["V_oc"][rest]) == pytest.approx(want, rel=0.01)
    assert abs(float(t["y"][rest])) <= 0.01 * 0.2e-3  # the plate at its rest gap
    # the design's values in the device, the defaults named as defaults
    prm = side["params"]
    assert (prm["sigma_C_per_m2"], prm["eps_r"], prm["thickness_m"], prm["gap_m"]) == \
        pytest.approx((8e-6, 3.0, 200e-6, 0.2e-3))
    dd = s["designed_device"]
    assert set(dd["defaults"]) >= {"mass_kg", "stiffness_N_per_m", "area_m2", "frequency_Hz"}
    assert "load_ohm" not in dd["defaults"] and ("amplitude_Pa" in dd["defaults"]) == (pressure is None)
    assert "defaults (" in err and "plate mass M = 13.45 g" in err and "σ = 8 µC/m²" in err


def test_options_and_config_replace_the_defaults(d1, tmp_path, capsys):
    from tengsim.design.device import DEFAULTS

    cfg = tmp_path / "dev.toml"
    cfg.write_text('[device]\nstiffness_N_per_m = "6kN/m"\n[waveform]\nfrequency_Hz = "4Hz"\n')
    out = tmp_path / "dev.csv"
    assert main(["device", "design", "--area-from", str(d1), "--mass", "20g", "--config", str(cfg), "--cycles", "2",
                 "--out", str(out), "--quiet"]) == 0
    side = json.loads(out.with_suffix(".json").read_text())
    assert side["params"]["mass_kg"] == pytest.approx(0.02) and side["params"]["stiffness_N_per_m"] == 6e3
    assert side["waveform"]["frequency_Hz"] == 4.0
    defaults = side["summary"]["designed_device"]["defaults"]
    assert set(defaults) == {"area_m2", "load_ohm", "amplitude_Pa", "field"}  # field: finite, issue 51
    # the defaults are the paper's Fig. 8 device, whose σ, ε_r, T and d0 a design takes by default
    from tengsim.cases.paper import fig8_params

    f8 = fig8_params(1.0)
    for k in ("mass_kg", "stiffness_N_per_m", "area_m2", "load_ohm"):
        assert DEFAULTS[k][0] == getattr(f8, k), k


@pytest.mark.parametrize("argv, words", [
    (["device", "design", "--pressure", "30kPa"], "presses to 30 kPa, beyond the pressures of A/S(P)"),
    (["device", "fig8"], "presses to 150 kPa, beyond"),
    (["device", "design", "--frequency", "-2Hz"], "frequency must be > 0 Hz, got -2 Hz"),
    (["device", "design", "--mass", "-2g"], "--mass must be > 0, got '-2g'"),
])
def test_a_waveform_outside_the_table_or_a_bad_value_is_one_line_nothing_written(d1, tmp_path, capsys, argv, words):
    out = tmp_path / "x.csv"
    assert main([*argv, "--area-from", str(d1), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and words in err and not out.exists()


def test_device_design_needs_a_design_result(tmp_path, capsys):
    out = tmp_path / "x.csv"
    assert main(["device", "design", "--out", str(out)]) == 2
    assert "needs a design result" in capsys.readouterr().err and not out.exists()


def test_fig7_with_a_designs_area_is_the_papers_device_and_says_so(d1, tmp_path, capsys):
    out = tmp_path / "f7.csv"
    assert main(["device", "fig7", "--area-from", str(d1), "--cycles", "2", "--dt", "1e-3", "--out", str(out)]) == 0
    err = capsys.readouterr().err
    assert "fig7 is the paper's device" in err and "tengsim device design" in err
    side = json.loads(out.with_suffix(".json").read_text())
    assert side["params"]["gap_m"] == pytest.approx(1e-3)  # Fig. 7's, not the design's
