"""The fast solver compiled with JAX: the same L-BFGS, end to end in one jit-compiled loop, on a GPU or a CPU.

:class:`JaxSolver` runs the algorithm of :class:`tengsim.solvers.FastSolver` (traced in
tengsim.solvers._jax_loop, with the same constants, tengsim.solvers._constants) as one ``lax.while_loop``:
no Python between iterations, every array on the device, the convolution ``jnp.fft`` inside the compiled
program (tengsim.solvers._jax_fft).  It therefore sits beside the NumPy solvers' seam (tengsim.backend,
NumPy arrays and scipy's pocketfft on the host) rather than in it: a JAX array inside a traced loop cannot go
through a host FFT.  From a kernel it takes only what :class:`tengsim.registry.FourierKernelLike` declares
(spectrum, padded shape, periodic, pinned mean): the free cell (zero padded), the periodic one and both with
a film; the mirror-block kernel (a DCT-I, which JAX lacks) is refused ("mirror kernel is CPU only"), and so is
a slab-distributed (MPI) kernel.  Every law whose ``_raw`` takes an array namespace ``xp`` (all the built-in
ones) runs, its parameters traced.

Registered solvers: ``jax`` (JAX's default device: the GPU when JAX has one, else the CPU) and ``gpu`` (a GPU
or a one-line error), both float64; ``auto`` (tengsim.solvers.choice) picks ``gpu`` where JAX sees one.
From the API: ``JaxSolver(dtype="float32")`` and ``JaxSolver(shards=N)``, the grid's rows split over N devices
(a slab FFT with all-to-all; equal to the one-device solve to round-off).  Results equal the NumPy solver's:
in float64 step for step to round-off, and where round-off grows (a long path, an adhesive rough surface) the
same equilibria to the tolerance (tests/test_jax_solver.py).  float32 fields keep every scalar (energies,
slopes, inner products, the L-BFGS coefficients) in float64; its tolerance is raised to :data:`F32_TOL` at
least, and where it stops short of that is in docs/benchmarks.md ("GPU").

Memory: JAX may take :data:`MEM_FRACTION` of a GPU (set before JAX starts, unless the user set it), and a
solve larger than the device allows is refused in one line naming the shards it needs
(:func:`check_device_memory`, from the bytes per point measured: tengsim.resources.GPU_BYTES_PER_POINT).

Compilation: one per static configuration (grid shape, kernel kind, law class, dtype, memory, resync,
device, shards), cached in this module and shared by every solver object and every equilibrium of a path; D
(through g0), the law's parameters, the kernel's spectrum, tol and max_iter are traced arguments.
:func:`compile_stats` reports how many compilations were made and how long they took; each
equilibrium's ``message`` names the compile time it paid (0 when cached).

JAX is imported only when a JaxSolver is made (or ``auto`` asks whether a GPU is there, on a machine with a GPU
plugin of JAX installed): ``import tengsim`` does not import it.
"""
from __future__ import annotations

import dataclasses
import inspect
import threading
import time
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from tengsim.errors import MemoryRefused, SolverUnavailable, TengsimError
from tengsim.laws.safe import SafeLaw
from tengsim.registry import SOLVERS
from tengsim.solvers.types import SOLVER_TOL, Equilibrium, Problem, State

F32_TOL = 2e-5  # float32 fields: the smallest tolerance it can reach reliably (max|r| in ε)
DEVICES = ("auto", "cpu", "gpu")
DTYPES = ("float64", "float32")
INSTALL = "pip install 'tengsim[gpu]' (CUDA 12) or 'tengsim[jax]' (CPU only)"

_CACHE: dict = {}
_LOCK = threading.Lock()
_STATS = {"compiles": 0, "compile_seconds": 0.0, "calls": 0}
_SPECTRA: dict = {}


def compile_stats() -> dict:
    """{'compiles', 'compile_seconds', 'calls'} since the process started (or :func:`clear_cache`)."""
    return dict(_STATS)


def clear_cache() -> None:
    """Forget every compiled loop (the next solve compiles anew) and reset the counters."""
    with _LOCK:
        _CACHE.clear()
        _SPECTRA.clear()
        _STATS.update(compiles=0, compile_seconds=0.0, calls=0)


