"""``tengsim design ... --relaxation``: the design's contact cycled on a viscoelastic material (tengsim.design.visco)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from tengsim.cli.main import main
from tengsim.design.plan import plan_design
from tengsim.design.visco import _t90, visco_cycles
from tengsim.design.visco_write import write_visco
from tengsim.relaxation import sls

TABLE = {"shape": "pyramid", "pitch": "10um", "base": "5um", "height": "3.5um", "E_star": "1MPa", "W": "50mJ/m2",
         "eps": "200nm", "p_max": "40kPa", "p_step": "10kPa"}


def test_t90_of_a_known_rise():
    t = np.linspace(0, 1, 1001)
    v = 1 - np.exp(-t / 0.1)
    assert _t90(t, v / v[-1], 0.0, 1.0) == pytest.approx(0.1 * math.log(10), rel=1e-3)


def test_cycles_show_the_rate_and_write_their_files(tmp_path):
    """A material relaxing at 1 s: at 10 Hz the solid is stiffer (smaller A/S at p_max) than relaxed (E∞), and
    the cycle lags (a recovery time); the files and the report section are written."""
    plan = plan_design(dict(TABLE))
    mat = sls(1e6, 1e6, 1.0)
    vd = visco_cycles(plan, mat, frequencies=(10.0,), pixels=16, steps=4)
    rows = {r["frequency_Hz"]: r for r in vd.table}
    assert set(rows) == {0.0, 10.0}
    assert rows[10.0]["area_max"] < rows[0.0]["area_max"]
    assert math.isnan(rows[0.0]["response_s"]) and rows[10.0]["recovery_s"] > 0
    (tmp_path / "report.md").write_text("# design\n")
    paths = write_visco(vd, tmp_path)
    assert all(p.exists() for p in paths)
    assert "Viscoelastic cycles" in (tmp_path / "report.md").read_text()


def test_bad_relaxation_file_is_one_line_before_anything_runs(tmp_path, capsys):
    bad = tmp_path / "r.toml"
    bad.write_text("[relaxation]\nE_inf = 'soft'\n")
    out = tmp_path / "d"
    args = ["design", "pyramid", *(f"--{k.replace('_', '-')}={v}" for k, v in TABLE.items() if k != "shape"),
            "--relaxation", str(bad), "--out", str(out), "--quiet"]
    assert main(args) == 2
    err = capsys.readouterr().err.strip()
    assert "relaxation E_inf" in err and len(err.splitlines()) == 1
    assert not out.exists()
