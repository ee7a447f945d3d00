"""The fourteen causes of issue 30, one group of tests each (``test_cNN_...``): a hostile input gets one line,
exit 2, nothing written (or the finished part kept), never a crash, a hang or a destroyed file.

The fault table with these tests is docs/faults.md.  A full disk is a real 64 KiB tmpfs where ``mount`` is
permitted (root in a container), else the test is skipped and the monkeypatched one still runs.
"""
import errno
import os
import shutil
import socket
import subprocess
import sys
import textwrap
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from tengsim import plugins
from tengsim.cli.main import main

BASE = ["contact", "pyramid", "--N", "0.946", "--cell", "3.78", "--dx", "0.3", "--d-min", "0", "--d-max", "0.5",
        "--d-step", "0.5", "--quiet"]
TOPO = ["--physical-size", "2um,2um", "--E-star", "1GPa", "--W", "50mJ/m2", "--tabor", "1", "--d-min", "-1",
        "--d-max", "1", "--quiet"]
STUDY = """
[base.contact]
shape = "pyramid"
N = 0.946
cell = 3.78
tabor = 0.5
dx = 0.3
d_min = -0.5
d_max = 0.5
d_step = 0.5
"""
SRC = str(Path(__import__("tengsim").__file__).resolve().parents[1])  # the tengsim under test


def refused(capsys, argv, *, where=None, keep=()):
    """Run ``argv`` in process: exit 2, one line 'tengsim: error: ...', no traceback, and (``where``) nothing
    new in that folder but the names in ``keep``.  Returns the line."""
    before = set(os.listdir(where)) if where is not None else set()
    rc = main(argv)
    err = capsys.readouterr().err
    lines = err.strip().splitlines()
    assert rc == 2, (argv[:6], err)
    assert len(lines) == 1 and lines[0].startswith("tengsim: error:"), err
    assert "Traceback" not in err
    if where is not None:
        assert set(os.listdir(where)) - before <= set(keep), sorted(set(os.listdir(where)) - before)
    return lines[0]


def _env(**extra):
    return {**os.environ, "PYTHONPATH": SRC, "OPENBLAS_NUM_THREADS": "1", "MPLBACKEND": "Agg", **extra}


@pytest.fixture
def tiny_fs(tmp_path):
    """A 64 KiB tmpfs (a real full disk), unmounted afterwards; skipped where mount is not permitted."""
    mnt = tmp_path / "full"
    mnt.mkdir()
    if shutil.which("mount") is None or subprocess.run(["mount", "-t", "tmpfs", "-o", "size=64k", "tmpfs", str(mnt)],
                                                       capture_output=True).returncode != 0:
        pytest.skip("mount of a tmpfs is not permitted here (the monkeypatched ENOSPC test still runs)")
    try:
        yield mnt
    finally:
        subprocess.run(["umount", "-l", str(mnt)], capture_output=True)


# ---- 1: a full disk during a sweep ---------------------------------------------------------------
def test_c01_full_disk_during_sweep(tiny_fs, tmp_path):
    """A point file that does not fit: was exit 139 (segfault in h5py), 36 lines and a stale .part."""
    study = tmp_path / "s.toml"
    study.write_text(STUDY + '[axes]\n"contact.N" = [0.946, 1.5]\n')
    p = subprocess.run([sys.executable, "-m", "tengsim.cli.main", "sweep", str(study), "--out", str(tiny_fs / "st"),
                        "--workers", "1", "--quiet"], capture_output=True, text=True, env=_env(), timeout=120)
    lines = p.stderr.strip().splitlines()
    assert p.returncode == 2, p.stderr[-2000:]
    assert lines[0].startswith("tengsim: error: ") and "No space left on device" in lines[0], p.stderr[-2000:]
    assert str(tiny_fs / "st" / "points") in lines[0]  # the path is named
    assert "Traceback" not in lines[0] and not any(l.startswith("tengsim:") for l in lines[1:])
    assert not list((tiny_fs / "st").rglob("*.part"))


