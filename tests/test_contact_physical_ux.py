"""A physical `tengsim contact` run end to end in the user's units (issue 29 item 3): the Tabor number at the
start, advice in nm/µm, load errors in kPa, a load-controlled path that extends itself to the loads asked for,
the pull-off in N and Pa, and --resume of a longer path."""
import re

import numpy as np
import pytest
import xarray as xr

from tengsim.cli.main import main
from tengsim.results.read import load_result


def _res(path):
    return load_result(path)[1]

PYR = ["contact", "pyramid", "--pitch", "10um", "--base", "5um", "--height", "3.5um", "--E-star", "1MPa",
       "--W", "50mJ/m2", "--eps", "100nm", "--dx", "1um"]
LOAD = ["--control", "load", "--f-step", "5kPa"]


def _run(argv, capsys, code=0):
    got = main(argv)
    cap = capsys.readouterr()
    assert got == code, cap.err
    return cap.err


def test_load_control_extends_itself_to_the_pressure_asked_for(tmp_path, capsys):
    out = tmp_path / "l.nc"
    err = _run([*PYR, *LOAD, "--f-max", "40kPa", "--out", str(out)], capsys)
    first = err.splitlines()[0]
    assert re.search(r"ε = 100 nm, Tabor number μ = 0\.\d+ \(derived from ε", first), first
    ds = xr.load_dataset(out)
    a = ds["branch"].values.astype(str) == "approach"
    p = ds["pressure_Pa"].values[a]
    on = ds["on_grid"].values[a].astype(bool)
    np.testing.assert_allclose(p[on][-1], 40e3, rtol=1e-3)  # the last load asked for is met, not 35 kPa
    np.testing.assert_allclose(np.diff(p[on]), 5e3, rtol=2e-3)
    assert ds["D"].values[a].max() > 20  # past LoadPathSpec's default search range: extended, no d_max given
    for line in err.splitlines():
        if "under-resolved" in line:  # advice in the user's lengths
            assert re.search(r"process zone [\d.]+ nm < 1\.2 dx = [\d.]+ [nµ]m \(dx = [\d.]+ [nµ]m", line), line
            assert re.search(r"resolved for dx <= [\d.]+ [nµ]m", line), line
    assert "pull-off not reached (the retraction ended at f_min = 0 Pa" in err


def test_a_load_not_reached_is_said_in_kpa_and_resume_takes_the_longer_path(tmp_path, capsys):
    out = tmp_path / "r.csv"
    err = _run([*PYR, *LOAD, "--f-max", "20kPa", "--d-max", "12", "--quiet", "--out", str(out)], capsys, 2)
    line = err.strip()
    assert "\n" not in line
    m = re.search(r"load (\d+) kPa \(F = [\d.]+\) is not reached: the highest load reached is ([\d.]+) kPa "
                  r"\(F = [\d.]+\), within d_max = 12 ε \(1\.2 µm\); raise d_max", line)
    assert m, line
    assert float(m.group(2)) < float(m.group(1))
    part = tmp_path / "r.csv.partial.csv"
    n_kept = sum(1 for ln in part.read_text().splitlines() if ln.startswith("approach"))
    assert n_kept > 3
    err = _run([*PYR, *LOAD, "--f-max", "20kPa", "--d-max", "40", "--quiet", "--resume", "--out", str(out)], capsys)
    assert not part.exists()
    fresh = tmp_path / "fresh.csv"
    _run([*PYR, *LOAD, "--f-max", "20kPa", "--d-max", "40", "--quiet", "--out", str(fresh)], capsys)
    a, b = _res(out), _res(fresh)
    np.testing.assert_array_equal(a.table["D"], b.table["D"])
    np.testing.assert_allclose(a.table["F"], b.table["F"], rtol=1e-12)


