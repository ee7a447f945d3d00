"""Memory a contact run needs, checked against what the machine has before anything is allocated.

:func:`estimate_bytes` counts the float64 arrays of a run on an nx × ny grid (n = nx·ny points):

* free kernel (padded P = px·py, px = fast_len(2nx − 1)): building the influence coefficients holds
  ~10.5 P floats at its peak (offset meshes, the four corner terms of Love's formula, the transform);
  kept afterwards: the half spectrum (complex, P floats), the per-thread transform buffers (P + 2 nx·py);
* periodic kernel: the multiplier and one complex buffer on the half spectrum nx·(ny/2 + 1), ~6 more
  while building it;
* fast solver: 12 work arrays, the convolution output, copies of g0, q and w (16 n), and the L-BFGS
  memory: s, y and their images K s, K y, 4·(memory + 1) rows of n (the 4 spare rows keep an evicted
  pair until its successor is confirmed);
* VSR solver: ~14 n (state, trial state, pressures, energies, residuals);
* the path: U0 and g0, and up to three equilibria alive (q, w, H, P each): 14 n; every saved map
  2 n, and 2 n more while the result is written.

The run's peak is the larger of the kernel build and the solve (the build's temporaries are freed
before the solve).  Checked against the peak RSS of a 525² run (tests/test_resources.py): within 10 %.
"""
from __future__ import annotations

import os
from dataclasses import dataclass

from tengsim.errors import TengsimError

_F64 = 8
KERNEL_BUILD_FREE = 10.5     # floats per padded point at the free kernel's build peak (measured 10.2)
KERNEL_BUILD_PERIODIC = 6.0  # floats per half-spectrum point while the periodic multiplier is built
FAST_WORK = 16               # work arrays of the fast solver besides its L-BFGS rows
VSR_WORK = 14
PATH_WORK = 14               # U0, g0 and three equilibria (q, w, H, P)
MAP_WORK = 4                 # P and H kept, and stacked once more for the file


MAX_POINTS = 100_000
"""The most points a study may hold (its grid's product of axis lengths, n samples, a range's num, an
optimisation's population × generations): a sweep of 10⁵ contact runs is weeks of CPU already."""
MAX_PIXELS_PER_SIDE = 65_536
"""The most pixels along one side of a contact grid (65 536² floats are 32 GiB each)."""


def check_count(count, what: str, limit: int = MAX_POINTS) -> int:
    """``count`` if at most ``limit``, else one TengsimError naming ``what``: the one check of how many
    points, values or workers an input asks for, made before anything is allocated or submitted."""
    count = int(count)
    if count > limit:
        raise TengsimError(f"{what} asks for {count:.4g} points; at most {limit} are allowed in one run"
                           if count >= 1e6 else f"{what} asks for {count}; at most {limit} are allowed in one run")
    return count


def max_workers() -> int:
    """The most local worker processes a sweep may start: 4 per core (at least 8)."""
    return max(8, 4 * (os.cpu_count() or 1))


