"""The periodic kernel split across MPI processes (issue 23, item 3): the slab-decomposed convolution and a
whole contact run under ``mpiexec -n 2`` equal the serial ones.  Skipped where mpi4py or mpiexec is absent
(``pip install 'tengsim[mpi]'`` brings both: mpi4py and the mpich wheel)."""
from __future__ import annotations

import os
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from tengsim.grid import Grid
from tengsim.kernels.distributed import slabs

mpi4py = pytest.importorskip("mpi4py")
MPIEXEC = shutil.which("mpiexec", path=str(Path(sys.executable).parent) + os.pathsep + os.environ.get("PATH", ""))
needs_mpiexec = pytest.mark.skipif(MPIEXEC is None, reason="no mpiexec on PATH")
ENV = {**os.environ, "OPENBLAS_NUM_THREADS": "1", "TENGSIM_THREADS": "1", "TENGSIM_FFT_WORKERS": "1",
       "MPLBACKEND": "Agg"}


def _mpirun(n, args, cwd, timeout=900):
    cmd = [MPIEXEC, "-n", str(n), *args]
    return subprocess.run(cmd, cwd=cwd, env=ENV, capture_output=True, text=True, timeout=timeout)


def test_slabs_split_rows_evenly():
    assert slabs(10, 3) == [(0, 4), (4, 7), (7, 10)]
    assert slabs(4, 4) == [(0, 1), (1, 2), (2, 3), (3, 4)]
    with pytest.raises(Exception, match="cannot split 2 rows over 3"):
        slabs(2, 3)


_CONV = textwrap.dedent("""
    import sys, numpy as np
    from mpi4py import MPI
    from tengsim.grid import Grid
    from tengsim.kernels import PeriodicKernel
    from tengsim.kernels.distributed import SlabPeriodicKernel
    comm = MPI.COMM_WORLD
    worst = 0.0
    for nx, ny, film in [(255, 261, None), (96, 100, dict(thickness=2.0, poisson=0.3)),
                         (64, 64, dict(thickness=1.0, poisson=0.5, substrate="frictionless"))]:
        g = Grid(nx, ny, 0.1, 0.13)
        kw = film or {}
        p = np.random.default_rng(nx).standard_normal(g.shape)
        ref = PeriodicKernel(g, 0.7, **kw).apply(p)
        k = SlabPeriodicKernel(g, 0.7, comm, **kw)
        r0, r1 = k.rows
        w = k.apply(p[r0:r1])
        worst = max(worst, float(np.abs(w - ref[r0:r1]).max() / np.abs(ref).max()))
        full = k.apply(p)                                  # a full field on every rank: the full K p
        worst = max(worst, float(np.abs(full - ref).max() / np.abs(ref).max()))
    worst = comm.allreduce(worst, op=MPI.MAX)
    if comm.rank == 0:
        print("WORST", worst)
""")


@needs_mpiexec
@pytest.mark.parametrize("n", [2, 3])
def test_slab_convolution_equals_serial(tmp_path, n):
    script = tmp_path / "conv.py"
    script.write_text(_CONV)
    res = _mpirun(n, [sys.executable, str(script)], tmp_path, timeout=300)
    assert res.returncode == 0, res.stderr[-2000:]
    worst = float(res.stdout.split("WORST")[1].split()[0])
    assert worst <= 1e-12


def _contact_args(cell, dx, out):
    # a gentle adhesive surface (μ 0.3, rms slope 0.05): a few hundred iterations per equilibrium at 1024²
    return ["contact", "rough", "--hurst", "0.8", "--rms-slope", "0.05", "--cell", str(cell), "--short-cutoff",
            str(4 * dx), "--seed", "7", "--dx", str(dx), "--boundary", "periodic", "--tabor", "0.3", "--d-min", "0.25",
            "--d-max", "0.5", "--d-step", "0.25", "--refine-levels", "0", "--tol", "1e-11", "--out", str(out)]


def _compare(tmp_path, cell, dx):
    from tengsim.results.read import load_result

    serial = tmp_path / "serial.csv"
    par = tmp_path / "par.csv"
    r1 = subprocess.run([sys.executable, "-m", "tengsim.cli.main", *_contact_args(cell, dx, serial)],
                        cwd=tmp_path, env=ENV, capture_output=True, text=True, timeout=1800)
    assert r1.returncode == 0, r1.stderr[-2000:]
    r2 = _mpirun(2, [sys.executable, "-m", "tengsim.cli.main", *_contact_args(cell, dx, par)], tmp_path, timeout=1800)
    assert r2.returncode == 0, r2.stderr[-2000:]
    (_, a), (_, b) = load_result(serial), load_result(par)
    assert b.params["mpi_processes"] == 2 and "mpi_processes" not in a.params
    assert len(a.table["F"]) == len(b.table["F"])
    scale = float(np.max(np.abs(a.table["F"])))
    assert np.max(np.abs(np.asarray(a.table["F"]) - np.asarray(b.table["F"]))) <= 1e-10 * scale
    assert list(a.table["status"]) == list(b.table["status"])
    return a, b


@needs_mpiexec
def test_contact_run_under_mpiexec_equals_serial_small(tmp_path):
    _compare(tmp_path, 12.8, 0.1)   # 128²


@needs_mpiexec
@pytest.mark.slow
def test_contact_run_under_mpiexec_equals_serial_1024(tmp_path):
    _compare(tmp_path, 102.4, 0.1)  # 1024²


@needs_mpiexec
def test_mpi_run_refuses_a_free_cell(tmp_path):
    out = tmp_path / "x.csv"
    args = ["contact", "pyramid", "--N", "0.946", "--cell", "3.78", "--dx", "0.4", "--d-min", "0", "--d-max",
            "1", "--d-step", "0.5", "--out", str(out)]
    res = _mpirun(2, [sys.executable, "-m", "tengsim.cli.main", *args], tmp_path, timeout=300)
    assert res.returncode == 2
    assert "periodic" in res.stderr and "Traceback" not in res.stderr
    assert not out.exists()
