"""Memory a contact run needs, checked against what the machine has (:func:`tengsim.resources.available_bytes`)
before anything is allocated.

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
  2 n, and 2 n more while the result is written.  The states the retraction takes back at the approach's
  jumps are in a temporary file, not in memory (:class:`tengsim.continuation.retrace.Spill`: on disk, 4 n
  for each of :data:`tengsim.continuation.retrace.MAX_KEPT` jumps, read back one at a time).

The run's peak is the larger of the kernel build and the solve (the build's temporaries are freed
before the solve).  tests/test_resources.py checks it against the peak RSS of whole runs.
"""
from __future__ import annotations

import os

from tengsim import resources
from tengsim.errors import MemoryRefused

_F64 = 8
KERNEL_BUILD_FREE = 10.5     # floats per padded point at the free kernel's build peak (measured 10.2)
KERNEL_BUILD_PERIODIC = 6.0  # floats per half-spectrum point while the periodic multiplier is built
FAST_WORK = 16               # work arrays of the fast solver besides its L-BFGS rows
VSR_WORK = 14
PATH_WORK = 14               # U0, g0 and three equilibria (q, w, H, P); the retraction's kept states: on disk
MAP_WORK = 4                 # P and H kept, and stacked once more for the file


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


def default_max_pixels(boundary: str = "free", solver: str = "fast") -> int:
    """The largest n² whose run fits in the machine's free memory (:func:`tengsim.resources.available_bytes`, :func:`estimate_bytes`):
    a refinement's default max_pixels; 4096² if the free memory cannot be read."""
    avail = resources.available_bytes()
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


def _gib(b: float) -> str:
    return f"{b / 2**30:.2f} GiB" if b < 10 * 2**30 else f"{b / 2**30:.0f} GiB"


def check_memory(nx: int, ny: int, boundary: str = "free", solver: str = "fast", memory: int = 10,
                 maps: int = 0, available: int | None = None) -> int:
    """Raise MemoryRefused (a TengsimError) (needed vs available) if the run cannot fit in memory; return the bytes needed.

    ``available`` defaults to :func:`tengsim.resources.available_bytes`; the check is skipped when that is unknown or
    when the environment variable TENGSIM_NO_MEMORY_CHECK is set to 1."""
    need = estimate_bytes(nx, ny, boundary, solver, memory, maps)
    if os.environ.get("TENGSIM_NO_MEMORY_CHECK") == "1":
        return need
    avail = resources.available_bytes() if available is None else int(available)
    if avail is not None and need > avail:
        raise MemoryRefused(
            f"a {nx}×{ny} grid ({boundary} boundary, {solver} solver) needs about {_gib(need)} of memory, "
            f"but {_gib(avail)} is available: use a larger dx or a smaller cell "
            f"(TENGSIM_NO_MEMORY_CHECK=1 skips this check)")
    return need
