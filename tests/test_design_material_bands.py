"""`tengsim design --material` (issue 48, issue 49 item 5): the material's band points read by one reader and planned
with the design's own bounds before anything runs (one line, exit 2, nothing written); a comparison of designs with
a material writes each design's band; the library plans and predicts the bands (plan_design(table, material))."""
import csv

import numpy as np
import pytest

from tengsim.cli.main import main

TINY = {"shape": "pyramid", "pitch": "1um", "base": "0.5um", "height": "0.2um", "E_star": "5MPa", "W": "20mJ/m2",
        "eps": "50nm", "p_max": "20kPa", "p_step": "10kPa", "tol": 0.05, "maps": False}
MATERIAL = '[design]\nE_star = "5MPa"\nW = "20mJ/m2"\neps = "50nm"\nsigma = "6uC/m2"\n'


def _toml(path, table):
    path.write_text("[design]\n" + "".join(f'{k} = "{v}"\n' if isinstance(v, str) else
                                           f"{k} = {str(v).lower()}\n" for k, v in table.items()))
    return path


def _points(*pts):
    return "".join("\n[[uncertainty.point]]\n" + "".join(f'{k} = "{v}"\n' for k, v in p.items()) for p in pts)


def _refused(tmp_path, capsys, material_text, *words):
    d = _toml(tmp_path / "d.toml", TINY)
    (tmp_path / "m.toml").write_text(material_text)
    rc = main(["design", str(d), "--material", str(tmp_path / "m.toml"), "--out", str(tmp_path / "o"), "--quiet"])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and len(err.splitlines()) == 1, err
    assert not (tmp_path / "o").exists()  # nothing written, nothing run
    for w in words:
        assert w in err, err
    return err


def test_negative_sigma_band_point_refused(tmp_path, capsys):
    _refused(tmp_path, capsys, MATERIAL + _points({"sigma": "-5uC/m2"}), "sigma", "[[uncertainty.point]] 1",
             "-5uC/m2", "m.toml")


def test_huge_sigma_band_point_refused(tmp_path, capsys):
    _refused(tmp_path, capsys, MATERIAL + _points({"sigma": "6uC/m2"}, {"sigma": "1e9C/m2"}), "sigma",
             "[[uncertainty.point]] 2", "outside")


def test_band_point_not_a_number_refused_before_any_work(tmp_path, capsys):
    _refused(tmp_path, capsys, MATERIAL + _points({"W": "abc"}), "W", "'abc'", "[[uncertainty.point]] 1")


def test_material_value_out_of_bounds_names_the_material(tmp_path, capsys):
    _refused(tmp_path, capsys, MATERIAL.replace('"6uC/m2"', '"-6uC/m2"'), "sigma", "m.toml")


@pytest.mark.parametrize("point", ["5", '["a"]', '"x"'])
def test_uncertainty_point_not_tables_is_one_line(tmp_path, capsys, point):
    _refused(tmp_path, capsys, MATERIAL + f"\n[uncertainty]\npoint = {point}\n", "point must be tables", "m.toml")


def test_material_table_beside_is_refused(tmp_path, capsys):
    _refused(tmp_path, capsys, MATERIAL + "\n[contact]\nlaw = 'md'\n", "unknown table", "contact")


def test_plan_design_with_material_plans_the_band_points():
    from tengsim.design import Material, plan_design

    mat = Material({"sigma": "6uC/m2", "W": "25mJ/m2"}, ({"sigma": "5uC/m2"}, {"sigma": "7uC/m2", "W": "30mJ/m2"}),
                   "m.toml")
    plan = plan_design(TINY, material=mat)
    assert plan.sigma == pytest.approx(6e-6) and plan.W == pytest.approx(25e-3)
    assert [b.sigma for b in plan.bands] == pytest.approx([5e-6, 7e-6])
    assert [b.W for b in plan.bands] == pytest.approx([25e-3, 30e-3])
    assert not any(b.maps for b in plan.bands) and plan_design(TINY).bands == ()


def test_comparison_of_two_designs_with_material_writes_each_band(tmp_path, capsys):
    """Two designs compared with --material (old: NameError _slug after everything was computed): each design's
    folder gets its band; σ-only points cost no design of their own (V_OC is linear in σ)."""
    from tengsim.device.formulas import voc_polymer

    a = _toml(tmp_path / "a.toml", {**TINY, "name": "first"})
    b = _toml(tmp_path / "b.toml", {**TINY, "name": "second", "height": "0.25um"})
    (tmp_path / "m.toml").write_text(MATERIAL + _points({"sigma": "5uC/m2"}, {"sigma": "7uC/m2"}))
    out = tmp_path / "cmp"
    rc = main(["design", str(a), str(b), "--material", str(tmp_path / "m.toml"), "--out", str(out), "--quiet"])
    assert rc == 0, capsys.readouterr().err
    assert (out / "compare.csv").is_file()
    for name in ("first", "second"):
        text = (out / name / "bands.csv").read_text()
        assert "all_ok: true" in text and (out / name / "bands.png").is_file()
        rows = list(csv.DictReader(ln for ln in text.splitlines() if not ln.startswith("#")))
        a_s = np.array([float(r["area_fraction"]) for r in rows])
        lo = np.array([float(r["voc_eq12_lower_V"]) for r in rows])
        hi = np.array([float(r["voc_eq12_upper_V"]) for r in rows])
        np.testing.assert_allclose(lo, voc_polymer(a_s, 5e-6, 2.4, 400e-6), rtol=1e-9)
        np.testing.assert_allclose(hi, voc_polymer(a_s, 7e-6, 2.4, 400e-6), rtol=1e-9)


def test_design_help_says_the_boundary_is_periodic(capsys):
    assert main(["design", "--help"]) == 0
    out = capsys.readouterr().out
    i = out.index("--boundary")
    assert "periodic (a design's default)" in out[i:i + 200] and "defaults as tengsim contact):" not in out


def test_band_point_that_cannot_run_here_is_refused_before_the_design_runs(tmp_path, capsys):
    """A band point whose design no machine can run (ε 0.1 nm: a grid 500 times finer per side than the design's)
    is planned and preflighted with the design: one line naming the point, nothing run or written."""
    _refused(tmp_path, capsys, MATERIAL + _points({"sigma": "5uC/m2"}, {"eps": "0.1nm"}), "[[uncertainty.point]] 2")
