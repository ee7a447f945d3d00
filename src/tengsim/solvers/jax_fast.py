"""The fast solver compiled with JAX: the same L-BFGS, end to end in one jit-compiled loop, on a GPU or a CPU.

:class:`JaxSolver` runs the algorithm of :class:`tengsim.solvers.FastSolver` (traced in
tengsim.solvers._jax_loop) as one ``lax.while_loop``: no Python between iterations, every array on the
device, the convolution ``jnp.fft`` inside the compiled program.  It therefore sits beside the
package's FFT seam (tengsim.backend.fft, which serves NumPy arrays to scipy's pocketfft on the host) rather
than in it: a JAX array inside a traced loop cannot go through a host FFT, and the kernels' spectra are
all the loop takes from them.  Any kernel that multiplies in Fourier space runs: the free cell (zero
padded), the periodic one and both with a film; the mirror-block kernel (a DCT-I, which JAX lacks) is
refused ("mirror kernel is CPU only"), and so is a slab-distributed (MPI) kernel.  Every law whose
``_raw`` takes an array namespace ``xp`` (all the built-in ones) runs, its parameters traced.

Registered solvers: ``jax`` (JAX's default device: the GPU when JAX has one, else the CPU) and
``gpu`` (a GPU or a one-line error), both float64; ``JaxSolver(dtype="float32")`` from the API.
Results equal the NumPy solver's: in float64 step for step to round-off, and where round-off grows
(a long path, an adhesive rough surface) the same equilibria to the tolerance (tests/test_jax_solver.py).
float32 fields (scalars still accumulated in float64, the rows' products and the law in float32): the
tolerance is raised to ``F32_TOL`` (2e-5) at least; float32 is for soft laws and for memory (how close
each precision comes, and the bytes per point: docs/benchmarks.md, "GPU").

Compilation: one per static configuration (grid shape, kernel kind, law class, dtype, memory, resync,
device), cached in this module and shared by every solver object and every equilibrium of a path; D
(through g0), the law's parameters, the kernel's spectrum, tol and max_iter are traced arguments.
:func:`compile_stats` reports how many compilations were made and how long they took; each
equilibrium's ``message`` names the compile time it paid (0 when cached).

JAX is imported only when a JaxSolver is made: ``import tengsim`` does not import it.
"""
from __future__ import annotations

import dataclasses
import inspect
import threading
import time
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from tengsim.errors import TengsimError
from tengsim.laws.safe import SafeLaw
from tengsim.registry import SOLVERS
from tengsim.solvers.types import Equilibrium, Problem, State

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


def _jax():
    """jax, with float64 enabled; a one-line TengsimError when it is not installed."""
    try:
        import jax
    except ImportError:
        raise TengsimError(f"the jax solver needs JAX, which is not installed: {INSTALL}") from None
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
        raise TengsimError(f"device {device!r}: JAX finds no {device.upper()} (it has: {have}); install JAX with "
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
    if hasattr(kernel, "mirror") or type(kernel).__name__ == "MirrorKernel":
        raise TengsimError("mirror kernel is CPU only (JAX has no DCT-I): use --symmetry off with the jax solver")
    spec = getattr(kernel, "_spectrum", None)
    padded = getattr(kernel, "padded_shape", None)
    if spec is None or padded is None or not hasattr(kernel, "periodic"):
        raise TengsimError(f"kernel {type(kernel).__name__} does not multiply in Fourier space: the jax solver "
                           f"cannot run it; use --solver fast")
    periodic = bool(kernel.periodic)
    pinned = bool(getattr(kernel, "pinned_mean", periodic))
    return periodic, tuple(int(n) for n in padded), spec, pinned


@dataclass(frozen=True)
class JaxSolver:
    """The fast solver (L-BFGS in the K metric, Wolfe line search) compiled with JAX (module docstring).

    ``device``: 'auto' (JAX's default), 'cpu' or 'gpu'; ``dtype``: 'float64' or 'float32' (the fields;
    scalars stay float64).  Same interface and result (host NumPy arrays) as FastSolver."""

    tol: float = 1e-6
    max_iter: int = 3000
    memory: int = 10
    resync: int = 25
    device: str = "auto"
    dtype: str = "float64"
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
        if self.dtype not in DTYPES:
            raise TengsimError(f"dtype must be one of {', '.join(DTYPES)}, got {self.dtype!r}")
        find_device(self.device)  # the one-line error now, before a run writes anything

    @property
    def effective_tol(self) -> float:
        return self.tol if self.dtype == "float64" else max(self.tol, F32_TOL)

    def _compiled(self, key, args, dev):
        with _LOCK:
            fn = _CACHE.get(key)
        if fn is not None:
            return fn, 0.0
        jax = _jax()
        from tengsim.solvers import _jax_loop

        shape, padded, periodic, pinned, cls, names, dtype, memory, resync, _ = key
        solve = _jax_loop.build(shape, padded, periodic, pinned, cls, names, dtype, memory, resync)
        t0 = time.perf_counter()
        with jax.default_device(dev):
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
        put = lambda a: jax.device_put(np.ascontiguousarray(a, dtype=dtype).ravel(), dev)  # noqa: E731
        f64 = lambda v: jax.device_put(np.float64(v), dev)  # noqa: E731
        args = (put(g0), put(start.q), put(start.w), self._spectrum(problem.kernel, spec, dtype, dev),
                tuple(f64(v) for v in values), f64(self.effective_tol), jax.device_put(np.int32(self.max_iter), dev),
                f64(problem.dA), f64(g0.size))
        key = (shape, padded, periodic, pinned, cls, names, dtype, int(self.memory), int(self.resync), str(dev))
        fn, compile_s = self._compiled(key, args, dev)
        out = jax.device_get(fn(*args))
        _STATS["calls"] += 1
        return _result(problem, out, shape, self.max_iter, compile_s, t0)


def _result(problem, out, shape, max_iter, compile_s, t0):
    q = np.asarray(out["q"], dtype=float).reshape(shape)
    w = np.asarray(out["w"], dtype=float).reshape(shape)
    r = np.asarray(out["r"], dtype=float)
    it, status, rmax = int(out["it"]), int(out["status"]), float(out["rmax"])
    if status == 4:
        ok, msg = False, "line search failed"
    elif not np.isfinite(rmax):
        ok, msg = False, "non-finite residual"
    elif bool(out["converged"]):
        ok, msg = True, "converged"
    else:
        ok, msg = False, f"not converged in {max_iter} iterations"
    if compile_s > 0:
        msg += f" (compiled in {compile_s:.1f} s)"
    H = problem.g0 + w - 1.0
    return Equilibrium(State(q, w), H, np.asarray(out["P"], dtype=float).reshape(shape),
                       float(np.max(np.abs(r))), ok, it, int(out["n_conv"]), float(out["E"]),
                       time.perf_counter() - t0, msg)


SOLVERS.register("jax", JaxSolver, summary="the fast solver compiled with JAX (GPU if JAX has one, else CPU)")
def gpu_solver(tol: float = 1e-6, **kw) -> JaxSolver:
    """The JAX solver on a GPU (TengsimError, one line, when JAX has none)."""
    return JaxSolver(tol=tol, **{"device": "gpu", "name": "gpu", **kw})


gpu_solver.compiles = True  # as JaxSolver


SOLVERS.register("gpu", gpu_solver, summary="the fast solver compiled with JAX on a GPU (pip install 'tengsim[gpu]')")
