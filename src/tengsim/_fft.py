"""The one seam to the FFT backend (``scipy.fft`` with worker threads)."""
from __future__ import annotations

import os

import scipy.fft as _sfft

WORKERS = int(os.environ.get("TENGSIM_FFT_WORKERS", "-1"))


def rfft2(a, s=None):
    return _sfft.rfft2(a, s=s, workers=WORKERS)


def irfft2(a, s):
    return _sfft.irfft2(a, s=s, workers=WORKERS)


def fast_len(n: int) -> int:
    """Smallest size >= n whose prime factors are 2, 3, 5 (and 7, 11, as scipy allows)."""
    return _sfft.next_fast_len(int(n), real=True)
