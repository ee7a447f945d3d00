"""[contact] control keys: load control and adaptive steps from the CLI and TOML; bad combinations refused."""
import csv

import numpy as np
import pytest

from tengsim.cli.main import main
from tengsim.run.plan import plan_contact
from tengsim.continuation import LoadPathSpec, PathSpec
from tengsim.cases.paper.units import paper_scaling

GROUP_A = ["contact", "pyramid", "--N", "0.946", "--cell", "3.78", "--tabor", "0.5", "--dx", "0.3", "--quiet"]
PHYS_A = ["contact", "pyramid", "--pitch", "2um", "--base", "1um", "--height", "0.7um", "--E-star", "0.59MPa",
          "--W", "54mJ/m2", "--tabor", "0.5"]


def _rows(path):
    with open(path) as fh:
        lines = [l for l in fh if not l.startswith("#")]
    return list(csv.DictReader(lines))


def _on_grid_F(path, branch):
    return np.array([float(r["F"]) for r in _rows(path) if r["branch"] == branch and r["on_grid"] in ("1", "True")])


def test_cli_load_control_hits_targets(tmp_path):
    out = tmp_path / "l.csv"
    assert main([*GROUP_A, "--control", "load", "--f-min", "-0.5", "--f-max", "1", "--f-step", "0.25",
                 "--out", str(out)]) == 0
    tol = 1e-4 * 0.25  # LoadPathSpec's default f_tol
    up, down = _on_grid_F(out, "approach"), _on_grid_F(out, "retraction")
    # approach: loads below the far-field F (−0.5, −0.25) are skipped (the body stays away)
    np.testing.assert_allclose(up, [0.0, 0.25, 0.5, 0.75, 1.0], atol=tol)
    assert np.all(np.abs(down - np.round(down / 0.25) * 0.25) <= tol)
    assert down[0] == pytest.approx(1.0, abs=tol) and len(down) >= 5
    head = "".join(l for l in open(out) if l.startswith("#"))
    assert "control" in head and "f_step" in head


def test_toml_load_control_and_adaptive(tmp_path):
    out = tmp_path / "l.csv"
    cfg = tmp_path / "run.toml"
    cfg.write_text(f"""
[contact]
shape = "pyramid"
N = 0.946
cell = 3.78
dx = 0.3
control = "load"
f_min = 0
f_max = 0.6
f_step = 0.3
out = "{out}"
""")
    assert main(["run", str(cfg), "--quiet"]) == 0
    np.testing.assert_allclose(_on_grid_F(out, "approach"), [0.0, 0.3, 0.6], atol=1e-4 * 0.3)
    plan = plan_contact({"shape": "pyramid", "N": 0.946, "cell": 3.78, "adaptive": True, "adapt_tol": 0.05,
                         "d_step": 0.4})
    assert isinstance(plan.path, PathSpec) and plan.path.adaptive and plan.path.adapt_tol == 0.05


def test_cli_adaptive_flag(tmp_path):
    out = tmp_path / "a.csv"
    assert main([*GROUP_A, "--d-max", "2", "--d-step", "0.4", "--refine-levels", "6", "--adaptive",
                 "--out", str(out)]) == 0
    head = "".join(l for l in open(out) if l.startswith("#"))
    assert "adapt_tol" in head


def test_physical_pressure_loads_use_the_scaling():
    cfg = {"shape": "pyramid", "pitch": "2um", "base": "1um", "height": "0.7um", "E_star": "0.59MPa",
           "W": "54mJ/m2", "tabor": 0.5, "dx": 0.3, "control": "load", "f_min": "-2kPa", "f_max": "10kPa",
           "f_step": 0.5}
    plan = plan_contact(cfg)
    sc = plan.scaling
    assert isinstance(plan.path, LoadPathSpec)
    # F = p · cell area / (3π W ℓ²/ε): back through the scaling's own pressure()
    assert sc.pressure(plan.path.f_max) == pytest.approx(10e3, rel=1e-12)
    assert sc.pressure(plan.path.f_min) == pytest.approx(-2e3, rel=1e-12)
    assert plan.path.f_step == 0.5  # a plain number is F of Eq. (10)
    a = paper_scaling("A")
    assert sc.pressure(1.0) == pytest.approx(a.pressure(1.0), rel=1e-3)


