"""``tengsim contact ... --relaxation FILE``: a physical run on a time axis; bad input is one line, exit 2."""
from __future__ import annotations

import csv
from pathlib import Path

import pytest

from tengsim.cli.main import main

PDMS = str(Path(__file__).resolve().parents[1] / "examples" / "relaxation" / "pdms.toml")
BASE = ["contact", "sphere", "--radius", "1um", "--pitch", "1.5um", "--E-star", "1MPa", "--W", "50mJ/m2",
        "--tabor", "1.0", "--dx", "100nm", "--quiet"]


def test_history_file_run_writes_a_time_table(tmp_path):
    h = tmp_path / "h.csv"
    h.write_text("time_s,approach_nm\n0,-200\n0.05,150\n0.1,-200\n")
    out = tmp_path / "v.csv"
    rc = main(BASE + ["--relaxation", PDMS, "--history", str(h), "--dt", "10ms",
                      "--out", str(out)])
    assert rc == 0
    rows = list(csv.DictReader(out.open()))
    assert float(rows[-1]["time"]) == pytest.approx(0.1)
    assert len(rows) >= 11
    assert max(float(r["area_fraction"]) for r in rows) > 0     # it touched
    assert float(rows[0]["approach_m"]) == pytest.approx(-200e-9)


@pytest.mark.parametrize("extra, words", [
    (["--wave", "triangle", "--wave-to", "2s", "--wave-time", "1s"], "--wave-to 2s"),
    (["--wave", "triangle", "--wave-to", "50nm"], "--wave-time"),
    ([], "needs a history"),
])
def test_bad_history_options_are_one_line_exit_2(tmp_path, capsys, extra, words):
    out = tmp_path / "v.csv"
    rc = main(BASE + ["--relaxation", PDMS, *extra, "--out", str(out)])
    assert rc == 2
    err = capsys.readouterr().err.strip()
    assert words in err and len(err.splitlines()) == 1
    assert not out.exists()


def test_bad_relaxation_file_is_refused(tmp_path, capsys):
    bad = tmp_path / "r.toml"
    bad.write_text('[relaxation]\nE_inf = "1MPa"\nbranches = [{E = "1MPa", tau = "-1s"}]\n')
    rc = main(BASE + ["--relaxation", str(bad), "--wave", "triangle", "--wave-to", "50nm", "--wave-time", "1s",
                      "--out", str(tmp_path / "v.csv")])
    assert rc == 2
    assert "tau must be > 0" in capsys.readouterr().err


def test_out_equal_to_the_relaxation_file_is_refused_and_the_file_kept(tmp_path, capsys):
    """An output path that is an input (the relaxation TOML) is refused before any work: the file is not replaced."""
    mat = tmp_path / "pdms.toml"
    mat.write_text(Path(PDMS).read_text())
    before = mat.read_bytes()
    rc = main(BASE + ["--relaxation", str(mat), "--wave", "triangle", "--wave-to", "50nm", "--wave-time", "0.1s",
                      "--out", str(mat)])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(err) == 1 and err[0].startswith("tengsim: error:"), err
    assert mat.read_bytes() == before


@pytest.mark.parametrize("flag", ["--relaxation", "--history"])
def test_random_bytes_as_relaxation_or_history_is_one_line(tmp_path, capsys, flag):
    junk = tmp_path / "junk"
    junk.write_bytes(bytes(range(128, 256)) * 3)
    extra = (["--relaxation", str(junk), "--wave", "triangle", "--wave-to", "50nm", "--wave-time", "0.1s"]
             if flag == "--relaxation" else ["--relaxation", PDMS, "--history", str(junk)])
    rc = main(BASE + extra + ["--out", str(tmp_path / "v.csv")])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(err) == 1 and "not a text" in err[0], err
    assert not (tmp_path / "v.csv").exists()