def test_c01_full_disk_on_write_names_the_path_monkeypatched(tmp_path, capsys, monkeypatch):
    """ENOSPC as the data reach the disk (fsync), in process: one line naming the output, nothing left."""
    from tengsim import io

    def full(path, flags=0):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(io, "_fsync", full)
    out = tmp_path / "r.nc"
    line = refused(capsys, [*BASE, "--tabor", "0.5", "--out", str(out)])
    # the first write of the run is its partial file (rows as they finish): that path is named
    assert f"{out}.partial.csv: No space left on device" in line
    assert list(tmp_path.iterdir()) == []
    import xarray as xr

    with pytest.raises(OSError) as e:
        io.write_dataset(xr.Dataset({"F": ("D", np.arange(3.0))}), out)
    assert e.value.errno == errno.ENOSPC and e.value.filename == str(out)
    with pytest.raises(OSError) as e:
        io.write_bytes(tmp_path / "x.bin", b"abc")
    assert e.value.errno == errno.ENOSPC and e.value.filename == str(tmp_path / "x.bin")
    assert list(tmp_path.iterdir()) == []


# ---- 2: random bytes as a topography -------------------------------------------------------------
def test_c02_random_bytes_are_not_a_topography(tmp_path, capsys):
    f = tmp_path / "noise.dat"
    f.write_bytes(np.random.default_rng(1).bytes(8192))  # 2·64² bytes: what the HGT reader takes
    line = refused(capsys, ["contact", "topography", str(f), *TOPO, "--out", str(tmp_path / "o.csv")],
                   where=tmp_path)
    assert "not a topography" in line and "'hgt'" in line


def test_c02_a_two_row_matrix_is_refused_with_the_text_readers_reason(tmp_path, capsys):
    f = tmp_path / "m.txt"
    np.savetxt(f, np.random.default_rng(0).normal(size=(2, 16)))
    line = refused(capsys, ["contact", "topography", str(f), *TOPO, "--out", str(tmp_path / "o.csv")],
                   where=tmp_path)
    assert "as a text matrix" in line and "two rows" in line


def test_c02_the_reader_used_is_named(tmp_path):
    from tengsim.shapes.topography import read

    f = tmp_path / "ok.txt"
    np.savetxt(f, 1e-8 * np.random.default_rng(0).normal(size=(16, 16)))
    assert read(f, physical_size=(2e-6, 2e-6)).reader == "asc"


# ---- 3: --out equal to the input -----------------------------------------------------------------
def test_c03_out_equal_to_the_input_is_refused_and_the_input_kept(tmp_path, capsys, monkeypatch):
    f = tmp_path / "g.csv"
    np.savetxt(f, 1e-8 * np.random.default_rng(0).normal(size=(16, 16)))
    data = f.read_bytes()
    monkeypatch.chdir(tmp_path)
    for out in ("g.csv", str(f), "./g.csv"):
        line = refused(capsys, ["contact", "topography", "g.csv", *TOPO, "--out", out], where=tmp_path)
        assert "is also an input" in line
        assert f.read_bytes() == data
    cfg = tmp_path / "run.toml"
    cfg.write_text('[contact]\nshape = "topography"\nfile = "g.csv"\nphysical_size = "2um,2um"\nE_star = "1GPa"\n'
                   'W = "50mJ/m2"\ntabor = 1\nout = "g.csv"\n')
    assert "is also an input" in refused(capsys, ["run", str(cfg), "--quiet"])
    assert f.read_bytes() == data


# ---- 4 and 14: plugins ---------------------------------------------------------------------------
@pytest.fixture
def plugin_dir(tmp_path, monkeypatch):
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setattr(plugins, "_LOADED", set())
    made = []

    def make(body):
        name = f"tengsim_hostile_plugin_{len(made)}_{tmp_path.name.replace('-', '_')}"
        (tmp_path / f"{name}.py").write_text(textwrap.dedent(body))
        made.append(name)
        monkeypatch.setenv("TENGSIM_PLUGINS", name)
        return name

    yield make
    for name in made:
        sys.modules.pop(name, None)


