"""The device reads a design's states (issue 48 item 5): `device design --area-from d/design.nc` takes A/S off the
states the design's pressed device passes (the curve calibrate's nodes are read off), so across a snap between two
asked pressures V_OC is the branch the device is on, not a straight line from one asked pressure to the next."""
import json

import numpy as np
import pytest
import xarray as xr

from tengsim.cli.main import main
from tengsim.device import area_table_from_design
from tengsim.device.formulas import voc_polymer

P = np.array([0.0, 5e3, 10e3])  # the asked pressures
APPROACH = np.array([0.05, 0.50, 0.55])  # A/S there (the states below, interpolated)
# the states passed on the approach: a snap at 0.77 kPa (two states at one load, as a design writes it), from A/S
# 0.06 to 0.45, then the contact grows slowly; the walk runs a little past p_max (11 kPa, beyond every asked one)
SP = np.array([0.0, 0.4e3, 0.77e3, 0.77e3, 2e3, 5e3, 8e3, 11e3])
SA = np.array([0.05, 0.055, 0.06, 0.45, 0.47, 0.50, 0.53, 0.56])
SIGMA, EPS_R, T, GAP = 5.84e-6, 2.4, 400e-6, 1e-4


def snapped_design(folder):
    """A design.nc to the writer's contract (tengsim.design.write.to_dataset) with a known snap between asked
    pressures: its A/S at the asked pressures and its states."""
    folder.mkdir(parents=True, exist_ok=True)
    n = len(SP)
    ret = np.array([0.6, 0.6, 0.55])
    bv = lambda a, r: (("branch", "applied_pressure"), np.vstack([a, r]))  # noqa: E731
    sv = lambda a: (("branch", "path_state"), np.vstack([a, np.full(n, np.nan)]))  # noqa: E731
    ds = xr.Dataset(
        {"charged_area_fraction": bv(APPROACH, ret), "repulsive_area_fraction": bv(APPROACH / 2, ret / 2),
         "voc_eq12": bv(voc_polymer(APPROACH, SIGMA, EPS_R, T), voc_polymer(ret, SIGMA, EPS_R, T)),
         "voc_eq17": bv(APPROACH, ret), "dvoc_dp": bv(APPROACH * 0, ret * 0),
         "state_pressure": sv(SP), "state_charged_area_fraction": sv(SA)},
        coords={"pressure": ("applied_pressure", P, {"units": "Pa"}),
                "branch": ("branch", np.array(["approach", "retraction"], dtype=object))},
        attrs={"Conventions": "CF-1.10", "shape": "pyramid", "shape_params": json.dumps({"pitch_m": 1e-6}),
               "E_star_Pa": 1e6, "W_J_m2": 0.05, "eps_m": 5e-8, "tabor": 0.5, "sigma_C_m2": SIGMA, "eps_r": EPS_R,
               "thickness_m": T, "gap_m": GAP, "status": "ok", "grids": "dx 20 nm", "tolerance": 0.01,
               "charged_area_definition": "contact"})
    ds["branch"].encoding["dtype"] = "S1"
    ds.to_netcdf(folder / "design.nc", engine="h5netcdf")
    return folder / "design.nc"


def test_passed_curve_is_the_states_between_the_asked_ends():
    from tengsim.device.areas import passed_curve

    p, a = passed_curve(SP, SA, 0.0, 10e3)
    np.testing.assert_array_equal(p, [0.0, 0.4e3, 0.77e3, 0.77e3, 2e3, 5e3, 8e3, 10e3])
    assert a[-1] == pytest.approx(0.53 + (0.56 - 0.53) * 2 / 3)  # the end read off the states, none beyond
    assert np.all(np.diff(a) >= 0)


def test_area_table_across_snap_follows_states(tmp_path):
    table = area_table_from_design(snapped_design(tmp_path / "d"))
    assert table.pressure_Pa[0] == 0.0 and table.pressure_Pa[-1] == 10e3  # the design's pressures, not beyond
    assert float(table(3e3)) == pytest.approx(0.47 + 0.03 / 3, rel=1e-12)  # the states' branch, past the snap
    assert float(table(0.77e3)) == pytest.approx(0.06) and float(table(0.771e3)) == pytest.approx(0.45, abs=1e-4)
    straight = float(np.interp(3e3, P, APPROACH))  # the old reading: a line from 0 to 5 kPa across the snap
    assert straight < 0.33 and float(table(3e3)) > 0.47
    np.testing.assert_allclose(table(P), APPROACH, rtol=1e-12)  # the asked pressures' values unchanged


def test_device_voc_across_snap_follows_states(tmp_path, capsys):
    """`tengsim device design --area-from` pressed to 3 kPa: the device charges A/S of the states (0.48), not of the
    straight line across the snap (0.32), and its V_OC back at the rest gap is Eq. 17 with that A/S (old: 33 % low)."""
    from tengsim.design.device import DEFAULTS
    from tengsim.device.formulas import voc_apart

    snapped_design(tmp_path / "d")
    out = tmp_path / "dev.nc"
    rc = main(["device", "design", "--area-from", str(tmp_path / "d"), "--pressure", "3kPa", "--cycles", "2",
               "--field", "parallel", "--out", str(out), "--quiet"])  # Eq. 17's plates: the area is what is tested
    assert rc == 0, capsys.readouterr().err
    ds = xr.load_dataset(out)
    charged = float(np.max(ds["area"].values)) / DEFAULTS["area_m2"][0]  # m² of the electrode's area → A/S
    assert charged == pytest.approx(0.48, rel=1e-9)
    summary = json.loads(ds.attrs["summary"])
    want = float(voc_apart(SIGMA, 0.48, summary["gap_at_rest_m"], 1.0))
    assert summary["voc_at_rest_gap_V"] == pytest.approx(want, rel=1e-6)
    assert summary["voc_at_rest_gap_V"] > 1.4 * float(voc_apart(SIGMA, np.interp(3e3, P, APPROACH), GAP, 1.0))
