"""Results written as they are computed: a killed ``tengsim contact`` keeps every finished equilibrium
in OUT.partial.csv (marked incomplete), and ``--resume`` completes it into the uninterrupted run's file.

The kill tests run the CLI in a subprocess with the test plugin tests/_stall_plugin.py, whose observer
blocks before row k+1 while TENGSIM_TEST_STALL_AFTER=k is set: the test waits for k rows in the partial
file, then sends SIGKILL, so the point of the kill is known and no timing is assumed (the polling has
only a generous hang guard).
"""
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from tengsim.cli.main import main
from tengsim.results.read import incomplete_note, load_result, read_partial
from tengsim.results import RowStream, partial_path

TESTS = Path(__file__).parent
RUN = ["pyramid", "--N", "0.946", "--cell", "3.78", "--tabor", "0.5", "--dx", "0.2", "--d-min", "-1",
       "--d-max", "2", "--d-step", "0.1", "--observers", "test_stall", "--quiet"]
HANG_GUARD_S = 120


def _env(stall=None):
    env = dict(os.environ, TENGSIM_PLUGINS="_stall_plugin", OPENBLAS_NUM_THREADS="1",
               PYTHONPATH=os.pathsep.join([str(TESTS), os.environ.get("PYTHONPATH", "")]))
    env.pop("TENGSIM_TEST_STALL_AFTER", None)
    if stall:
        env["TENGSIM_TEST_STALL_AFTER"] = str(stall)
    return env


def _cli(args, stall=None, cwd=None):
    return subprocess.run([sys.executable, "-m", "tengsim.cli.main", *args], env=_env(stall), cwd=cwd,
                          capture_output=True, text=True, timeout=HANG_GUARD_S)


def _data_lines(path):
    try:
        return [l for l in path.read_text().splitlines(keepends=True) if not l.startswith("#")]
    except FileNotFoundError:
        return []