def test_c04_a_plugin_alias_may_not_replace_a_built_in(plugin_dir, capsys):
    from tengsim.registry import SHAPES
    from tengsim.shapes.pyramid import Pyramid

    name = plugin_dir("""
        from tengsim.registry import SHAPES
        from tengsim.shapes.pyramid import Pyramid
        SHAPES.register("my_pyramid", Pyramid, aliases=("pyramid",))
    """)
    line = refused(capsys, ["contact", "--help"])
    assert name in line and "alias 'pyramid'" in line
    assert SHAPES.get("pyramid") is Pyramid and "my_pyramid" not in SHAPES


def test_c04_alias_clash_in_the_registry_changes_nothing():
    from tengsim.errors import TengsimError
    from tengsim.registry import Registry

    r = Registry("thing")
    r.register("a", 1, aliases=("x",))
    with pytest.raises(TengsimError, match="alias 'x' is already an alias of 'a'"):
        r.register("b", 2, aliases=("x",))
    with pytest.raises(TengsimError, match="alias 'A' is already the thing 'a'"):
        r.register("c", 3, aliases=("A",))
    assert r.names() == ("a",) or list(r.names()) == ["a"]
    assert r.get("x") == 1


def test_c14_a_plugin_raising_on_import_is_named(plugin_dir, capsys):
    name = plugin_dir("raise RuntimeError('boom at import')\n")
    line = refused(capsys, ["contact", "--help"])
    assert name in line and "RuntimeError: boom at import" in line


def test_c14_a_plugin_calling_sys_exit_is_named(plugin_dir, capsys):
    name = plugin_dir("import sys\nsys.exit(3)\n")
    line = refused(capsys, ["contact", "--help"])
    assert name in line and "sys.exit(3)" in line


# ---- 5: bad input reported as an internal error --------------------------------------------------
def _study(tmp_path, text):
    f = tmp_path / "s.toml"
    f.write_text(STUDY + text)
    return f


@pytest.mark.parametrize("text, words", [
    ('tol = "=' + "+".join(["1"] * 100_000) + '"\n[axes]\n"contact.N" = [0.946]\n', "expression"),
    ('tol = "=1' + "0" * 400 + '"\n[axes]\n"contact.N" = [0.946]\n', "out of range"),
    ('tol = "=1e-8*k"\n[base.var]\nk = 1\n[axes]\n"var.k" = ["abc"]\n', "var.k"),
    ('[axes]\n"contact.N" = { start = 0.9, stop = 1.0, num = 1000000000 }\n', "at most 100000"),
    ('[study]\nsampling = "lhs"\nn = 1000000000\n[axes]\n"contact.N" = { start = 0.9, stop = 1.0 }\n',
     "at most 100000"),
    ('[study]\nsampling = "lhs"\nn = 4\nseed = 1000000000000000000000000000000\n'
     '[axes]\n"contact.N" = { start = 0.9, stop = 1.0 }\n', "seed"),
])
def test_c05_bad_study_values_are_exit_2_not_internal_errors(tmp_path, capsys, text, words):
    f = _study(tmp_path, text)
    out = tmp_path / "out"
    t0 = time.perf_counter()
    line = refused(capsys, ["sweep", str(f), "--out", str(out), "--workers", "1"], where=tmp_path)
    assert time.perf_counter() - t0 < 10
    assert words in line, line
    assert not out.exists()


@pytest.mark.parametrize("extra, words", [
    (["--dx", "1e-320"], "dx"),
    (["--cell", "1e308"], "cell"),
    (["--cell", "1e50"], "pixels per side"),
    (["--tabor", "1" + "0" * 400], "tabor"),
])
def test_c05_extreme_numbers_are_exit_2(tmp_path, capsys, extra, words):
    argv = [*BASE, "--tabor", "0.5", *extra, "--out", str(tmp_path / "o.csv")]
    assert words in refused(capsys, argv, where=tmp_path)


