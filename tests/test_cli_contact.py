"""Command line: contact runs, TOML configs, plot, and clear errors with no partial output."""
import csv
import json

import numpy as np
import pytest
import xarray as xr

from tengsim.cli.main import main

GROUP_A = ["contact", "pyramid", "--N", "0.946", "--cell", "3.78", "--tabor", "0.5", "--dx", "0.2",
           "--d-min", "-1", "--d-max", "2", "--d-step", "0.25", "--quiet"]


def _rows(path):
    with open(path) as fh:
        lines = [l for l in fh if not l.startswith("#")]
    return list(csv.DictReader(lines))


def test_contact_csv_has_required_columns_and_grid_rows(tmp_path):
    out = tmp_path / "a.csv"
    assert main(GROUP_A + ["--out", str(out)]) == 0
    rows = _rows(out)
    for col in ("branch", "D", "F", "contact_length", "converged", "residual"):
        assert col in rows[0]
    for branch in ("approach", "retraction"):
        D = [float(r["D"]) for r in rows if r["branch"] == branch and r["on_grid"] == "1"]
        expected = -1 + 0.25 * np.arange(13)
        assert sorted(D) == pytest.approx(expected)
    assert all(r["converged"] == "1" for r in rows)
    assert max(float(r["residual"]) for r in rows) <= 1e-6
    # parameters travel in the header
    head = [l for l in open(out) if l.startswith("#")]
    assert any(l.startswith("# tabor: 0.5") for l in head)


def test_contact_netcdf_roundtrip_and_plot(tmp_path):
    out = tmp_path / "a.nc"
    assert main(GROUP_A + ["--out", str(out), "--maps", "1"]) == 0
    ds = xr.load_dataset(out)
    assert ds["P"].shape[0] == 2  # D = 1 on approach and on retraction
    params = json.loads(ds.attrs["params"])
    assert params["N"] == pytest.approx(0.946)
    png = tmp_path / "a.png"
    assert main(["plot", str(out), "--out", str(png)]) == 0
    assert png.stat().st_size > 10_000


def test_physical_input_matches_dimensionless(tmp_path):
    """2 µm pitch, 1 µm base, 0.7 µm height with E* = 0.59 MPa, W = 54 mJ/m², μ = 0.5 is group A."""
    phys, dim = tmp_path / "p.csv", tmp_path / "d.csv"
    args = ["contact", "pyramid", "--pitch", "2um", "--base", "1um", "--height", "0.7um",
            "--E-star", "0.59MPa", "--W", "54mJ/m2", "--tabor", "0.5", "--dx", "0.2",
            "--d-max", "2", "--d-step", "0.25", "--quiet", "--out", str(phys)]
    assert main(args) == 0
    assert main(["contact", "pyramid", "--N", str(0.7 / (2 * 0.36981855868)), "--cell",
                 str(2 * 0.7 / (0.36981855868 * 1.0)), "--dx", "0.2", "--d-max", "2", "--d-step", "0.25",
                 "--quiet", "--out", str(dim)]) == 0
    Fp = [float(r["F"]) for r in _rows(phys)]
    Fd = [float(r["F"]) for r in _rows(dim)]
    assert Fp == pytest.approx(Fd, rel=1e-6, abs=1e-9)


@pytest.mark.parametrize("bad, word", [
    (["--N", "-1", "--cell", "3"], "N"),
    (["--N", "nan", "--cell", "3"], "nan"),
    (["--N", "3", "--cell", "3.78"], "wider than its cell"),
    (["--N", "0.9", "--cell", "3.78", "--dx", "0"], "dx"),
    (["--N", "0.9", "--cell", "3.78", "--boundary", "moebius"], "moebius"),
    (["--N", "0.9", "--cell", "3.78", "--d-step", "-0.1"], "d_step"),
])
def test_bad_input_one_line_exit_2_no_file(tmp_path, capsys, bad, word):
    out = tmp_path / "x.csv"
    rc = main(["contact", "pyramid", *bad, "--quiet", "--out", str(out)])
    err = capsys.readouterr().err
    assert rc == 2
    assert word in err and "Traceback" not in err
    assert len(err.strip().splitlines()) == 1
    assert not out.exists() and list(tmp_path.iterdir()) == []