@pytest.mark.parametrize("bad, word", [
    (["--f-min", "-0.5"], "f_min"),
    (["--control", "load", "--f-max", "1", "--f-step", "0.25", "--adaptive"], "adaptive"),
    (["--control", "load", "--f-max", "1", "--f-step", "0.25", "--adapt-tol", "0.1"], "adapt_tol"),
    (["--adapt-tol", "0.1"], "adapt_tol"),
    (["--control", "load", "--f-max", "1"], "f_step"),
    (["--control", "load", "--f-max", "1kPa", "--f-step", "0.25"], "f_max"),
    (["--control", "pressure"], "control"),
    (["--control", "load", "--f-max", "1", "--f-step", "0"], "f_step"),
    (["--control", "load", "--f-max", "-1", "--f-step", "0.2"], "f_max"),
    (["--adaptive", "maybe"], "adaptive"),
])
def test_bad_control_combinations(tmp_path, capsys, bad, word):
    out = tmp_path / "x.csv"
    rc = main([*GROUP_A, *bad, "--out", str(out)])
    err = capsys.readouterr().err
    assert rc == 2
    assert word in err and "Traceback" not in err
    assert len(err.strip().splitlines()) == 1
    assert list(tmp_path.iterdir()) == []


def test_physical_pressure_needs_a_pressure(tmp_path, capsys):
    rc = main([*PHYS_A, "--control", "load", "--f-max", "10um", "--f-step", "0.5", "--out", str(tmp_path / "x.csv")])
    assert rc == 2
    err = capsys.readouterr().err
    assert "f_max" in err and "pressure" in err
    assert list(tmp_path.iterdir()) == []


# ---- issue 21: maps at a requested D or load, never dropped; a load not met is warned about -------------


def test_cli_maps_at_off_the_d_step_lattice(tmp_path, capsys):
    """`--maps-at 1.1` with `--d-step 0.25`: the maps at D = 1.1 on both branches (an extra row each)."""
    import xarray as xr

    out = tmp_path / "m.nc"
    assert main([*GROUP_A, "--d-max", "2", "--d-step", "0.25", "--maps-at", "1.1", "--out", str(out)]) == 0
    ds = xr.load_dataset(out)
    assert sorted(zip(ds["map_branch"].values.astype(str), ds["map_D"].values.tolist())) == [
        ("approach", 1.1), ("retraction", 1.1)]
    at = np.flatnonzero(ds["D"].values == 1.1)
    assert len(at) == 2 and not ds["on_grid"].values[at].astype(bool).any()


def test_cli_load_maps_at_off_the_f_step_lattice(tmp_path):
    import xarray as xr

    out = tmp_path / "l.nc"
    assert main([*GROUP_A, "--control", "load", "--f-max", "0.5", "--f-step", "0.25", "--maps-at", "0.1",
                 "--out", str(out)]) == 0
    ds = xr.load_dataset(out)
    assert sorted(ds["map_branch"].values.astype(str)) == ["approach", "retraction"]
    F = ds["F"].values
    for D in ds["map_D"].values:  # the rows the maps were kept at hold the load 0.1
        assert abs(F[np.flatnonzero(ds["D"].values == D)[0]] - 0.1) <= 1e-4 * 0.25


@pytest.mark.parametrize("bad, words", [
    (["--d-max", "2", "--d-step", "0.25", "--maps-at", "2.1"], "maps_at D = 2.1 is outside the path's D range [-1, 2]"),
    (["--maps-at", "1.1"], "maps_at = 1.1 needs a .nc output: out = "),
    (["--control", "load", "--f-max", "0.5", "--f-step", "0.25", "--maps-at", "-2"],
     "maps_at load F = -2 is outside the path's load range [0, 0.5]"),
])
def test_cli_maps_at_refused_one_line_nothing_written(tmp_path, capsys, bad, words):
    rc = main([*GROUP_A, *bad, "--out", str(tmp_path / "x.csv")])
    err = capsys.readouterr().err
    assert rc == 2 and words in err and len(err.strip().splitlines()) == 1, err
    assert list(tmp_path.iterdir()) == []


def test_cli_load_not_met_warns_with_where(tmp_path, capsys, monkeypatch):
    """A load whose outer solve stops short of f_tol (regula falsi capped at one step here): exit 0, the
    rows not_converged, and the warnings say which loads and where."""
    from tengsim.continuation import load as loadpath

    monkeypatch.setattr(loadpath._LoadBranch, "max_root_steps", 1)
    out = tmp_path / "l.csv"
    assert main([*GROUP_A, "--control", "load", "--f-max", "0.5", "--f-step", "0.25", "--out", str(out)]) == 0
    err = capsys.readouterr().err
    lines = [l for l in err.splitlines() if l.startswith("tengsim: warning:")]
    assert any("not converged" in l and "load not met to f_tol" in l and "approach D" in l for l in lines), err
    assert any("load(s) not met, first approach: load F = " in l and "D in [" in l for l in lines), err
    rows = _rows(out)
    assert any(r["status"] == "not_converged" for r in rows)
    head = "".join(l for l in open(out) if l.startswith("#"))
    assert "load_not_met" in head
