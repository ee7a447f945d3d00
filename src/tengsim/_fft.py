"""The one seam to the FFT backend (``scipy.fft`` with worker threads).

The kernels' convolvers run on scipy's own pocketfft binding (no dispatch overhead per call) where
the installed scipy has it and it agrees with the public ``scipy.fft`` on a test field; else on the
public functions, which are slower on small grids (measured, one convolution: group A's 39² free cell
90 vs 186 µs, a 256² periodic cell 1.3 vs 3.3 ms, on a loaded 2-core VM).
:data:`BACKEND` says which path the convolvers use (``"pocketfft"`` or ``"scipy.fft"``); the first
fall-back in a process is reported once as a :class:`FFTBackendWarning`.
"""
from __future__ import annotations

import os
import threading
import warnings

import numpy as np
import scipy.fft as _sfft

try:  # scipy's own pocketfft binding: the same transforms without the ~15 µs of dispatch per call
    from scipy.fft._pocketfft import pypocketfft as _pp
except Exception:  # pragma: no cover - a scipy without it: the public functions are used
    _pp = None

#: the convolvers' path: "pocketfft" (scipy's binding, direct) or "scipy.fft" (the public functions)
BACKEND = "pocketfft" if _pp is not None else "scipy.fft"
_warned = False


class FFTBackendWarning(RuntimeWarning):
    """The convolutions run on the slower public scipy.fft path."""


def _fall_back(reason: str) -> None:
    """Record that a convolver uses the public path; warn once per process."""
    global BACKEND, _warned
    BACKEND = "scipy.fft"
    if not _warned:
        _warned = True
        warnings.warn(f"tengsim: FFT convolutions fall back to the public scipy.fft functions ({reason}); "
                      "results are the same, small grids run slower", FFTBackendWarning, stacklevel=4)

_ENV = os.environ.get("TENGSIM_FFT_WORKERS")
# Threads pay off only for large transforms (measured on 2 cores: a 384² pair is ~2× slower with 2
# threads, a 2048² pair ~1.5× faster); TENGSIM_FFT_WORKERS forces a count.
THREAD_MIN_SIZE = 512 * 512


def _threads(shape) -> int:
    w = _workers(shape)
    return os.cpu_count() or 1 if w < 0 else w


def _workers(shape) -> int:
    if _ENV:
        return int(_ENV)
    n = 1
    for k in shape:
        n *= int(k)
    return -1 if n >= THREAD_MIN_SIZE else 1


def rfft2(a, s=None):
    return _sfft.rfft2(a, s=s, workers=_workers(s or a.shape))


def irfft2(a, s):
    return _sfft.irfft2(a, s=s, workers=_workers(s))


def convolve_periodic(a, spectrum):
    """irfft2(rfft2(a) · spectrum), one axis at a time, transforming in place where possible.

    (scipy's irfft2 copies its input; the axis-by-axis form measured ~25 % faster at 1024²–2048².)
    """
    s = a.shape
    w = _workers(s)
    b = _sfft.rfft(a, axis=1, workers=w)
    b = _sfft.fft(b, axis=0, workers=w, overwrite_x=True)
    b *= spectrum
    b = _sfft.ifft(b, axis=0, workers=w, overwrite_x=True)
    return _sfft.irfft(b, n=s[1], axis=1, workers=w)


def fast_len(n: int) -> int:
    """Smallest size >= n whose prime factors are 2, 3, 5 (and 7, 11, as scipy allows)."""
    return _sfft.next_fast_len(int(n), real=True)


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


def rfft2_padded(a, s):
    """rfft2 of ``a`` zero-padded to shape ``s``, skipping the transforms of all-zero rows."""
    w = _workers(s)
    b = _sfft.rfft(a, n=s[1], axis=1, workers=w)
    return _sfft.fft(b, n=s[0], axis=0, workers=w, overwrite_x=True)


def irfft2_cropped(spec, s, out):
    """irfft2 to shape ``s``, computing only the leading ``out`` = (rows, cols) block."""
    w = _workers(s)
    b = _sfft.ifft(spec, axis=0, workers=w, overwrite_x=True)[: out[0]]
    return _sfft.irfft(b, n=s[1], axis=1, workers=w)[:, : out[1]]


def _getstate(self):
    st = dict(self.__dict__)
    del st["_tls"]  # per-thread buffers are not pickled; they are made again on first use
    return st


def _setstate(self, st):
    self.__dict__.update(st)
    self._tls = threading.local()


def _checked(conv, shape) -> bool:
    """Does the direct pocketfft path of ``conv`` agree with the public scipy.fft one?"""
    try:
        x = np.random.default_rng(0).standard_normal(shape)
        return bool(np.allclose(conv._apply_direct(x), conv._apply_public(x), rtol=1e-12, atol=1e-12))
    except Exception:  # pragma: no cover - an incompatible private binding
        return False