def _kill_after(args, k, part):
    """Start the CLI stalling after k rows, wait until the partial file holds them, SIGKILL it."""
    proc = subprocess.Popen([sys.executable, "-m", "tengsim.cli.main", *args], env=_env(k),
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    try:
        t0 = time.monotonic()
        while len(_data_lines(part)) < k + 1:  # the names line and k rows
            assert proc.poll() is None, f"the run ended before it was killed: {proc.stderr.read()}"
            assert time.monotonic() - t0 < HANG_GUARD_S, "no rows appeared (hang guard)"
            time.sleep(0.02)
    finally:
        proc.send_signal(signal.SIGKILL)
        proc.wait(timeout=HANG_GUARD_S)
    assert proc.returncode == -signal.SIGKILL


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    """The uninterrupted run, as NetCDF (rows and maps)."""
    out = tmp_path_factory.mktemp("ref") / "ref.nc"
    r = _cli(["contact", *RUN, "--maps", "0,1", "--out", str(out)])
    assert r.returncode == 0, r.stderr
    return load_result(out)[1]


def _assert_same_rows(res, ref):
    """Every column of the reference equal: strings exactly, D exactly, the rest to solver tolerance
    (rtol 1e-6 of the value, atol 1e-9; they agree bitwise on one machine); 'seconds' is wall time."""
    assert len(res.table["D"]) == len(ref.table["D"])
    for k, v in ref.table.items():
        if k in ("seconds",):
            continue
        a = np.asarray(res.table[k])
        if a.dtype.kind in "USb" or k == "D":
            assert np.array_equal(a, v), k
        else:
            assert np.allclose(a.astype(float), v.astype(float), rtol=1e-6, atol=1e-9, equal_nan=True), k


def test_sigkilled_contact_csv_leaves_readable_partial_and_resumes(tmp_path, reference):
    out = tmp_path / "run.csv"
    part = partial_path(out)
    args = ["contact", *RUN, "--out", str(out)]
    _kill_after(args, 15, part)
    assert not out.exists()
    kind, res = load_result(part)  # readable: every finished equilibrium, marked incomplete
    assert kind == "contact" and len(res.table["D"]) == 15
    assert res.params["complete"] is False and "15 finished equilibria" in incomplete_note(kind, res)
    _assert_same_rows(res, type(res)(table={k: v[:15] for k, v in reference.table.items()}, grid=None))
    before = part.read_bytes()
    # a plain rerun would overwrite the finished rows: refused, one line, nothing touched
    r = _cli(args)
    assert r.returncode == 2 and r.stderr.count("\n") == 1 and "--resume" in r.stderr
    assert part.read_bytes() == before and not out.exists()
    r = _cli(args + ["--resume"])
    assert r.returncode == 0, r.stderr
    assert not part.exists()  # the whole result saved, the partial file goes
    _, done = load_result(out)
    assert "complete" not in done.params
    _assert_same_rows(done, reference)


@pytest.mark.slow  # ~6 s: three more CLI processes (the CSV test above covers the kill in the default suite)
def test_sigkilled_run_config_netcdf_keeps_maps_and_resumes(tmp_path, reference):
    """`tengsim run CONFIG --resume` with a NetCDF output: rows in OUT.partial.csv, maps beside it."""
    out = tmp_path / "run.nc"
    part = partial_path(out)
    cfg = tmp_path / "c.toml"
    cfg.write_text('[contact]\nshape = "pyramid"\nN = 0.946\ncell = 3.78\ntabor = 0.5\ndx = 0.2\n'
                   'd_min = -1\nd_max = 2\nd_step = 0.1\nobservers = ["test_stall"]\nmaps_at = [0, 1]\n'
                   f'out = "{out}"\n')
    _kill_after(["run", str(cfg), "--quiet"], 25, part)  # past the approach's map at D = 1 (row 21)
    res = load_result(part)[1]
    assert len(res.table["D"]) == 25
    assert [(m["branch"], m["D"]) for m in res.maps] == [("approach", 0.0), ("approach", 1.0)]
    r = _cli(["run", str(cfg), "--quiet", "--resume"])
    assert r.returncode == 0, r.stderr
    assert not part.exists() and not Path(str(out) + ".partial.maps.npz").exists()
    done = load_result(out)[1]
    _assert_same_rows(done, reference)
    assert len(done.maps) == len(reference.maps) == 4
    for m, n in zip(done.maps, reference.maps):
        assert (m["branch"], m["D"]) == (n["branch"], n["D"]) and np.allclose(m["P"], n["P"], rtol=1e-6, atol=1e-9)


# ---- in process: refusals and edge cases (no plugin: interrupted by a patched stream) --------------
FAST = ["contact", "pyramid", "--N", "0.946", "--cell", "3.78", "--tabor", "0.5", "--dx", "0.3",
        "--d-min", "-1", "--d-max", "1", "--d-step", "0.25", "--quiet"]


@pytest.fixture
def interrupted(tmp_path, monkeypatch, capsys):
    """A partial file of 6 rows, left by a run interrupted with Ctrl-C (KeyboardInterrupt after row 6)."""
    out = tmp_path / "r.csv"
    original = RowStream.__call__

    def call(self, row, maps=()):
        original(self, row, maps)
        if self.n == 6:
            raise KeyboardInterrupt

    monkeypatch.setattr(RowStream, "__call__", call)
    assert main(FAST + ["--out", str(out)]) == 130
    err = capsys.readouterr().err
    assert err == f"tengsim: interrupted; 6 finished equilibria kept in {partial_path(out)} (continue with --resume)\n"
    monkeypatch.setattr(RowStream, "__call__", original)
    return out


def test_resume_refuses_other_settings_and_edited_rows(tmp_path, interrupted, capsys):
    out, part = interrupted, partial_path(interrupted)
    before = part.read_bytes()
    assert main([*FAST[:7], "0.6", *FAST[8:], "--out", str(out), "--resume"]) == 2  # --tabor 0.6
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "another run (tabor: 0.5 there, 0.6 now)" in err
    assert part.read_bytes() == before and not out.exists()
    # a row edited by hand: found when that row is solved again, the file left as it was
    text = before.decode().splitlines(keepends=True)
    names = [l for l in text if not l.startswith("#")][0].rstrip("\n").split(",")
    i = len(text) - 3  # the 4th of the 6 rows
    fields = text[i].rstrip("\n").split(",")
    fields[names.index("F")] = repr(float(fields[names.index("F")]) + 1e-3)
    text[i] = ",".join(fields) + "\n"
    part.write_text("".join(text))
    edited = part.read_bytes()
    assert main(FAST + ["--out", str(out), "--resume"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "row 4 of" in err and "is not what this run gives" in err
    assert part.read_bytes() == edited and not out.exists()


def test_resume_refusals_without_a_partial_file(tmp_path, capsys):
    out = tmp_path / "r.csv"
    assert main(FAST + ["--out", str(out), "--resume"]) == 2
    assert "no partial file" in capsys.readouterr().err and not list(tmp_path.iterdir())
    partial_path(out).write_text("branch,D\n")  # not written by tengsim
    assert main(FAST + ["--out", str(out), "--resume"]) == 2
    assert "not a partial file written by tengsim" in capsys.readouterr().err
    cfg = tmp_path / "d.toml"
    cfg.write_text('[device]\n')
    assert main(["run", str(cfg), "--resume"]) == 2
    assert "--resume continues a [contact] run" in capsys.readouterr().err


def test_plot_draws_a_partial_file_and_says_it_is_incomplete(tmp_path, interrupted, capsys):
    assert main(["plot", str(partial_path(interrupted)), "--out", str(tmp_path / "p.png")]) == 0
    assert "incomplete run: 6 finished equilibria" in capsys.readouterr().err
    assert (tmp_path / "p.png").exists()


def test_torn_last_line_is_left_out_and_resume_completes(tmp_path, interrupted, capsys):
    out, part = interrupted, partial_path(interrupted)
    with open(part, "a") as fh:
        fh.write("approach,0.5,-0.12")  # a row half written when the run was killed
    kind, res = load_result(part)
    assert len(res.table["D"]) == 6 and incomplete_note(kind, res)
    assert len(read_partial(part)[1]["D"]) == 6
    assert main(FAST + ["--out", str(out), "--resume"]) == 0
    assert not part.exists()
    ref = tmp_path / "ref.csv"
    assert main(FAST + ["--out", str(ref)]) == 0
    _assert_same_rows(load_result(out)[1], load_result(ref)[1])


def test_stream_writes_nothing_before_the_first_row(tmp_path):
    s = RowStream(tmp_path / "r.csv")
    s.begin({"tabor": 0.5})
    s.close()
    assert not list(tmp_path.iterdir())
