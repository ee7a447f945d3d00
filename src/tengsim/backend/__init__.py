"""The seam for the NumPy solvers' arrays and FFTs: every array the NumPy solvers (fast, vsr, homotopy, the
mirror and MPI kernels) allocate and every Fourier transform they and the kernels' builds make goes through
here (NumPy arrays, scipy's pocketfft).  The JAX solver (tengsim.solvers.jax_fast) does not: its loop is one
compiled program on its device, with ``jnp.fft`` inside it (tengsim.solvers._jax_fft); it takes from a
kernel only its spectrum and padded shape (tengsim.registry.FourierKernelLike), built here on the host.

- the array namespace :data:`xp` and its allocators :func:`empty`, :func:`zeros`; the small solve
  :func:`solve_upper` (the L-BFGS memory's triangular systems, on backend arrays); :func:`sync` brings
  a sweep's reductions (backend scalars, small arrays) to the host in one transfer, :func:`to_host` one
  scalar: the only places a solve waits for the device;
- the thread policy :func:`workers` / :func:`threads` (``TENGSIM_FFT_WORKERS`` forces a count);
- FFT-friendly lengths :func:`fast_len`, :func:`fast_odd_len`;
- the transforms (:mod:`tengsim.backend.fft`): the direct ``r2c``/``c2c``/``c2r``/``dct`` writing into
  ``out`` (scipy's pocketfft binding), the public scipy.fft functions they fall back to, and NumPy's
  own transforms where a result is defined by them (surface synthesis, resampling).
"""
from __future__ import annotations

import numpy as np
from scipy.linalg.lapack import dtrtrs

from tengsim.backend import fft
from tengsim.backend.fft import THREAD_MIN_SIZE, FFTBackendWarning, threads, workers

#: the array namespace
xp = np

def empty(shape, dtype=float):
    """An uninitialised backend array."""
    return xp.empty(shape, dtype=dtype)


def zeros(shape, dtype=float):
    """A zero-filled backend array."""
    return xp.zeros(shape, dtype=dtype)


def sync(scalars, tail=None):
    """Backend scalars (then the entries of the small array ``tail``, if given) as one host float64
    array: one transfer, stacked on the device first.  The solvers gather the scalars a sweep over the
    grid produced and call this once per sweep, never once per scalar."""
    a = xp.array(scalars, dtype=float)
    if tail is not None:
        a = xp.concatenate((a, xp.ravel(xp.asarray(tail, dtype=float))))
    return np.asarray(a)


def to_host(x) -> float:
    """A backend scalar as a host float (one transfer: :func:`sync` of one value)."""
    return float(sync((x,))[0])


def solve_upper(a, b, trans=False):
    """x with U x = b (``trans``: Uᵀ x = b), U the upper triangle of the small square backend array ``a``
    (its lower triangle is not read): LAPACK's trtrs for NumPy (scipy's solve_triangular costs ~10× more
    on these tiny systems).  A zero pivot is not checked: x is then meaningless (LAPACK leaves b)."""
    return dtrtrs(a, b, lower=0, trans=int(bool(trans)))[0]


def fast_len(n: int) -> int:
    """Smallest size >= n whose prime factors are 2, 3, 5 (and 7, 11, as scipy allows)."""
    return fft.next_fast_len(int(n))


def fast_odd_len(n: int) -> int:
    """Smallest odd size >= n with prime factors 3, 5, 7, 11, 13 only (an FFT-friendly odd count)."""
    m = max(3, int(n) | 1)
    while True:
        k = m
        for p in (3, 5, 7, 11, 13):
            while k % p == 0:
                k //= p
        if k == 1:
            return m
        m += 2


__all__ = ["FFTBackendWarning", "THREAD_MIN_SIZE", "empty", "fast_len", "fast_odd_len", "fft", "threads",
           "solve_upper", "sync", "to_host", "workers", "xp", "zeros"]
