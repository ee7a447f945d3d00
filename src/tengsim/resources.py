"""What the machine has and what it allows: the memory this process can still get (:func:`available_bytes`), the
bounds on what one input may ask for (:func:`check_count`, :data:`MAX_PIXELS_PER_SIDE`, :func:`max_workers`), and the
cost models of one solver iteration on the CPU and on a GPU (:data:`CPU_COST`, :data:`GPU_COST`).  What a contact
run needs of that memory, and the check against it, is the run layer's (:mod:`tengsim.run.memory`).
"""
from __future__ import annotations

import os
from dataclasses import dataclass

from tengsim.errors import TengsimError



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
CPU_WALK_COST = CostModel(CPU_COST.backend, 0.0, 1.0e-7)
"""A design's walk on the NumPy fast solver: seconds of CPU per solved pixel and solver iteration of the whole walk
(the path's per-row work, the charged-area scans, the status and the line search's extra trials spread over the
iterations), what the design's expected time counts (:func:`cost_model`); re-fitted on four designs on the 2-core
build machine, shared (docs/benchmarks.md, "Design estimates", 2026-12-02: at :data:`CPU_COST`'s 5.3e-8 the README
design's expected time was 2.8× low; one constant cannot hold every design within 1.5×: 1e-7 puts the README
pyramid at 1.5× under, the hemisphere and the cube 0.6–0.7× over).  :data:`CPU_COST` stays the solver's own iteration, which the GPU's
break-even compares with."""
GPU_COST = CostModel("GPU (JAX solver, float64; constants of one NVIDIA H200)", 6.2e-4, 3.5e-10)
"""The JAX solver on a GPU: a floor per iteration (launches and synchronisations) plus a per-point term, fitted to
one H200's cold rough solves at 1024²–8192² (docs/benchmarks.md, "GPU")."""


def gpu_break_even_points() -> float:
    """Grid points from which an iteration costs less on the GPU than on the CPU by the two cost models (the
    GPU's floor over the CPU's extra per point): about 11 800 (≈ 109²).  Below it the solver ``auto`` keeps the
    CPU (tengsim.run.choice)."""
    return GPU_COST.floor / (CPU_COST.per_point - GPU_COST.per_point)


GPU_BYTES_PER_POINT = {"float64": 480, "float32": 240}
"""Peak device memory of the JAX solver per grid point, rounded up from the H200's (docs/benchmarks.md, "GPU")."""


def cost_model(gpu: bool) -> CostModel:
    """The cost model of the backend a run solves on: :data:`GPU_COST` on a GPU, else :data:`CPU_WALK_COST`."""
    return GPU_COST if gpu else CPU_WALK_COST


