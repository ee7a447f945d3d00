"""Elastic half-space kernels: displacement w = K P of the surface under pressure P (Eq. 9).

In the dimensionless form of Eq. (9), w(X) = (κ/π) ∬ P(X')/|X − X'| dX' with coupling κ = μ^{3/2}.
A kernel's ``apply`` is one convolution (a forward and an inverse real FFT): the unit of cost.

* :class:`FreeKernel` — an isolated cell on a half-space, exactly the paper's Eq. (9): linear
  convolution by zero padding, with the exact influence coefficients of a uniformly loaded
  rectangular pixel (Love 1929; Johnson 1985 §3.3).
* :class:`PeriodicKernel` — an infinite array of cells: Fourier multiplier 2κ/|q|, the mean
  displacement (q = 0) held at zero, so D is measured from the mean surface.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from tengsim import _fft
from tengsim.errors import positive
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


@dataclass
class FreeKernel:
    """Isolated cell (non-periodic) half-space, paper Eq. (9)."""

    grid: Grid
    coupling: float
    padded_shape: tuple = field(init=False)

    def __post_init__(self):
        positive("coupling", self.coupling)
        g = self.grid
        self.padded_shape = (_fft.fast_len(2 * g.nx - 1), _fft.fast_len(2 * g.ny - 1))
        px, py = self.padded_shape
        ix = np.arange(px)
        iy = np.arange(py)
        ox = np.where(ix < g.nx, ix, ix - px) * g.dx
        oy = np.where(iy < g.ny, iy, iy - py) * g.dy
        X, Y = np.meshgrid(ox, oy, indexing="ij")
        coeff = pixel_influence(X, Y, g.dx, g.dy) * (self.coupling / np.pi)
        self._spectrum = _fft.rfft2(coeff)
        self._conv = _fft.PaddedConvolver(g.shape, self.padded_shape, self._spectrum)
        self.periodic = False

    def apply(self, p: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
        """w = K p on the cell (one convolution), into ``out`` if given."""
        return self._conv(np.asarray(p, dtype=float), out)

    def params(self) -> dict:
        return {"boundary": "free", "coupling": self.coupling}


@dataclass
class PeriodicKernel:
    """Periodic array of cells: ŵ(q) = (2κ/|q|) P̂(q), ŵ(0) = 0."""

    grid: Grid
    coupling: float

    def __post_init__(self):
        positive("coupling", self.coupling)
        g = self.grid
        qx = 2 * np.pi * np.fft.fftfreq(g.nx, d=g.dx)
        qy = 2 * np.pi * np.fft.rfftfreq(g.ny, d=g.dy)
        q = np.hypot(*np.meshgrid(qx, qy, indexing="ij"))
        with np.errstate(divide="ignore"):
            mult = np.where(q > 0, 2 * self.coupling / np.where(q > 0, q, 1.0), 0.0)
        self._spectrum = mult
        self._conv = _fft.PeriodicConvolver(g.shape, mult)
        self.padded_shape = g.shape
        self.periodic = True

    def apply(self, p: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
        """w = K p (one convolution), into ``out`` if given."""
        return self._conv(p, out)

    def params(self) -> dict:
        return {"boundary": "periodic", "coupling": self.coupling}


def make_kernel(boundary: str, grid: Grid, coupling: float, **params):
    """Kernel by registered name (see ``tengsim.registry.KERNELS``): 'free' (isolated cell, Eq. 9 as
    printed) or 'periodic' (array of cells).  A registered kernel is a factory
    ``(grid, coupling, **params) -> kernel``."""
    return KERNELS.get(boundary)(grid, coupling, **params)


KERNELS.register("free", FreeKernel, summary="isolated cell on a half-space, Eq. (9)")
KERNELS.register("periodic", PeriodicKernel, summary="periodic array of cells")