def test_unknown_unit_is_named(tmp_path, capsys):
    rc = main(["contact", "pyramid", "--pitch", "2um", "--base", "1um", "--height", "0.7furlong",
               "--E-star", "0.59MPa", "--W", "54mJ/m2", "--tabor", "0.5", "--out", str(tmp_path / "x.nc")])
    assert rc == 2
    assert "furlong" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


def test_toml_config_runs_and_records_itself(tmp_path):
    cfg = tmp_path / "run.toml"
    out = tmp_path / "r.csv"
    cfg.write_text(f"""
[contact]
shape = "pyramid"
N = 0.946
cell = 3.78
dx = 0.2
d_max = 1.5
d_step = 0.25
out = "{out}"
""")
    assert main(["run", str(cfg), "--quiet"]) == 0
    head = "".join(l for l in open(out) if l.startswith("#"))
    assert "config_file" in head and "tengsim_version" in head


@pytest.mark.parametrize("text, word", [
    ("[contact\nN = 1", "not valid TOML"),
    ("[contact]\nN = 0.9\ncell = 3.78\nbogus = 1\nout = 'x.csv'", "bogus"),
    ("[nothing]\n", "nothing"),
    ("[contact]\nN = 0.9\ncell = 3.78\nrefine_levels = 1.5\nout = 'x.csv'", "refine_levels"),
    ("[contact]\nshape = 'cube'\nhalf_width = '0.7um'\nout = 'x.csv'", "half_width"),
    ("[contact]\nshape = 'cone'\nradius = 2\nout = 'x.csv'", "radius"),
    ("[contact]\nN = 0.9\ncell = 3.78\nout = 'x.csv'\nplot = 'x.txt'", "plot"),
    ("[reproduce]\nquick = 'maybe'", "quick"),
])
def test_bad_config(tmp_path, capsys, text, word):
    cfg = tmp_path / "bad.toml"
    cfg.write_text(text)
    assert main(["run", str(cfg)]) == 2
    assert word in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.toml"]


def test_missing_config_file(tmp_path, capsys):
    assert main(["run", str(tmp_path / "nope.toml")]) == 2
    assert "not found" in capsys.readouterr().err


def test_shipped_examples_are_valid():
    """Every example config in examples/ plans without error (the README points users to them)."""
    from pathlib import Path

    from tengsim.run.plan import plan_contact
    from tengsim.schema import read_config as load_toml

    files = sorted((Path(__file__).parent.parent / "examples").glob("*.toml"))
    assert files
    shapes = set()
    for f in files:
        cfg = load_toml(f)
        if "contact" in cfg:
            plan = plan_contact(cfg["contact"])
            assert plan.tabor > 0 and plan.path.d_max > plan.path.d_min
            shapes.add((cfg["contact"].get("shape", "pyramid"), plan.scaling is not None))
    # examples show physical input for more than the paper's pyramid, and a dimensionless run
    assert {("sphere", True), ("cone", True)} <= shapes and any(not phys for _, phys in shapes)


def test_unwritable_output_fails_before_running(tmp_path, capsys):
    blocker = tmp_path / "file"
    blocker.write_text("x")  # a file where a folder would have to be
    rc = main(GROUP_A + ["--out", str(blocker / "sub" / "a.csv")])
    err = capsys.readouterr().err
    assert rc == 2 and "cannot write" in err and "Traceback" not in err
    assert main(["reproduce", "--quick", "--quiet", "--out", str(blocker / "paper")]) == 2
    assert sorted(p.name for p in tmp_path.iterdir()) == ["file"]
