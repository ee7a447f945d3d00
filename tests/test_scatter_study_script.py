"""scripts/scatter_study.py's convergence runs (issue 15): option checks, the run plan, the append/skip
bookkeeping and the table builder (no physics claims: those are tests/test_arrays.py's)."""
import csv
import importlib.util
from pathlib import Path

import pytest

PATH = Path(__file__).parent.parent / "scripts" / "scatter_study.py"


@pytest.fixture(scope="module")
def mod():
    spec = importlib.util.spec_from_file_location("_scatter_study_under_test", PATH)
    m = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(m)
    return m


@pytest.mark.parametrize("argv, msg", [
    (["--dx", "0"], "--dx must be in (0, 1], got 0"),
    (["--dx", "nan"], "--dx must be in (0, 1], got nan"),
    (["--K", "4", "0"], "--K must be >= 1, got 0"),
    (["--seeds", "-1"], "--seeds must be >= 0, got -1"),
    (["--scatter", "5", "100"], "--scatter must be in [0, 100) %, got 100"),
    (["--quick", "--K", "2"], "--quick/--waviness cannot be combined"),
])
def test_bad_option_one_line_exit_2_nothing_written(mod, tmp_path, capsys, argv, msg):
    out = tmp_path / "o"
    assert mod.main(argv + ["--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert msg in err and err.count("\n") == 1 and "Traceback" not in err
    assert not out.exists()


def test_plan_scatter_in_percent_and_flat_array_once(mod):
    args = mod.argparse.Namespace(dx=None, K=[2, 8], seeds=[3, 4], scatter=[0, 10], quick=False, waviness=False)
    assert mod.convergence_plan(args) == [(0.2, 2, 0.0, 3), (0.2, 2, 0.1, 3), (0.2, 2, 0.1, 4),
                                          (0.2, 8, 0.0, 3), (0.2, 8, 0.1, 3), (0.2, 8, 0.1, 4)]


def _read(p):
    with open(p, newline="") as fh:
        return list(csv.DictReader(fh))


def test_runs_append_skip_and_tables(mod, tmp_path, capsys):
    out = tmp_path / "o"
    common = ["--out", str(out), "--K", "2", "--seeds", "0", "--scatter", "0", "--name", "c"]
    assert mod.main(common + ["--dx", "0.4"]) == 0
    runs1 = _read(out / "c_runs.csv")
    assert mod.main(common + ["--dx", "0.4"]) == 0  # already there: skipped, nothing changes
    assert "already in c_runs.csv, skipped" in capsys.readouterr().err
    assert _read(out / "c_runs.csv") == runs1
    md = out / "c.md"
    md.write_text(md.read_text() + "\n## Findings\n\nhand-written\n")
    assert mod.main(common + ["--dx", "0.3"]) == 0
    runs, rows = _read(out / "c_runs.csv"), _read(out / "c.csv")
    assert [(r["dx"], r["K"], r["scatter"], r["seed"]) for r in runs] == [("0.3", "2", "0.0", "0"),
                                                                       ("0.4", "2", "0.0", "0")]
    assert all(float(r["seconds"]) > 0 and r["n_unconverged"] == "0" for r in runs)
    assert len(rows) == 2 * len(mod.TARGETS_KPA)
    text = md.read_text()
    assert text.endswith("## Findings\n\nhand-written\n")  # the hand-written section survives a rewrite
    a = {(r["dx"], float(r["P_target_kPa"])): float(r["A_S_greenwood"]) for r in rows}
    fine, coarse = a["0.3", 150.0] / a["0.3", 10.0], a["0.4", 150.0] / a["0.4", 10.0]
    assert "## Grid: the same K, s, seed at each dx" in text
    line = {d: next(ln for ln in text.splitlines() if ln.startswith(f"| 2 | 0% | 0 | {d} | ")) for d in ("0.3", "0.4")}
    assert line["0.3"].endswith(f"| {fine:.3f} | +0.000 |")
    assert line["0.4"].endswith(f"| {coarse:.3f} | {coarse - fine:+.3f} |")
    assert f"| {a['0.4', 50.0]:.3f} | {a['0.4', 100.0]:.3f} |" in line["0.4"]