def test_c05_seed_and_plugin_path_and_text_in_a_csv(tmp_path, capsys, monkeypatch):
    rough = ["contact", "rough", "--cell", "8", "--rms-height", "0.5", "--boundary", "periodic", "--tabor", "1",
             "--dx", "1", "--d-min", "0", "--d-max", "0.5", "--d-step", "0.5", "--quiet"]
    assert "seed" in refused(capsys, [*rough, "--seed", "1e30", "--out", str(tmp_path / "o.csv")], where=tmp_path)
    # a result whose D holds text: tengsim plot names it (was a TypeError inside matplotlib, exit 70)
    res = tmp_path / "r.csv"
    assert main([*BASE, "--tabor", "0.5", "--out", str(res)]) == 0
    lines = res.read_text().splitlines()
    i = next(k for k, l in enumerate(lines) if not l.startswith("#"))
    j = lines[i].split(",").index("D")
    row = lines[i + 1].split(",")
    row[j] = "abc"
    lines[i + 1] = ",".join(row)
    res.write_text("\n".join(lines) + "\n")
    assert "column 'D' must hold numbers" in refused(capsys, ["plot", str(res), "--out", str(tmp_path / "p.png")],
                                                     where=tmp_path)
    monkeypatch.setattr(plugins, "_LOADED", set())
    monkeypatch.setenv("TENGSIM_PLUGINS", "../../x")
    assert "is not a module name" in refused(capsys, ["contact", "--help"])


# ---- 6: unbounded work ---------------------------------------------------------------------------
def test_c06_huge_axes_and_workers_are_refused_at_once(tmp_path, capsys):
    big = "[" + ", ".join(f"{0.9 + i * 1e-6:.7f}" for i in range(100_000)) + "]"
    f = _study(tmp_path, f'[axes]\n"contact.N" = {big}\n"contact.tabor" = {big.replace("0.9", "0.4")}\n')
    t0 = time.perf_counter()
    line = refused(capsys, ["sweep", str(f), "--out", str(tmp_path / "o")], where=tmp_path)
    assert time.perf_counter() - t0 < 20 and "1e+10 points" in line
    f = _study(tmp_path, '[axes]\n"contact.N" = [0.946]\n')
    t0 = time.perf_counter()
    line = refused(capsys, ["sweep", str(f), "--out", str(tmp_path / "o"), "--workers", "100000"], where=tmp_path)
    assert time.perf_counter() - t0 < 5 and "--workers 100000" in line


def test_c06_sixteen_thousand_unknown_keys_cost_linear_time_and_a_short_line(tmp_path, capsys):
    cfg = tmp_path / "run.toml"
    keys = "".join(f"k{i} = 1\n" for i in range(16_000))
    cfg.write_text('[contact]\nshape = "pyramid"\nN = 0.946\ncell = 3.78\ntabor = 0.5\nout = "o.csv"\n' + keys)
    t0 = time.perf_counter()
    line = refused(capsys, ["run", str(cfg), "--quiet"], where=tmp_path)
    assert time.perf_counter() - t0 < 5
    assert "'k0', 'k1', 'k2', 'k3', 'k4' and 15995 more" in line and len(line) < 1500


def _server(greeting: bytes | None):
    """A TCP server that accepts connections and sends ``greeting`` (None: says nothing); returns its port."""
    srv = socket.socket()
    srv.bind(("127.0.0.1", 0))
    srv.listen()
    conns = []

    def serve():
        while True:
            try:
                c, _ = srv.accept()
            except OSError:
                return
            conns.append(c)
            if greeting is not None:
                c.sendall(greeting)

    threading.Thread(target=serve, daemon=True).start()
    return srv, srv.getsockname()[1]


@pytest.mark.parametrize("greeting, words", [(None, "no Dask greeting within 0.5 s"),
                                             (b"HTTP/1.1 400 Bad Request\r\n\r\n", "not a Dask scheduler")])