def test_a_d_path_resumed_longer_keeps_its_approach_and_drops_the_old_retraction(tmp_path, monkeypatch, capsys):
    from tengsim.results import RowStream, partial_path

    base = ["contact", "pyramid", "--N", "0.946", "--cell", "3.78", "--tabor", "0.5", "--dx", "0.3",
            "--d-min", "-1", "--d-step", "0.25", "--quiet"]
    out, full = tmp_path / "x.csv", tmp_path / "full.csv"
    original = RowStream.__call__
    seen = []

    def call(self, row, maps=()):  # Ctrl-C once the short run is two rows into its retraction
        original(self, row, maps)
        seen.append(str(row["branch"]))
        if seen.count("retraction") == 2:
            raise KeyboardInterrupt

    monkeypatch.setattr(RowStream, "__call__", call)
    assert main([*base, "--d-max", "1", "--out", str(out)]) == 130
    monkeypatch.setattr(RowStream, "__call__", original)
    assert "retraction" in partial_path(out).read_text()
    _run([*base, "--d-max", "2", "--out", str(out), "--resume"], capsys)
    _run([*base, "--d-max", "2", "--out", str(full)], capsys)
    got, want = _res(out), _res(full)
    np.testing.assert_array_equal(got.table["D"], want.table["D"])
    np.testing.assert_array_equal(np.asarray(got.table["branch"]).astype(str),
                                  np.asarray(want.table["branch"]).astype(str))
    np.testing.assert_allclose(got.table["F"], want.table["F"], rtol=1e-12)
    # a shorter path is another run: refused by name
    monkeypatch.setattr(RowStream, "__call__", call)
    seen.clear()
    out2 = tmp_path / "y.csv"
    assert main([*base, "--d-max", "1", "--out", str(out2)]) == 130
    monkeypatch.setattr(RowStream, "__call__", original)
    assert main([*base, "--d-max", "0.5", "--out", str(out2), "--resume"]) == 2
    assert "another run (d_max: 1.0 there, 0.5 now)" in capsys.readouterr().err


def test_pull_off_of_a_physical_d_run_in_newtons_and_pascals(tmp_path, capsys):
    err = _run([*PYR[:-4], "--tabor", "0.5", "--dx", "0.5um", "--d-max", "2", "--out", str(tmp_path / "d.csv")],
               capsys)
    assert "(as given; ε derived from it)" in err.splitlines()[0]
    m = re.search(r"pull-off (-[\d.]+) ([nµm]?N) per cell, (-[\d.]+) (k?Pa) nominal \(F = (-[\d.]+)\)", err)
    assert m, err
    res = _res(tmp_path / "d.csv")
    f_n = float(np.min(np.asarray(res.table["F_N"])[np.asarray(res.table["branch"]).astype(str) == "retraction"]))
    scale = {"N": 1, "mN": 1e-3, "µN": 1e-6, "nN": 1e-9}[m.group(2)]
    assert float(m.group(1)) * scale == pytest.approx(f_n, rel=2e-3)


def test_a_negative_pressure_with_its_unit_is_a_value(tmp_path, capsys):
    out = tmp_path / "n.csv"
    _run([*PYR, *LOAD, "--f-min", "-5kPa", "--f-max", "10kPa", "--quiet", "--out", str(out)], capsys)
    res = _res(out)
    p = np.asarray(res.table["pressure_Pa"])[np.asarray(res.table["on_grid"]).astype(bool)]
    assert p.min() == pytest.approx(-5e3, rel=1e-3)


def test_d_max_help_states_the_load_control_default():
    from tengsim.run.keys import common_fields
    from tengsim.continuation import LoadPathSpec

    f = {x.name: x for x in common_fields()}["d_max"]
    assert f.default == 4.0 and f"default {LoadPathSpec.d_max:g}" in f.help


def test_the_path_ends_at_the_largest_load_asked_for(tmp_path, capsys):
    """f_min = 1 kPa, f_step = 5 kPa, f_max = 20 kPa: the loads 1, 6, 11, 16 kPa and then 20 kPa (not 16)."""
    out = tmp_path / "m.csv"
    _run([*PYR, *LOAD, "--f-min", "1kPa", "--f-max", "20kPa", "--quiet", "--out", str(out)], capsys)
    res = _res(out)
    a = np.asarray(res.table["branch"]).astype(str) == "approach"
    on = np.asarray(res.table["on_grid"]).astype(bool) & a
    np.testing.assert_allclose(np.asarray(res.table["pressure_Pa"])[on], [1e3, 6e3, 11e3, 16e3, 20e3], rtol=2e-3)


def test_refinement_stop_message_in_the_runs_lengths(tmp_path, capsys):
    """--resolve auto stopped by max_pixels in a physical run names dx in nm/µm, not X units (issue 29)."""
    out = tmp_path / "r.csv"
    argv = ["contact", "sphere", "--radius", "1um", "--pitch", "2um", "--E-star", "1MPa", "--W", "50mJ/m2",
            "--tabor", "1", "--dx", "100nm", "--d-min", "-1", "--d-max", "0.5", "--resolve", "auto",
            "--max-pixels", "1000", "--out", str(out)]
    assert main(argv) == 0
    err = capsys.readouterr().err
    line = next(ln for ln in err.splitlines() if "refinement stopped by max_pixels" in ln)
    assert "at dx = 95.24 nm (21×21; next 33×33)" in line
    assert " nm needed" in line or " µm needed" in line or "nm needed" in line