def _use_direct(conv, shape) -> bool:
    """Can ``conv`` run on the pocketfft binding?  If not, say so (:func:`_fall_back`)."""
    if _pp is None:
        _fall_back("scipy.fft._pocketfft.pypocketfft is not importable")
        return False
    if not _checked(conv, shape):
        _fall_back("scipy's pocketfft binding disagrees with scipy.fft on a test field")
        return False
    return True


class PaddedConvolver:
    """w = crop(irfft2(rfft2(pad(p)) · spectrum)): the free kernel's convolution, one object per grid.

    Pads the (nx, ny) field to ``padded`` = (px, py), transforms only the nx rows that are not zero
    (axis 1, real), then all px rows (axis 0), and back, keeping only the nx × ny block.  Runs on
    scipy's pocketfft binding with preallocated buffers where the installed scipy has it (checked
    against the public ``scipy.fft`` once), else on the public functions; the two agree to round-off.
    """

    def __init__(self, shape, padded, spectrum):
        self.shape, self.padded = tuple(shape), tuple(padded)
        self.spectrum = spectrum
        self.threads = _threads(self.padded)
        nx, _ = self.shape
        px, py = self.padded
        self._tls = threading.local()  # buffers per thread: one kernel may serve several threads
        self._direct = _use_direct(self, self.shape)

    def _apply_public(self, p):
        spec = rfft2_padded(p, self.padded)
        spec *= self.spectrum
        return np.ascontiguousarray(irfft2_cropped(spec, self.padded, self.shape))

    __getstate__ = _getstate
    __setstate__ = _setstate

    @property
    def backend(self) -> str:
        return "pocketfft" if self._direct else "scipy.fft"

    def _buffers(self):
        b = getattr(self._tls, "b", None)
        if b is None:
            nx, _ = self.shape
            px, py = self.padded
            b = self._tls.b = (np.zeros((nx, py)), np.zeros((px, py // 2 + 1), complex), np.empty((nx, py)))
        return b

    def _apply_direct(self, p):
        nx, ny = self.shape
        py = self.padded[1]
        t = self.threads
        rb, cb, out = self._buffers()
        rb[:, :ny] = p
        _pp.r2c(rb, (1,), True, 0, cb[:nx], t)
        cb[nx:] = 0.0
        _pp.c2c(cb, (0,), True, 0, cb, t)
        cb *= self.spectrum
        _pp.c2c(cb, (0,), False, 2, cb, t)
        _pp.c2r(cb[:nx], (1,), py, False, 2, out, t)
        return out[:, :ny]

    def __call__(self, p, out=None):
        """K p into ``out`` (a new array when None)."""
        w = self._apply_direct(p) if self._direct else self._apply_public(p)
        if out is None:
            return w.copy() if self._direct else w
        np.copyto(out, w)
        return out


class PeriodicConvolver:
    """w = irfft2(rfft2(p) · spectrum) on a periodic cell, one object per grid.

    On scipy's pocketfft binding where available (checked against :func:`convolve_periodic` once):
    transforms in place in a per-thread spectrum buffer, the result written straight into ``out``
    (measured on 2 cores: 0.84 → 0.56 ms at 256², 14.7 → 9.7 ms at 1024², equal at 2048²).
    """

    def __init__(self, shape, spectrum):
        self.shape = tuple(shape)
        self.spectrum = spectrum
        self.threads = _threads(self.shape)
        self._tls = threading.local()
        self._direct = _use_direct(self, self.shape)

    __getstate__ = _getstate
    __setstate__ = _setstate

    @property
    def backend(self) -> str:
        return "pocketfft" if self._direct else "scipy.fft"

    def _apply_public(self, p):
        return convolve_periodic(p, self.spectrum)

    def _apply_direct(self, p, out=None):
        cb = getattr(self._tls, "cb", None)
        if cb is None:
            cb = self._tls.cb = np.empty(self.spectrum.shape, complex)
        t = self.threads
        _pp.r2c(np.ascontiguousarray(p, dtype=float), (1,), True, 0, cb, t)
        _pp.c2c(cb, (0,), True, 0, cb, t)
        cb *= self.spectrum
        _pp.c2c(cb, (0,), False, 2, cb, t)
        if out is None:
            out = np.empty(self.shape)
        _pp.c2r(cb, (1,), self.shape[1], False, 2, out, t)
        return out

    def __call__(self, p, out=None):
        """K p into ``out`` (a new array when None)."""
        if self._direct:
            return self._apply_direct(p, out)
        w = self._apply_public(p)
        if out is None:
            return w
        np.copyto(out, w)
        return out