def test_c06_a_scheduler_that_is_not_dask_is_refused_in_its_timeout(tmp_path, capsys, monkeypatch, greeting, words):
    from tengsim.study import runner

    monkeypatch.setattr(runner, "CONNECT_TIMEOUT_S", 0.5)
    srv, port = _server(greeting)
    try:
        f = _study(tmp_path, '[axes]\n"contact.N" = [0.946]\n')
        t0 = time.perf_counter()
        line = refused(capsys, ["sweep", str(f), "--out", str(tmp_path / "o"), "--scheduler",
                                f"tcp://127.0.0.1:{port}"], where=tmp_path)
        assert time.perf_counter() - t0 < 5
        assert words in line and f"127.0.0.1:{port}" in line
    finally:
        srv.close()


# ---- 7: implausible surfaces ---------------------------------------------------------------------
@pytest.mark.parametrize("scale", [50.0, 5e292])
def test_c07_heights_far_beyond_the_scan_are_refused_with_unit_advice(tmp_path, capsys, scale):
    f = tmp_path / "bump.txt"
    x = np.linspace(-2, 2, 32)
    np.savetxt(f, scale * np.exp(-x[:, None] ** 2 - x[None] ** 2))
    line = refused(capsys, ["contact", "topography", str(f), *TOPO, "--out", str(tmp_path / "o.csv")],
                   where=tmp_path)
    assert "implausible" in line and "--unit nm" in line and "'asc'" in line


def test_c07_a_bump_in_nm_with_its_unit_runs(tmp_path, capsys):
    f = tmp_path / "bump.txt"
    x = np.linspace(-2, 2, 24)
    np.savetxt(f, 50 * np.exp(-x[:, None] ** 2 - x[None] ** 2))
    assert main(["contact", "topography", str(f), *TOPO, "--unit", "nm", "--d-step", "1",
                 "--out", str(tmp_path / "o.csv")]) == 0, capsys.readouterr().err


@pytest.mark.parametrize("slope", ["1e300", "50"])
def test_c07_an_absurd_rms_slope_is_refused(tmp_path, capsys, slope):
    argv = ["contact", "rough", "--cell", "8", "--rms-slope", slope, "--boundary", "periodic", "--tabor", "1",
            "--dx", "1", "--d-min", "0", "--d-max", "0.5", "--d-step", "0.5", "--quiet", "--out", str(tmp_path / "o.csv")]
    assert "rms_slope" in refused(capsys, argv, where=tmp_path)


# ---- 8: --resolve auto keeps its finished grids --------------------------------------------------
RESOLVE = ["contact", "sphere", "--radius", "5", "--cell", "4", "--tabor", "1", "--d-min", "-0.6", "--d-max", "0.6",
           "--d-step", "0.1", "--dx", "0.4", "--resolve", "auto", "--quiet"]


def test_c08_a_refinement_killed_after_two_grids_keeps_them_and_resumes(tmp_path, capsys, monkeypatch):
    from tengsim.run import simulate as contact
    from tengsim.results.read import load_result
    from tengsim.results import checkpoint_path

    out = tmp_path / "r.csv"
    real = contact._one_grid
    grids = []

    def killed_at_third(*a, **k):
        grids.append(a[0].grid.nx)
        if len(grids) == 3:
            raise KeyboardInterrupt
        return real(*a, **k)

    monkeypatch.setattr(contact, "_one_grid", killed_at_third)
    assert main([*RESOLVE, "--out", str(out)]) == 130
    assert "finished grids are kept" in capsys.readouterr().err
    assert checkpoint_path(out).is_file() and not out.exists()
    import json

    kept = json.loads(load_result(checkpoint_path(out))[1].params["resolve_checkpoint"])
    assert len(kept["levels"]) == 2  # both finished grids, with their observables
    # without --resume the kept grids are not overwritten
    assert "--resume" in refused(capsys, [*RESOLVE, "--out", str(out)])
    grids.clear()
    monkeypatch.setattr(contact, "_one_grid", lambda *a, **k: (grids.append(a[0].grid.nx), real(*a, **k))[1])
    assert main([*RESOLVE, "--out", str(out), "--resume"]) == 0
    assert len(grids) == 1  # only the third grid is computed
    assert not checkpoint_path(out).exists()
    ref = tmp_path / "ref.csv"
    assert main([*RESOLVE, "--out", str(ref)]) == 0
    a, b = load_result(out)[1], load_result(ref)[1]
    np.testing.assert_array_equal(a.table["F"], b.table["F"])
    assert a.params["resolve_grids"] == b.params["resolve_grids"] and len(a.params["resolve_grids"]) == 3


