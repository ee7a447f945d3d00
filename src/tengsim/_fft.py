"""The one seam to the FFT backend (``scipy.fft`` with worker threads)."""
from __future__ import annotations

import os

import scipy.fft as _sfft

_ENV = os.environ.get("TENGSIM_FFT_WORKERS")
# Threads pay off only for large transforms (measured on 2 cores: a 384² pair is ~2× slower with 2
# threads, a 2048² pair ~1.5× faster); TENGSIM_FFT_WORKERS forces a count.
THREAD_MIN_SIZE = 512 * 512


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
