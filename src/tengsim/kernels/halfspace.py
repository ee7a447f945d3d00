"""Elastic half-space kernels: displacement w = K P of the surface under pressure P (Eq. 9).

In the dimensionless form of Eq. (9), w(X) = (κ/π) ∬ P(X')/|X − X'| dX' with coupling κ = μ^{3/2}.
A kernel's ``apply`` is one convolution (a forward and an inverse real FFT): the unit of cost.

* :class:`FreeKernel` — an isolated cell on a half-space, exactly the paper's Eq. (9): linear
  convolution by zero padding, with the exact influence coefficients of a uniformly loaded
  rectangular pixel (Love 1929; Johnson 1985 §3.3).
* :class:`PeriodicKernel` — an infinite array of cells: Fourier multiplier 2κ/|q|, the mean
  displacement (q = 0) held at zero, so D is measured from the mean surface.

Both take an optional film (``thickness`` T in X units, ``substrate`` 'bonded' or 'frictionless',
``poisson`` ν; :mod:`tengsim.kernels.film`): a layer of thickness T on a rigid substrate instead of the
half-space, E* keeping its meaning.  The periodic multiplier becomes (2κ/|q|) C(|q| T, ν) with the
finite mean compliance κT(1 − 2ν)/(1 − ν)² at q = 0; the free kernel adds to the exact half-space
pixel coefficients the layer's smooth correction (κ/π)(1/T) h(r/T), pixel-averaged by Gauss points
(:func:`film_pixel_correction`), which cancels them exactly beyond 40 thicknesses.  A kernel whose
mean mode has no compliance (the half-space, or an incompressible periodic film) says so with
``pinned_mean = True``; the solvers then hold the mean of q fixed.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from tengsim import backend
from tengsim.backend import fft as _bf
from tengsim.grid import Grid
from tengsim.kernels import film
from tengsim.kernels.convolve import PaddedConvolver, PeriodicConvolver
from tengsim.kernels.base import pixel_influence
from tengsim.kernels.film import _Film, film_pixel_correction
from tengsim.registry import KERNELS


@dataclass
class FreeKernel(_Film):
    """Isolated cell (non-periodic) half-space, paper Eq. (9); or a film of ``thickness`` T."""

    grid: Grid
    coupling: float
    thickness: float | None = None
    substrate: str = "bonded"
    poisson: float = 0.5
    padded_shape: tuple = field(init=False)

    def __post_init__(self):
        self._init_body()
        g = self.grid
        self.padded_shape = (backend.fast_len(2 * g.nx - 1), backend.fast_len(2 * g.ny - 1))
        px, py = self.padded_shape
        ix = np.arange(px)
        iy = np.arange(py)
        ox = np.where(ix < g.nx, ix, ix - px) * g.dx
        oy = np.where(iy < g.ny, iy, iy - py) * g.dy
        X, Y = np.meshgrid(ox, oy, indexing="ij")
        coeff = pixel_influence(X, Y, g.dx, g.dy)
        if self.film:
            coeff += film_pixel_correction(X, Y, g.dx, g.dy, self.thickness, self.poisson, self.substrate)
        coeff *= self.coupling / np.pi
        self._spectrum = _bf.rfft2(coeff)
        self._conv = PaddedConvolver(g.shape, self.padded_shape, self._spectrum)
        self.periodic = False
        self.pinned_mean = False

    @property
    def spectrum(self) -> np.ndarray:
        """K̂ on the rfft2 layout of the padded grid (:class:`tengsim.registry.FourierKernelLike`)."""
        return self._spectrum

    def apply(self, p: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
        """w = K p on the cell (one convolution), into ``out`` if given."""
        return self._conv(np.asarray(p, dtype=float), out)

    def params(self) -> dict:
        return {"boundary": "free", "coupling": self.coupling, **self.film_params()}


def periodic_multiplier(body, grid: Grid, cols: slice = slice(None)) -> np.ndarray:
    """The periodic kernel's Fourier multiplier on the rfft2 layout of ``grid`` (its ``cols`` of the
    last axis only): 2κ/|q|, times the film's C(|q| T, ν), mean mode 0 or the film's mean compliance.
    ``body``: an object with ``coupling`` and the film fields (``film``, ``thickness``, ``poisson``, ``substrate``)."""
    qx = 2 * np.pi * _bf.fftfreq(grid.nx, d=grid.dx)
    qy = (2 * np.pi * _bf.rfftfreq(grid.ny, d=grid.dy))[cols]
    q = np.hypot(*np.meshgrid(qx, qy, indexing="ij"))
    with np.errstate(divide="ignore"):
        mult = np.where(q > 0, 2 * body.coupling / np.where(q > 0, q, 1.0), 0.0)
    if body.film:
        mult *= film.compliance_factor(q * body.thickness, body.poisson, body.substrate)
        mult[q == 0] = film.mean_compliance(body.thickness, body.poisson, body.coupling)
    return mult


@dataclass
class PeriodicKernel(_Film):
    """Periodic array of cells: ŵ(q) = (2κ/|q|) P̂(q), ŵ(0) = 0; with a film of ``thickness`` T,
    ŵ(q) = (2κ/|q|) C(|q| T, ν) P̂(q) and ŵ(0) = κT(1 − 2ν)/(1 − ν)² P̂(0) (uniaxial strain)."""

    grid: Grid
    coupling: float
    thickness: float | None = None
    substrate: str = "bonded"
    poisson: float = 0.5

    def __post_init__(self):
        self._init_body()
        g = self.grid
        mult = periodic_multiplier(self, g)
        self.mean_compliance = float(mult[0, 0])
        self.pinned_mean = not self.mean_compliance > 0
        self._spectrum = mult
        self._conv = PeriodicConvolver(g.shape, mult)
        self.padded_shape = g.shape
        self.periodic = True

    @property
    def spectrum(self) -> np.ndarray:
        """The multiplier on the rfft2 layout of the grid (:class:`tengsim.registry.FourierKernelLike`)."""
        return self._spectrum

    def apply(self, p: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
        """w = K p (one convolution), into ``out`` if given."""
        return self._conv(p, out)

    def params(self) -> dict:
        return {"boundary": "periodic", "coupling": self.coupling, **self.film_params()}


KERNELS.register("free", FreeKernel, summary="isolated cell on a half-space, Eq. (9), or on a film")
KERNELS.register("periodic", PeriodicKernel, summary="periodic array of cells (half-space or film)")
