"""One reader of a design file (issue 48 item 2, issue 49 item 5): `design` and `calibrate` read a design's tables
through tengsim.design.design_table (the file by tengsim.schema.read_config), so a table one command refuses the
other refuses the same way; no command drops a table it does not read."""
import numpy as np
import pytest

from tengsim.cli.main import main
from tengsim.errors import TengsimError

DESIGN = ('shape = "pyramid"\npitch = "1um"\nbase = "0.5um"\nheight = "0.2um"\nE_star = "5MPa"\nW = "20mJ/m2"\n'
          'eps = "50nm"\np_max = "20kPa"\np_step = "10kPa"\n')


def _both(tmp_path, capsys, text):
    """(design's one line, calibrate's one line) for the design file ``text``; neither writes anything."""
    f = tmp_path / "d.toml"
    f.write_text(text)
    (tmp_path / "m.csv").write_text("pressure_kPa,voc_V\n5,10\n10,12\n15,13\n20,14\n")
    rc = main(["design", str(f), "--out", str(tmp_path / "o1"), "--quiet"])
    e1 = capsys.readouterr().err.strip()
    rc2 = main(["calibrate", str(f), "--data", str(tmp_path / "m.csv"), "--out", str(tmp_path / "o2"), "--quiet"])
    e2 = capsys.readouterr().err.strip()
    assert rc == rc2 == 2, (e1, e2)
    assert not (tmp_path / "o1").exists() and not (tmp_path / "o2").exists()
    return e1, e2


def test_calibrate_refuses_md_law_as_design_does(tmp_path, capsys):
    """[contact] law = "md" beside [design]: design refuses it; calibrate dropped the table and fitted LJ93."""
    e1, e2 = _both(tmp_path, capsys, "[design]\n" + DESIGN + '\n[contact]\nlaw = "md"\n')
    for e in (e1, e2):
        assert "'contact' beside [design]" in e and "d.toml" in e and len(e.splitlines()) == 1


def test_calibrate_refuses_a_table_in_a_top_level_design_as_design_does(tmp_path, capsys):
    e1, e2 = _both(tmp_path, capsys, DESIGN + '\n[contact]\nlaw = "md"\n')
    for e in (e1, e2):
        assert "unknown table(s) 'contact'" in e and "d.toml" in e


def test_calibrate_and_design_read_an_unreadable_file_alike(tmp_path, capsys):
    e1, e2 = _both(tmp_path, capsys, "[design\nshape = 1\n")
    for e in (e1, e2):
        assert "not valid TOML" in e and "d.toml" in e


def test_calibrate_honours_the_law_in_design_as_design_does(tmp_path):
    """A law given in [design] (where the design's contact keys belong) is the one both plan."""
    from tengsim.calibrate import plan_calibration
    from tengsim.calibrate.data import Curve
    from tengsim.design import read_design
    from tengsim.design import plan_design

    f = tmp_path / "d.toml"
    f.write_text("[design]\n" + DESIGN + 'law = "md"\n')
    P = np.array([5e3, 10e3, 15e3, 20e3])
    curve = Curve("m", P, np.array([10.0, 12.0, 13.0, 14.0]), ("approach",) * 4)
    prob = plan_calibration([f], [curve], "sigma,W", "W=10mJ/m2:60mJ/m2")
    law = type(prob.plans[0].contact_plan.law).__name__
    assert law == type(plan_design(read_design(str(f))).contact_plan.law).__name__ == "MaugisDugdale"


def test_a_design_table_given_to_the_api_is_read_by_the_same_rules(tmp_path):
    from tengsim.calibrate import plan_calibration
    from tengsim.calibrate.data import Curve

    curve = Curve("m", np.array([5e3, 10e3, 15e3]), np.array([10.0, 12.0, 13.0]), ("approach",) * 3)
    with pytest.raises(TengsimError, match="unknown table"):
        plan_calibration([{"shape": "pyramid", "contact": {"law": "md"}}], [curve])
