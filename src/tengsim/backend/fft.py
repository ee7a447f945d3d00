"""The transforms of the seam, and their thread policy.

Direct path: scipy's own pocketfft binding, called without scipy.fft's per-call dispatch (the costs
measured: docs/benchmarks.md), writing into ``out``: :func:`r2c`, :func:`c2c`,
:func:`c2r`, :func:`dct`.  :func:`has_direct` says whether the binding is importable; a convolver that
cannot use it calls :func:`fall_back`, which sets :data:`BACKEND` to ``"scipy.fft"`` and warns once per
process (:class:`FFTBackendWarning`).  Public path: scipy.fft's functions (``workers=`` threads).
NumPy's own transforms (``np_*``) serve where a result is defined by them (surface synthesis,
spectral resampling), so that their values stay what they were.
"""
from __future__ import annotations

import os
import warnings

import numpy as np
import scipy.fft as _sfft

try:  # scipy's own pocketfft binding: the same transforms without the dispatch per call
    from scipy.fft._pocketfft import pypocketfft as _pp
except Exception:  # pragma: no cover - a scipy without it: the public functions are used
    _pp = None

#: the convolvers' path: "pocketfft" (scipy's binding, direct) or "scipy.fft" (the public functions)
BACKEND = "pocketfft" if _pp is not None else "scipy.fft"
_warned = False

#: transforms of at least this many points use all cores, smaller ones one thread (threads pay off only
#: for large transforms); ``TENGSIM_FFT_WORKERS`` forces a count
THREAD_MIN_SIZE = 512 * 512
_ENV = os.environ.get("TENGSIM_FFT_WORKERS")


class FFTBackendWarning(RuntimeWarning):
    """The convolutions run on the slower public scipy.fft path."""


def has_direct() -> bool:
    """Is scipy's pocketfft binding importable?"""
    return _pp is not None


def fall_back(reason: str) -> None:
    """Record that a convolver uses the public path; warn once per process."""
    global BACKEND, _warned
    BACKEND = "scipy.fft"
    if not _warned:
        _warned = True
        warnings.warn(f"tengsim: FFT convolutions fall back to the public scipy.fft functions ({reason}); "
                      "results are the same, small grids run slower", FFTBackendWarning, stacklevel=4)


def workers(shape) -> int:
    """scipy.fft ``workers`` for a transform over ``shape``: 1, or −1 (all cores) from 512² points on."""
    if _ENV:
        return int(_ENV)
    n = 1
    for k in shape:
        n *= int(k)
    return -1 if n >= THREAD_MIN_SIZE else 1


def threads(shape) -> int:
    """The thread count of the direct transforms over ``shape`` (:func:`workers`, −1 as the core count)."""
    w = workers(shape)
    return os.cpu_count() or 1 if w < 0 else w


def next_fast_len(n: int) -> int:
    return _sfft.next_fast_len(int(n), real=True)


# ---- direct path (scipy's pocketfft binding), each writing into ``out`` ----------------------------
def r2c(a, axis: int, out, threads: int, forward: bool = True, norm: int = 0):
    """Real-to-complex FFT of ``a`` along ``axis`` into ``out``."""
    return _pp.r2c(a, (axis,), forward, norm, out, threads)


def c2c(a, axis: int, forward: bool, norm: int, out, threads: int):
    """Complex FFT along ``axis`` into ``out`` (``out`` may be ``a``); norm 2: divide by the length."""
    return _pp.c2c(a, (axis,), forward, norm, out, threads)


def c2r(a, axis: int, n: int, norm: int, out, threads: int):
    """Inverse complex-to-real FFT to ``n`` points along ``axis`` into ``out``."""
    return _pp.c2r(a, (axis,), n, False, norm, out, threads)


def dct(a, type: int, axis: int, out, threads: int):
    """Unnormalised DCT of ``type`` along ``axis`` into ``out`` (``out`` may be ``a``)."""
    return _pp.dct(a, type, (axis,), 0, out, threads)


# ---- public path (scipy.fft) ---------------------------------------------------------------------
rfft, irfft, fft, ifft, scipy_dct = _sfft.rfft, _sfft.irfft, _sfft.fft, _sfft.ifft, _sfft.dct


def rfft2(a, s=None):
    """2-D real FFT (to shape ``s``), threads by the policy."""
    return _sfft.rfft2(a, s=s, workers=workers(s or a.shape))


def irfft2(a, s):
    """2-D inverse real FFT to shape ``s``, threads by the policy."""
    return _sfft.irfft2(a, s=s, workers=workers(s))


# ---- NumPy's own transforms and frequencies --------------------------------------------------------
np_fft2, np_ifft2, np_rfft2, np_irfft2 = np.fft.fft2, np.fft.ifft2, np.fft.rfft2, np.fft.irfft2
fftfreq, rfftfreq = np.fft.fftfreq, np.fft.rfftfreq
