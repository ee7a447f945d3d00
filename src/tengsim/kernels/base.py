"""Pieces every elastic kernel shares: the exact pixel influence of the half-space and the factory."""
from __future__ import annotations

import numpy as np

from tengsim.grid import Grid
from tengsim.registry import KERNELS


def _F(x, y):
    """Antiderivative of 1/sqrt(x² + y²) in x and y: x asinh(y/|x|) + y asinh(x/|y|).

    (= x ln(y + r) + y ln(x + r) up to terms in x or y alone, which cancel in a double difference.)
    """
    ax, ay = np.abs(x), np.abs(y)
    a = x * np.arcsinh(y / np.where(ax > 0, ax, 1.0))
    b = y * np.arcsinh(x / np.where(ay > 0, ay, 1.0))
    return a + b


def pixel_influence(x, y, dx: float, dy: float) -> np.ndarray:
    """∬ over the pixel [−dx/2, dx/2]×[−dy/2, dy/2] of 1/|r − r'|, at offsets (x, y)."""
    a, b = dx / 2, dy / 2
    return _F(x + a, y + b) - _F(x + a, y - b) - _F(x - a, y + b) + _F(x - a, y - b)


def make_kernel(boundary: str, grid: Grid, coupling: float, **params):
    """Kernel by registered name (see ``tengsim.registry.KERNELS``): 'free' (isolated cell, Eq. 9 as
    printed) or 'periodic' (array of cells); both take ``thickness``, ``substrate``, ``poisson`` for a
    film on a rigid substrate.  A registered kernel is a factory ``(grid, coupling, **params) -> kernel``."""
    return KERNELS.get(boundary)(grid, coupling, **params)