MEM_FRACTION = "0.95"
"""The share of a GPU's memory JAX may take (JAX's default, 0.75, leaves a 16384² float64 solve off one H200).
Set before JAX starts, unless the user set XLA_PYTHON_CLIENT_MEM_FRACTION (or XLA_PYTHON_CLIENT_PREALLOCATE=false)
themselves."""


def prepare_environment() -> None:
    """Let JAX take :data:`MEM_FRACTION` of a GPU (called before JAX is first imported by tengsim)."""
    import os

    if "XLA_PYTHON_CLIENT_PREALLOCATE" not in os.environ:
        os.environ.setdefault("XLA_PYTHON_CLIENT_MEM_FRACTION", MEM_FRACTION)


def check_device_memory(dev, points: int, dtype: str, shards: int = 1, padded: int = 0) -> None:
    """Refuse (one line) a solve whose measured bytes per point (tengsim.resources.GPU_BYTES_PER_POINT) over the
    devices exceed what the device lets JAX allocate; nothing is checked where the device does not say.
    ``padded``: the free cell's zero-padded points (its spectrum and transform buffers, 24 B each more)."""
    from tengsim.resources import GPU_BYTES_PER_POINT

    stats = getattr(dev, "memory_stats", lambda: None)() if dev.platform != "cpu" else None
    limit = (stats or {}).get("bytes_limit")
    need = (GPU_BYTES_PER_POINT[dtype] * points + 24 * padded) / max(int(shards), 1)
    if limit and need > limit:
        more = -(-int(need * max(int(shards), 1)) // int(limit))
        raise MemoryRefused(f"{points:.3g} points in {dtype} need about {need / 2**30:.0f} GiB per device, "
                           f"{dev.platform.upper()} {dev.id} allows {limit / 2**30:.0f} GiB: split the grid "
                           f"over {more} or more devices (JaxSolver(shards=...)) or use a coarser grid"
                           + (" (float32 halves the memory but may stop short of the tolerance on large grids)"
                              if dtype == "float64" else ""))


def _jax():
    """jax, with float64 enabled; a one-line TengsimError when it is not installed."""
    prepare_environment()
    try:
        import jax
    except ImportError:
        raise SolverUnavailable(f"the jax solver needs JAX, which is not installed: {INSTALL}") from None
    jax.config.update("jax_enable_x64", True)
    return jax


def find_device(device: str):
    """The JAX device for 'auto', 'cpu' or 'gpu' (TengsimError, one line, when there is none)."""
    jax = _jax()
    if device == "auto":
        return jax.devices()[0]
    try:
        found = jax.devices(device)
    except RuntimeError:
        found = []
    if not found:
        have = ", ".join(sorted({d.platform for d in jax.devices()}))
        raise SolverUnavailable(f"device {device!r}: JAX finds no {device.upper()} (it has: {have}); install JAX with "
                           f"CUDA, {INSTALL.split(' or ')[0]}, or use --solver jax (CPU) or fast")
    return found[0]


def _law_form(law):
    """(class, field names, values) of a law the loop can trace (a SafeLaw's own law: the loop applies
    the safe extension itself), or TengsimError."""
    if isinstance(law, SafeLaw):
        law = law.law
    cls = type(law)
    raw = getattr(cls, "_raw", None)
    ok = dataclasses.is_dataclass(law) and raw is not None and hasattr(law, "evaluate_xp")
    if ok:
        try:
            ok = "xp" in inspect.signature(raw).parameters
        except (TypeError, ValueError):
            ok = False
    if not ok:
        raise TengsimError(f"law {cls.__name__} has no array-namespace form (a dataclass Law whose _raw takes "
                           f"xp): the jax solver cannot trace it; use --solver fast")
    names = tuple(f.name for f in dataclasses.fields(law))
    return cls, names, tuple(float(getattr(law, k)) for k in names)


def _kernel_form(kernel):
    """(periodic, padded shape, spectrum, pinned mean) of a kernel that multiplies in Fourier space."""
    if getattr(kernel, "comm", None) is not None:
        raise TengsimError("the jax solver runs on one device: a slab-distributed (MPI) kernel is CPU only")
    if hasattr(kernel, "mirror"):  # a symmetry-reduced kernel (tengsim.kernels.mirror) declares its mirror
        raise TengsimError("mirror kernel is CPU only (JAX has no DCT-I): use --symmetry off with the jax solver")
    from tengsim.registry import FourierKernelLike

    if not isinstance(kernel, FourierKernelLike):
        raise TengsimError(f"kernel {type(kernel).__name__} does not multiply in Fourier space: the jax solver "
                           f"cannot run it; use --solver fast")
    return bool(kernel.periodic), tuple(int(n) for n in kernel.padded_shape), kernel.spectrum, bool(kernel.pinned_mean)


@dataclass(frozen=True)
class JaxSolver:
    """The fast solver (L-BFGS in the K metric, Wolfe line search) compiled with JAX (module docstring).

    ``device``: 'auto' (JAX's default), 'cpu' or 'gpu'; ``dtype``: 'float64' or 'float32' (the fields;
    scalars stay float64).  Same interface and result (host NumPy arrays) as FastSolver."""

    tol: float = SOLVER_TOL
    max_iter: int = 3000
    memory: int = 10
    resync: int = 25
    device: str = "auto"
    dtype: str = "float64"
    shards: int = 1
    """Devices the grid's rows are split over (a slab FFT with all-to-all, tengsim.solvers._jax_fft): 1 is one
    device; N > 1 takes the first N of the device's platform (the grid's rows must divide by N)."""
    name: str = "jax"
    resumes_from_state: ClassVar[bool] = True  # continuation.persist may go on from its capped state
    compiles: ClassVar[bool] = True  # compiled before its first solve on a grid (seconds, once per configuration)

    def __post_init__(self):
        if not self.tol > 0:
            raise TengsimError(f"tol must be > 0, got {self.tol!r}")
        if int(self.memory) < 1:
            raise TengsimError(f"memory must be >= 1, got {self.memory!r}")
        if int(self.resync) < 1:
            raise TengsimError(f"resync must be >= 1, got {self.resync!r}")
        if self.device not in DEVICES:
            raise TengsimError(f"device must be one of {', '.join(DEVICES)}, got {self.device!r}")
        if int(self.shards) < 1:
            raise TengsimError(f"shards must be >= 1, got {self.shards!r}")
        if self.dtype not in DTYPES:
            raise TengsimError(f"dtype must be one of {', '.join(DTYPES)}, got {self.dtype!r}")
        find_device(self.device)  # the one-line error now, before a run writes anything

    @property
    def effective_tol(self) -> float:
        return self.tol if self.dtype == "float64" else max(self.tol, F32_TOL)

    def _compiled(self, key, args, dev, mesh=None):
        with _LOCK:
            fn = _CACHE.get(key)
        if fn is not None:
            return fn, 0.0
        jax = _jax()
        from tengsim.solvers import _jax_loop

        shape, padded, periodic, pinned, cls, names, dtype, memory, resync = key[:9]
        solve = _jax_loop.build(shape, padded, periodic, pinned, cls, names, dtype, memory, resync, mesh)
        t0 = time.perf_counter()
        if mesh is None:
            with jax.default_device(dev):
                fn = jax.jit(solve).lower(*args).compile()
        else:  # the shardings are the arguments' own (put by solve)
            fn = jax.jit(solve).lower(*args).compile()
        dt = time.perf_counter() - t0
        with _LOCK:
            _CACHE[key] = fn
            _STATS["compiles"] += 1
            _STATS["compile_seconds"] += dt
        return fn, dt

    def _spectrum(self, kernel, spec, dtype, dev):
        """The kernel's spectrum on the device, kept while the kernel lives (a path's equilibria share it)."""
        jax = _jax()
        key = (id(kernel), dtype, str(dev))
        hit = _SPECTRA.get(key)
        if hit is not None and hit[0] is spec:
            return hit[1]
        cdt = np.complex128 if dtype == "float64" else np.complex64
        arr = jax.device_put(np.asarray(spec).astype(cdt if np.iscomplexobj(spec) else dtype), dev)
        if len(_SPECTRA) >= 2:  # a path uses one kernel: keep little device memory for spectra of the past
            _SPECTRA.clear()
        _SPECTRA[key] = (spec, arr)
        return arr

    def _mesh(self, dev, shape):
        """None on one device; else the mesh of the first ``shards`` devices of ``dev``'s platform."""
        n = int(self.shards)
        if n == 1:
            return None
        jax = _jax()
        from tengsim.solvers import _jax_fft

        devs = jax.devices(dev.platform)
        if len(devs) < n:
            raise TengsimError(f"shards = {n}: JAX has only {len(devs)} {dev.platform.upper()} device(s)")
        if shape[0] % n:
            raise TengsimError(f"shards = {n}: the grid's {shape[0]} rows do not split into {n} equal slabs")
        return _jax_fft.make_mesh(devs[:n])

    def solve(self, problem: Problem, start: State) -> Equilibrium:
        t0 = time.perf_counter()
        if problem.weights is not None:
            raise TengsimError("mirror kernel is CPU only (a weighted, symmetry-reduced problem): "
                               "use --symmetry off with the jax solver")
        jax = _jax()
        dev = find_device(self.device)
        periodic, padded, spec, pinned = _kernel_form(problem.kernel)
        cls, names, values = _law_form(problem.law)
        g0 = np.asarray(problem.g0, dtype=float)
        shape = g0.shape
        dtype = self.dtype
        mesh = self._mesh(dev, shape)
        if mesh is None:
            field_at = scalar_at = dev
            spec_dev = self._spectrum(problem.kernel, spec, dtype, dev)
        else:
            from tengsim.solvers import _jax_fft

            field_at, scalar_at = _jax_fft.field_sharding(mesh), _jax_fft.replicated(mesh)
            cdt = np.complex128 if dtype == "float64" else np.complex64
            spec_dev = jax.device_put(_jax_fft.pad_spectrum(np.asarray(spec).astype(
                cdt if np.iscomplexobj(spec) else dtype), mesh.devices.size), _jax_fft.spectrum_sharding(mesh))
        put = lambda a: jax.device_put(np.ascontiguousarray(a, dtype=dtype).ravel(), field_at)  # noqa: E731
        f64 = lambda v: jax.device_put(np.float64(v), scalar_at)  # noqa: E731
        args = (put(g0), put(start.q), put(start.w), spec_dev,
                tuple(f64(v) for v in values), f64(self.effective_tol),
                jax.device_put(np.int32(self.max_iter), scalar_at), f64(problem.dA), f64(g0.size))
        key = (shape, padded, periodic, pinned, cls, names, dtype, int(self.memory), int(self.resync), str(dev),
               int(self.shards))
        if key not in _CACHE:
            check_device_memory(dev, g0.size, dtype, self.shards, 0 if periodic else int(np.prod(padded)))
        fn, compile_s = self._compiled(key, args, dev, mesh)
        out = jax.device_get(fn(*args))
        _STATS["calls"] += 1
        return _result(problem, out, shape, self.max_iter, compile_s, t0)


def _result(problem, out, shape, max_iter, compile_s, t0):
    q = np.asarray(out["q"], dtype=float).reshape(shape)
    w = np.asarray(out["w"], dtype=float).reshape(shape)
    r = np.asarray(out["r"], dtype=float)
    it, status, rmax = int(out["it"]), int(out["status"]), float(out["rmax"])
    capped = False
    if status == 4:
        ok, msg = False, "line search failed"
    elif not np.isfinite(rmax):
        ok, msg = False, "non-finite residual"
    elif bool(out["converged"]):
        ok, msg = True, "converged"
    else:
        ok, msg, capped = False, f"not converged in {max_iter} iterations", True
    if compile_s > 0:
        msg += f" (compiled in {compile_s:.1f} s)"
    H = problem.g0 + w - 1.0
    return Equilibrium(State(q, w), H, np.asarray(out["P"], dtype=float).reshape(shape),
                       float(np.max(np.abs(r))), ok, it, int(out["n_conv"]), float(out["E"]),
                       time.perf_counter() - t0, msg, capped)


SOLVERS.register("jax", JaxSolver, summary="the fast solver compiled with JAX (GPU if JAX has one, else CPU)")
def gpu_solver(tol: float = SOLVER_TOL, **kw) -> JaxSolver:
    """The JAX solver on a GPU (TengsimError, one line, when JAX has none)."""
    return JaxSolver(tol=tol, **{"device": "gpu", "name": "gpu", **kw})


gpu_solver.compiles = True  # as JaxSolver


SOLVERS.register("gpu", gpu_solver, summary="the fast solver compiled with JAX on a GPU (pip install 'tengsim[gpu]')")
