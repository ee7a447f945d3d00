"""`tengsim device ... --field parallel|finite --electrode-side/--electrode-diameter`: the outputs and the refusals."""
import json

import pytest

from tengsim.cli.main import main


def test_fig7_finite_disk_outputs(tmp_path, capsys):
    out = tmp_path / "f7.csv"
    assert main(["device", "fig7", "--field", "finite", "--electrode-diameter", "7cm", "--cycles", "2", "--out",
                 str(out), "--quiet"]) == 0
    side = json.loads(out.with_suffix(".json").read_text())
    s = side["summary"]
    assert s["field_model"] == "finite" and side["params"]["field"] == "finite"
    assert s["electrode"]["shape"] == "disk" and s["electrode"]["size_m"] == pytest.approx(0.07)
    assert side["params"]["area_m2"] == pytest.approx(3.14159265 * 0.035 ** 2)
    v = s["voc_at_max_gap_V"]
    assert 0.85 < v["finite"] / v["parallel"] < 1.0  # ~1 mm on 7 cm: a few % of fringing
    assert s["voc_V"] == pytest.approx(v["finite"], rel=1e-3)
    assert s["sigma_breakdown_C_m2"] > s["sigma_times_area_fraction_C_m2"] and s["breakdown_exceeded"] is False
    assert s["sigma_breakdown_short_C_m2"] > s["sigma_breakdown_C_m2"]
    # the breakdown-limited CMEO to the run's largest gap: below the cap, the cycle is the unlimited one, its
    # energy the closed form's (tests/test_device_breakdown.py) and its FOM_S of order one at x ~ 1 mm on 7 cm
    c = s["breakdown_cycle"]
    assert c["x_max_m"] == pytest.approx(v["gap_m"]) and c["sigma_held_C_m2"] == pytest.approx(
        s["sigma_times_area_fraction_C_m2"])
    assert c["energy_J"] == pytest.approx(c["energy_unlimited_J"], rel=1e-12) and 0.1 < c["fom_structural"] < 2.0
    from tengsim.device import DeviceParams
    from tengsim.device.breakdown import breakdown_cycle

    p = DeviceParams(**{k: side["params"][k] for k in ("mass_kg", "stiffness_N_per_m", "area_m2", "thickness_m",
                                                       "gap_m", "eps_r", "sigma_C_per_m2", "field",
                                                       "electrode_shape")})
    ref = breakdown_cycle(p, c["x_max_m"], sigma_area_C_m2=c["sigma_held_C_m2"])
    assert c["energy_J"] == pytest.approx(ref.energy_J, rel=1e-9)


@pytest.mark.parametrize("argv, msg", [
    (["--electrode-side", "-2cm"], "--electrode-side must be > 0, got '-2cm'"),
    (["--electrode-side", "2kg"], "--electrode-side = '2kg' is a mass, expected a length"),
    (["--electrode-side", "2cm", "--electrode-diameter", "1cm"], "not both"),
    (["--air-pressure", "0Pa"], "--air-pressure must be > 0"),
])
def test_bad_field_options_one_line_exit_2_nothing_written(tmp_path, capsys, argv, msg):
    out = tmp_path / "f7.csv"
    assert main(["device", "fig7", "--out", str(out)] + argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and msg in err[0]
    assert not out.exists() and not out.with_suffix(".json").exists()
