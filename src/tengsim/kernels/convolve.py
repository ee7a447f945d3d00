"""The convolvers of the elastic kernels: w = K p by FFT, one object per grid.

:class:`PaddedConvolver` (free cell: zero-padded, cropped), :class:`PeriodicConvolver` (periodic cell);
the mirror-symmetric one is :class:`tengsim.kernels.dct.MirrorConvolver`.  Each runs on the seam's
direct transforms (scipy's pocketfft binding, :mod:`tengsim.backend.fft`) with per-thread buffers where
they agree with the public scipy.fft path on a test field (checked once per convolver), else on the
public path; the two agree to round-off.  Per-thread buffers are not pickled (dask workers pickle kernels).
"""
from __future__ import annotations

import threading

import numpy as np

from tengsim.backend import fft as _bf
from tengsim.backend import threads as _threads
from tengsim.backend import workers as _workers


def convolve_periodic(a, spectrum):
    """irfft2(rfft2(a) · spectrum), one axis at a time, transforming in place where possible.

    (scipy's irfft2 copies its input; the axis-by-axis form does not.)
    """
    s = a.shape
    w = _workers(s)
    b = _bf.rfft(a, axis=1, workers=w)
    b = _bf.fft(b, axis=0, workers=w, overwrite_x=True)
    b *= spectrum
    b = _bf.ifft(b, axis=0, workers=w, overwrite_x=True)
    return _bf.irfft(b, n=s[1], axis=1, workers=w)


def rfft2_padded(a, s):
    """rfft2 of ``a`` zero-padded to shape ``s``, skipping the transforms of all-zero rows."""
    w = _workers(s)
    b = _bf.rfft(a, n=s[1], axis=1, workers=w)
    return _bf.fft(b, n=s[0], axis=0, workers=w, overwrite_x=True)


def irfft2_cropped(spec, s, out):
    """irfft2 to shape ``s``, computing only the leading ``out`` = (rows, cols) block."""
    w = _workers(s)
    b = _bf.ifft(spec, axis=0, workers=w, overwrite_x=True)[: out[0]]
    return _bf.irfft(b, n=s[1], axis=1, workers=w)[:, : out[1]]


def _getstate(self):
    st = dict(self.__dict__)
    del st["_tls"]  # per-thread buffers are not pickled; they are made again on first use
    return st


def _setstate(self, st):
    self.__dict__.update(st)
    self._tls = threading.local()


class _Convolver:
    """What every convolver shares: per-thread buffers that are not pickled, and its backend's name."""

    __getstate__ = _getstate
    __setstate__ = _setstate

    @property
    def backend(self) -> str:
        """"pocketfft" (scipy's binding, direct) or "scipy.fft" (the public functions)."""
        return "pocketfft" if self._direct else "scipy.fft"


class _IntoConvolver(_Convolver):
    """A convolver whose direct path writes into ``out`` itself (periodic, mirror)."""

    def __call__(self, p, out=None):
        """K p into ``out`` (a new array when None)."""
        if self._direct:
            return self._apply_direct(p, out)
        w = self._apply_public(p)
        if out is None:
            return w
        np.copyto(out, w)
        return out


def _checked(conv, shape) -> bool:
    """Does the direct pocketfft path of ``conv`` agree with the public scipy.fft one?"""
    try:
        x = np.random.default_rng(0).standard_normal(shape)
        return bool(np.allclose(conv._apply_direct(x), conv._apply_public(x), rtol=1e-12, atol=1e-12))
    except Exception:  # pragma: no cover - an incompatible private binding
        return False


def _use_direct(conv, shape) -> bool:
    """Can ``conv`` run on the pocketfft binding?  If not, say so (:func:`tengsim.backend.fft.fall_back`)."""
    if not _bf.has_direct():
        _bf.fall_back("scipy.fft._pocketfft.pypocketfft is not importable")
        return False
    if not _checked(conv, shape):
        _bf.fall_back("scipy's pocketfft binding disagrees with scipy.fft on a test field")
        return False
    return True


class PaddedConvolver(_Convolver):
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
        _bf.r2c(rb, 1, cb[:nx], t)
        cb[nx:] = 0.0
        _bf.c2c(cb, 0, True, 0, cb, t)
        cb *= self.spectrum
        _bf.c2c(cb, 0, False, 2, cb, t)
        _bf.c2r(cb[:nx], 1, py, 2, out, t)
        return out[:, :ny]

    def __call__(self, p, out=None):
        """K p into ``out`` (a new array when None)."""
        w = self._apply_direct(p) if self._direct else self._apply_public(p)
        if out is None:
            return w.copy() if self._direct else w
        np.copyto(out, w)
        return out


class PeriodicConvolver(_IntoConvolver):
    """w = irfft2(rfft2(p) · spectrum) on a periodic cell, one object per grid.

    On scipy's pocketfft binding where available (checked against :func:`convolve_periodic` once):
    transforms in place in a per-thread spectrum buffer, the result written straight into ``out``.
    """

    def __init__(self, shape, spectrum):
        self.shape = tuple(shape)
        self.spectrum = spectrum
        self.threads = _threads(self.shape)
        self._tls = threading.local()
        self._direct = _use_direct(self, self.shape)

    def _apply_public(self, p):
        return convolve_periodic(p, self.spectrum)

    def _apply_direct(self, p, out=None):
        cb = getattr(self._tls, "cb", None)
        if cb is None:
            cb = self._tls.cb = np.empty(self.spectrum.shape, complex)
        t = self.threads
        _bf.r2c(np.ascontiguousarray(p, dtype=float), 1, cb, t)
        _bf.c2c(cb, 0, True, 0, cb, t)
        cb *= self.spectrum
        _bf.c2c(cb, 0, False, 2, cb, t)
        if out is None:
            out = np.empty(self.shape)
        _bf.c2r(cb, 1, self.shape[1], 2, out, t)
        return out