def estimate_bytes(nx: int, ny: int, boundary: str = "free", solver: str = "fast", memory: int = 10,
                   maps: int = 0) -> int:
    """Peak bytes of the arrays a contact run on an ``nx`` × ``ny`` grid allocates (see module doc).

    ``boundary`` 'free' or 'periodic', ``solver`` 'fast' or 'vsr' (other names: counted as 'free' and
    'fast', the larger), ``memory`` the fast solver's L-BFGS pairs, ``maps`` the number of saved maps."""
    from tengsim import backend

    nx, ny, n = int(nx), int(ny), int(nx) * int(ny)
    if boundary == "periodic":
        half = nx * (ny // 2 + 1)
        build = KERNEL_BUILD_PERIODIC * half
        kept = 3.0 * half  # real multiplier + complex buffer
    else:
        px, py = backend.fast_len(2 * nx - 1), backend.fast_len(2 * ny - 1)
        P = px * py
        build = KERNEL_BUILD_FREE * P
        kept = 2.0 * P + 2.0 * nx * py
    work = VSR_WORK if solver == "vsr" else FAST_WORK + 4 * (int(memory) + 1)
    solve = kept + work * n + PATH_WORK * n + MAP_WORK * int(maps) * n
    return int(_F64 * max(build, solve))


def available_bytes() -> int | None:
    """Memory this process can still get: MemAvailable (/proc/meminfo), else the free physical pages
    (os.sysconf), capped by a cgroup v2 limit (:func:`cgroup_room`); None if nothing can be read."""
    avail = None
    try:
        with open("/proc/meminfo") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    avail = int(line.split()[1]) * 1024
                    break
    except (OSError, ValueError, IndexError):
        pass
    if avail is None:
        try:
            avail = os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
        except (ValueError, OSError, AttributeError):
            avail = None
    room = cgroup_room()  # a container's limit may be far below the host's free memory
    if room is not None:
        avail = room if avail is None else min(avail, room)
    return avail


def cgroup_room(root: str = "/sys/fs/cgroup") -> int | None:
    """Bytes left under a cgroup v2 memory limit: memory.max − memory.current + the inactive file
    cache (reclaimable); None without a limit."""
    from pathlib import Path

    try:
        limit = (Path(root) / "memory.max").read_text().strip()
        if limit == "max":
            return None
        used = int((Path(root) / "memory.current").read_text().strip())
    except (OSError, ValueError):
        return None
    cache = 0
    try:
        for line in (Path(root) / "memory.stat").read_text().splitlines():
            key, _, val = line.partition(" ")
            if key == "inactive_file":
                cache = int(val)
    except (OSError, ValueError):
        pass
    return max(0, int(limit) - used + cache)


def default_max_pixels(boundary: str = "free", solver: str = "fast") -> int:
    """The largest n² whose run fits in the machine's free memory (:func:`available_bytes`, :func:`estimate_bytes`):
    a refinement's default max_pixels; 4096² if the free memory cannot be read."""
    avail = available_bytes()
    if avail is None:
        return 4096**2
    lo, hi = 3, 3
    while estimate_bytes(hi, hi, boundary, solver) <= avail and hi < 2**17:
        lo, hi = hi, hi * 2
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if estimate_bytes(mid, mid, boundary, solver) <= avail:
            lo = mid
        else:
            hi = mid
    return max(9, lo * lo)


@dataclass(frozen=True)
class CostModel:
    """Seconds of one solver iteration on a grid of ``points`` solved pixels: ``floor`` + ``per_point`` × points;
    ``backend`` names the machine and solver the constants were measured on (printed with every estimate)."""

    backend: str
    floor: float
    per_point: float

    def iteration_seconds(self, points: float) -> float:
        return self.floor + self.per_point * float(points)


CPU_COST = CostModel("CPU (NumPy fast solver; constant of the 2-core build machine)", 0.0, 5.3e-8)
"""The NumPy fast solver: seconds per solved pixel and iteration, fitted on four designs on the 2-core build machine
(docs/benchmarks.md, "Design estimates")."""
GPU_COST = CostModel("GPU (JAX solver, float64; constants of one NVIDIA H200)", 6.2e-4, 3.5e-10)
"""The JAX solver on a GPU: a floor per iteration (launches and synchronisations) plus a per-point term, fitted to
one H200's cold rough solves at 1024²–8192² (docs/benchmarks.md, "GPU")."""


def gpu_break_even_points() -> float:
    """Grid points from which an iteration costs less on the GPU than on the CPU by the two cost models (the
    GPU's floor over the CPU's extra per point): about 11 800 (≈ 109²).  Below it the solver ``auto`` keeps the
    CPU (tengsim.solvers.choice)."""
    return GPU_COST.floor / (CPU_COST.per_point - GPU_COST.per_point)


GPU_BYTES_PER_POINT = {"float64": 480, "float32": 240}
"""Peak device memory of the JAX solver per grid point, rounded up from the H200's (docs/benchmarks.md, "GPU")."""


def cost_model(gpu: bool) -> CostModel:
    """The cost model of the backend a run solves on: :data:`GPU_COST` on a GPU, else :data:`CPU_COST`."""
    return GPU_COST if gpu else CPU_COST


def _gib(b: float) -> str:
    return f"{b / 2**30:.2f} GiB" if b < 10 * 2**30 else f"{b / 2**30:.0f} GiB"


def check_memory(nx: int, ny: int, boundary: str = "free", solver: str = "fast", memory: int = 10,
                 maps: int = 0, available: int | None = None) -> int:
    """Raise TengsimError (needed vs available) if the run cannot fit in memory; return the bytes needed.

    ``available`` defaults to :func:`available_bytes`; the check is skipped when that is unknown or
    when the environment variable TENGSIM_NO_MEMORY_CHECK is set to 1."""
    need = estimate_bytes(nx, ny, boundary, solver, memory, maps)
    if os.environ.get("TENGSIM_NO_MEMORY_CHECK") == "1":
        return need
    avail = available_bytes() if available is None else int(available)
    if avail is not None and need > avail:
        raise TengsimError(
            f"a {nx}×{ny} grid ({boundary} boundary, {solver} solver) needs about {_gib(need)} of memory, "
            f"but {_gib(avail)} is available: use a larger dx or a smaller cell "
            f"(TENGSIM_NO_MEMORY_CHECK=1 skips this check)")
    return need