# ---- 9: [objective] subject_to -------------------------------------------------------------------
@pytest.mark.parametrize("bound", ['min = "abc"', "min = 2.0, max = 1.0", 'max = "nan"'])
def test_c09_subject_to_bounds_are_checked_before_any_point(tmp_path, capsys, bound):
    f = _study(tmp_path, '[axes]\n"contact.N" = { start = 0.9, stop = 1.0 }\n[objective]\nminimize = "pull_off_F"\n'
                         f"subject_to = {{ hysteresis_J_m2 = {{ {bound} }} }}\n")
    t0 = time.perf_counter()
    line = refused(capsys, ["optimize", str(f), "--out", str(tmp_path / "o"), "--workers", "1"], where=tmp_path)
    assert "subject_to.hysteresis_J_m2" in line and time.perf_counter() - t0 < 10


# ---- 10: underscores in numbers ------------------------------------------------------------------
@pytest.mark.parametrize("key, value", [("--tabor", "0_5"), ("--N", "0_946"), ("--dx", "0_3")])
def test_c10_an_underscore_in_a_number_is_refused(tmp_path, capsys, key, value):
    argv = [*BASE, "--tabor", "0.5", key, value, "--out", str(tmp_path / "o.csv")]
    assert "no underscores in numbers" in refused(capsys, argv, where=tmp_path)


def test_c10_underscores_are_refused_in_toml_strings_and_quantities(tmp_path, capsys):
    from tengsim.errors import TengsimError
    from tengsim.units import parse_quantity, read_number

    for bad in ("0_5", "1_000", "0_5MPa"):
        with pytest.raises(TengsimError, match="no underscores"):
            parse_quantity(bad)
    assert read_number("0.5") == 0.5 and parse_quantity("0.59MPa") == 590000.0
    cfg = tmp_path / "run.toml"
    cfg.write_text('[contact]\nshape = "pyramid"\nN = "0_946"\ncell = 3.78\ntabor = 0.5\nout = "o.csv"\n')
    assert "no underscores" in refused(capsys, ["run", str(cfg), "--quiet"], where=tmp_path)


# ---- 11: late failures ---------------------------------------------------------------------------
def test_c11_reproduce_refuses_a_file_as_out_before_computing(tmp_path, capsys):
    f = tmp_path / "taken"
    f.write_text("mine\n")
    t0 = time.perf_counter()
    line = refused(capsys, ["reproduce", "--quick", "--quiet", "--out", str(f)], where=tmp_path)
    assert time.perf_counter() - t0 < 5 and "is a file, not a folder" in line
    assert f.read_text() == "mine\n"


# ---- 12: two sweeps on one --out -----------------------------------------------------------------
def test_c12_a_second_sweep_on_a_held_folder_is_refused(tmp_path, study_client):
    from tengsim.errors import TengsimError
    from tengsim.study import parse_study, run_study
    from tengsim.study.layout import StudyDir

    import tomllib

    study = parse_study(tomllib.loads(STUDY + '[axes]\n"contact.N" = [0.946]\n'), source="t")
    sd = StudyDir(tmp_path / "out")
    with sd.lock():
        with pytest.raises(TengsimError, match=rf"in use by another sweep or optimisation \(pid {os.getpid()}\)"):
            run_study(study, sd.root, client=study_client, quiet=True)
    assert not sd.points.exists() and not sd.spec.exists()  # nothing computed twice, nothing written
    s = run_study(study, sd.root, client=study_client, quiet=True)  # free again: it runs
    assert s["ok"] + s.get("under_resolved", 0) == 1


