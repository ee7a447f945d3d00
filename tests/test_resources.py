"""Memory check of a contact run: the estimate against a measured peak RSS, and a clear refusal."""
import json
import os
import subprocess
import sys

import pytest

from tengsim.run.plan import ContactPlan
from tengsim import resources
from tengsim.run import memory
from tengsim.cli.main import main
from tengsim.errors import TengsimError

_PEAK = r"""
import json, resource, sys
from tengsim.run.plan import ContactPlan
from tengsim.run.simulate import simulate
from tengsim.shapes import Pyramid
from tengsim.continuation import PathSpec
def rss():
    # peak RSS of this process image: VmHWM (getrusage's ru_maxrss also counts the parent's RSS at
    # fork time, since Linux keeps it across exec)
    try:
        with open("/proc/self/status") as fh:
            return next(int(l.split()[1]) * 1024 for l in fh if l.startswith("VmHWM:"))
    except (OSError, StopIteration):
        return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
boundary, solver, n = sys.argv[1], sys.argv[2], int(sys.argv[3])
shape = Pyramid(0.946, 3.78)
grid = shape.grid(3.78 / n)
base = rss()
simulate(ContactPlan(shape, 0.5, 3.78 / n, PathSpec(-1.0, 0.0, 0.5), boundary=boundary, solver=solver, solver_tol=1e-5,
                     symmetry="off"))  # the estimate is the full grid's (a symmetric run checks its block's)
print(json.dumps([grid.nx, grid.ny, rss() - base]))
"""


def _measured_peak(boundary, solver, n):
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1"}
    out = subprocess.run([sys.executable, "-c", _PEAK, boundary, solver, str(n)], capture_output=True,
                         text=True, env=env, check=True).stdout
    return json.loads(out)


@pytest.mark.parametrize("boundary, solver, n", [
    ("free", "fast", 512),
    pytest.param("periodic", "fast", 512, marks=pytest.mark.slow),
    pytest.param("free", "vsr", 512, marks=pytest.mark.slow),
])
def test_estimate_within_30_percent_of_measured_peak_rss(boundary, solver, n):
    """Peak RSS growth of a whole run (kernel build, path, solves) in a fresh process, 525² grid.
    Measured on the test machine (floats per grid point, measured / estimated): free/fast 85 / 83,
    periodic/fast 66 / 72, and at 1029² free/fast 83.6 / 83.0.  Below ~500² glibc serves arrays
    from heap holes left by the imports and the RSS growth undercounts."""
    nx, ny, peak = _measured_peak(boundary, solver, n)
    est = memory.estimate_bytes(nx, ny, boundary, solver)
    assert abs(est - peak) <= 0.3 * peak, (est, peak, est / peak)


def test_estimate_scales_with_grid_and_memory():
    a = memory.estimate_bytes(1025, 1025)
    assert memory.estimate_bytes(2049, 2049) == pytest.approx(4 * a, rel=0.1)
    assert memory.estimate_bytes(1025, 1025, memory=20) > a > memory.estimate_bytes(1025, 1025, "periodic")
    assert memory.estimate_bytes(1025, 1025, solver="vsr") < a
    # the 1893² run of the issue: ~3 GB, far below what the old fixed 4096² limit let through (11 GB)
    assert 2e9 < memory.estimate_bytes(1893, 1893) < 4e9
    assert memory.estimate_bytes(4096, 4096) > 1e10


def test_available_memory_is_read():
    avail = resources.available_bytes()
    assert avail is not None and 1 << 26 < avail < 1 << 50


def test_check_memory_names_needed_and_available():
    need = memory.check_memory(101, 101, available=1 << 40)
    assert need == memory.estimate_bytes(101, 101)
    with pytest.raises(TengsimError) as exc:
        memory.check_memory(4001, 4001, "periodic", "vsr", available=2 * 2**30)
    msg = str(exc.value)
    assert "4001×4001" in msg and "periodic" in msg and "vsr" in msg
    assert f"{memory.estimate_bytes(4001, 4001, 'periodic', 'vsr') / 2**30:.2f} GiB" in msg
    assert "2.00 GiB is available" in msg


def test_check_memory_can_be_switched_off(monkeypatch):
    monkeypatch.setenv("TENGSIM_NO_MEMORY_CHECK", "1")
    assert memory.check_memory(4001, 4001, available=1) > 0


def test_cli_refuses_a_run_that_does_not_fit(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(resources, "available_bytes", lambda: 10 * 2**20)
    out = tmp_path / "r.csv"
    rc = main(["contact", "sphere", "--cell", "8", "--dx", "0.05", "--quiet", "--out", str(out)])
    err = capsys.readouterr().err
    assert rc == 2 and "165×165 grid" in err and "0.01 GiB is available" in err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert list(tmp_path.iterdir()) == []


def test_cgroup_limit_counts_reclaimable_cache(tmp_path):
    assert resources.cgroup_room(str(tmp_path)) is None  # no cgroup files
    (tmp_path / "memory.max").write_text("max\n")
    (tmp_path / "memory.current").write_text("5000\n")
    assert resources.cgroup_room(str(tmp_path)) is None  # no limit
    (tmp_path / "memory.max").write_text("8000\n")
    assert resources.cgroup_room(str(tmp_path)) == 3000
    (tmp_path / "memory.stat").write_text("anon 3000\nfile 2000\nactive_file 500\ninactive_file 1500\n")
    assert resources.cgroup_room(str(tmp_path)) == 4500


@pytest.mark.parametrize("symmetry", ["auto", "off"])
def test_simulate_checks_memory_before_any_kernel_is_built(monkeypatch, symmetry):
    """The run's memory is checked after its pieces are chosen (the block, the solver wrapped for it) and before
    the kernel, the first large allocation: one line naming the block and the inner solver, and no kernel built."""
    from tengsim.continuation import PathSpec
    from tengsim.run import simulate as sim
    from tengsim.shapes import Pyramid

    def no_kernel(*a, **k):
        raise AssertionError("a kernel was built before the memory check refused the run")

    monkeypatch.setattr(sim, "MirrorKernel", no_kernel)
    monkeypatch.setattr(sim, "make_kernel", no_kernel)
    monkeypatch.setattr(resources, "available_bytes", lambda: 2**20)
    shape = Pyramid(0.946, 3.78)
    g = shape.grid(3.78 / 61)
    with pytest.raises(TengsimError) as err:
        sim.simulate(ContactPlan(shape, 0.5, g.dx, PathSpec(-1.0, 0.0, 0.5), symmetry=symmetry))
    n = (g.nx + 1) // 2 if symmetry == "auto" else g.nx  # the block of the odd grid, mirrored in X and Y
    assert g.nx % 2 == 1 and f"a {n}×{n} grid (free boundary, fast solver) needs about" in str(err.value)