def test_c12_a_sweep_and_a_design_on_one_folder_refuse_each_other(tmp_path):
    """The one output-folder lock (tengsim.outfolder) is held by a sweep too: a design, calibration or
    reproduction on the sweep's folder is refused in one line naming the sweep, and a sweep on a folder a
    design holds is refused; each folder is free again after its holder ends."""
    from tengsim.errors import TengsimError
    from tengsim.outfolder import folder_lock
    from tengsim.study.layout import StudyDir

    sd = StudyDir(tmp_path / "out")
    with sd.lock("sweep"):
        with pytest.raises(TengsimError, match=r"in use by another tengsim run \(pid \d+, tengsim sweep"):
            with folder_lock(sd.root, holder="tengsim design"):
                pass
    with folder_lock(sd.root, holder="tengsim design"):
        with pytest.raises(TengsimError, match=r"in use by another tengsim run \(pid \d+, tengsim design"):
            with sd.lock("optimize"):
                pass
    with sd.lock("sweep"), pytest.raises(TengsimError, match="in use by another sweep"):
        with sd.lock("sweep"):
            pass
    with folder_lock(sd.root, holder="tengsim calibrate"), StudyDir(tmp_path / "other").lock("sweep"):
        pass  # two folders: no interference
    with sd.lock("sweep"):  # free again
        pass


def test_c12_a_child_forked_while_the_folder_is_held_does_not_keep_it(tmp_path):
    """A process forked while a sweep holds its folder (a worker a Dask nanny restarts) does not hold the
    folder after the sweep ends (a flock kept by the child's copy made the next sweep refuse, by chance);
    another live process that holds it is still refused, with its pid."""
    import signal
    import subprocess
    import sys

    from tengsim.errors import TengsimError
    from tengsim.study.layout import StudyDir

    sd = StudyDir(tmp_path / "out")
    children, truncate = [], os.ftruncate

    def fork_meanwhile(fd, n):  # another thread's fork lands while the lock is being taken
        truncate(fd, n)
        if not children:
            pid = os.fork()
            if pid == 0:  # the child: outlives the sweep's lock, as a restarted worker does
                time.sleep(30)
                os._exit(0)
            children.append(pid)

    os.ftruncate = fork_meanwhile
    try:
        with sd.lock():
            os.ftruncate = truncate
            with pytest.raises(TengsimError, match="in use by another sweep"):  # the same process, again
                with sd.lock():
                    pass
    finally:
        os.ftruncate = truncate
    (pid,) = children
    try:
        with sd.lock():  # the child still lives and the folder is free
            pass
    finally:
        os.kill(pid, signal.SIGKILL)
        os.waitpid(pid, 0)
    code = ("import sys, time; from pathlib import Path; from tengsim.study.layout import StudyDir\n"
            "with StudyDir(Path(sys.argv[1])).lock():\n    print('held', flush=True); time.sleep(30)\n")
    p = subprocess.Popen([sys.executable, "-c", code, str(sd.root)], stdout=subprocess.PIPE, text=True)
    try:
        assert p.stdout.readline().strip() == "held"
        with pytest.raises(TengsimError, match=rf"in use by another sweep or optimisation \(pid {p.pid}\)"):
            with sd.lock():
                pass
    finally:
        p.kill()
        p.wait()
    with sd.lock():  # its holder is gone: free again
        pass


# ---- 13: messages that keep the cause ------------------------------------------------------------
def test_c13_negative_quantity_is_a_value_not_a_missing_argument(tmp_path, capsys):
    argv = ["contact", "pyramid", "--pitch", "2um", "--base", "1um", "--height", "0.7um", "--E-star", "-0.59MPa",
            "--W", "54mJ/m2", "--tabor", "1", "--out", str(tmp_path / "o.csv")]
    line = refused(capsys, argv, where=tmp_path)
    assert "E_star" in line and "> 0" in line and "expected one argument" not in line


@pytest.mark.parametrize("key, value, words", [
    ("--E-star", "-0.59MPa", "E_star must be > 0, got '-0.59MPa'"),
    ("--pitch", "-2um", "pitch must be > 0, got '-2um'"),
    ("--base", "3um", "pyramid base 3 µm is wider than its pitch 2 µm"),
])
def test_c13_a_bad_physical_value_is_named_as_the_user_wrote_it(tmp_path, capsys, key, value, words):
    args = {"--pitch": "2um", "--base": "1um", "--height": "0.7um", "--E-star": "0.59MPa", "--W": "54mJ/m2"}
    args[key] = value
    out = tmp_path / "r.csv"
    argv = ["contact", "pyramid", *[w for kv in args.items() for w in kv], "--tabor", "0.5", "--out", str(out)]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert err == f"tengsim: error: {words}" and not out.exists()


def test_c13_unknown_tables_name_device_and_a_huge_value_is_cut(tmp_path, capsys):
    cfg = tmp_path / "run.toml"
    cfg.write_text("[foo]\nx = 1\n")
    assert "device" in refused(capsys, ["run", str(cfg)])
    huge = "9" * 100_000
    line = refused(capsys, [*BASE, "--tabor", huge, "--out", str(tmp_path / "o.csv")], where=tmp_path, keep={"run.toml"})
    assert len(line) < 300 and "100002 characters" in line
    line = refused(capsys, ["sweep", str(cfg), "--workers", "x" * 100_000])
    assert len(line) < 300
    for argv in (["contact", "pyramid", "--law", huge], ["sweep", huge], ["contact", huge]):  # the edge cuts too
        assert len(refused(capsys, [*argv, "--out", str(tmp_path / "o.csv")], where=tmp_path, keep={"run.toml"})) < 400


def test_c13_the_shown_value_is_cut():
    from tengsim.errors import listed, shown

    assert shown("a" * 10) == "'aaaaaaaaaa'"
    assert shown("a" * 1000).endswith("… (1002 characters)") and len(shown("a" * 1000)) < 90
    assert listed(["a", "b", "c"], 2) == "'a', 'b' and 1 more"


# ---- the study NetCDF: CF names ------------------------------------------------------------------
def test_cf_variable_names_are_letters_digits_underscores():
    from tengsim.study.dataset import cf_name

    assert cf_name("contact.tabor") == "contact_tabor"
    assert cf_name("var.aspect") == "var_aspect"
    assert cf_name("group") == "group"
    assert cf_name("1x") == "v_1x"


def test_c05_a_huge_popsize_is_refused_before_any_point(tmp_path, capsys):
    f = _study(tmp_path, '[axes]\n"contact.N" = { start = 0.9, stop = 1.0 }\n[objective]\nminimize = "pull_off_F"\n'
                         "popsize = 1000000000\n")
    line = refused(capsys, ["optimize", str(f), "--out", str(tmp_path / "o"), "--workers", "1"], where=tmp_path)
    assert "popsize" in line and "at most 100000" in line and not (tmp_path / "o").exists()


def test_c12_a_child_forked_during_a_sweep_does_not_keep_the_folder(tmp_path):
    """A process forked while the study folder is locked (a worker a Dask nanny restarts by fork during the
    sweep) does not hold the folder once the sweep has ended: the next sweep on it takes the lock."""
    import time

    from tengsim.study.layout import StudyDir

    sd = StudyDir(tmp_path / "out")
    with sd.lock():
        pid = os.fork()
        if pid == 0:  # the child lives on past the sweep
            time.sleep(3.0)
            os._exit(0)
        time.sleep(0.3)
    try:
        with sd.lock():
            pass
    finally:
        os.kill(pid, 9)
        os.waitpid(pid, 0)
