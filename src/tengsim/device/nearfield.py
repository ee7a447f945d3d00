"""The charged pattern's near field: the field and gap voltage of the contact map's charge in the first
micrometres of separation, against the uniform sigma A/S the device model uses.

The tribo charge sits on the charged area of a periodic contact map (a fraction map f(x, y) in [0, 1] on an
Nx x Ny grid of one cell, pitches p_x x p_y (a square cell by default), each pixel a constant). Its mean
sigma <f> = sigma A/S is the device model's uniform sheet; the rest is a sum of Fourier modes of wavenumber
q = 2 pi |(k_x/p_x, k_y/p_y)|, each solved exactly in the layered geometry: the grounded back electrode under
the dielectric (thickness T, eps_r), the sheet on its surface, the air gap x and the moving electrode (held
at the sheet's mean potential: modes k != 0 carry no net charge).
For a mode of amplitude s_k the surface potential is

    phi_k = s_k / (eps0 q (coth(q x) + eps_r coth(q T))),

and in the gap (height z above the surface) the normal field is E_k(z) = phi_k q cosh(q (x - z))/sinh(q x),
which decays like exp(-q z) away from the surface when x >> p. No equivalent-thickness approximation here:
the pattern's pitch is rarely >> T. Cells are constants, so the map's modes are its DFT times the cell's
sinc factor; modes above the grid's Nyquist limit are dropped (they decay like exp(-pi z/dx), dx the pixel).
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from tengsim.backend import fft as _bf
from tengsim.constants import EPS0
from tengsim.errors import positive, require


@dataclass(frozen=True, eq=False)
class PatternField:
    """The near field of a periodic charged pattern (SI): ``fraction`` (Nx x Ny map in [0, 1], axis 0 along x),
    ``pitch_m`` (the cell's side along x), ``sigma_C_m2`` (the density on the charged area), the dielectric
    ``thickness_m`` and ``eps_r``; ``pitch_y_m`` the cell's side along y (None: ``pitch_m``, a square cell)."""

    fraction: np.ndarray
    pitch_m: float
    sigma_C_m2: float
    thickness_m: float
    eps_r: float
    pitch_y_m: float | None = None

    def __post_init__(self):
        f = np.asarray(self.fraction, dtype=float)
        require(f.ndim == 2 and min(f.shape) >= 2,
                f"the contact map must be a 2-D array of at least 2 x 2 pixels, got shape {f.shape}")
        require(bool(np.all((f >= 0) & (f <= 1))), "the contact map's fractions must be in [0, 1]")
        object.__setattr__(self, "fraction", f)
        if self.pitch_y_m is None:
            object.__setattr__(self, "pitch_y_m", self.pitch_m)
        for name in ("pitch_m", "pitch_y_m", "thickness_m", "eps_r"):
            object.__setattr__(self, name, positive(name, getattr(self, name)))

    @property
    def area_fraction(self) -> float:
        """A/S of the map: the mean of the fraction map."""
        return float(self.fraction.mean())

    def _modes(self):
        return self._spectrum

    @cached_property
    def _spectrum(self):
        """The map's modes s_k (C/m², half the spectrum along y), their wavenumbers q (1/m) and the pixel
        count: computed once per pattern."""
        nx, ny = self.fraction.shape
        kx, ky = np.meshgrid(_bf.fftfreq(nx, d=1.0 / nx), _bf.fftfreq(ny, d=1.0 / ny), indexing="ij")  # integers
        cell = np.sinc(kx / nx) * np.sinc(ky / ny)  # piecewise-constant pixels
        s = self.sigma_C_m2 * _bf.np_fft2(self.fraction) / (nx * ny) * cell
        q = 2 * np.pi * np.hypot(kx / self.pitch_m, ky / self.pitch_y_m)
        nyq = (np.abs(kx) < nx / 2) & (np.abs(ky) < ny / 2)
        s = np.where(nyq, s, 0.0)
        s[0, 0] = 0.0
        h = ny // 2 + 1  # a real pattern's spectrum is Hermitian: its half along y is all of it
        return s[:, :h], q[:, :h], nx * ny

    def surface_potential(self, gap_m: float) -> np.ndarray:
        """The pattern's part of the surface potential (V, Nx x Ny map) at gap ``gap_m``: the local gap voltage
        is the uniform sheet's plus this."""
        x = positive("gap", gap_m)
        s, q, n = self._modes()
        with np.errstate(divide="ignore", invalid="ignore"):
            phi = s / (EPS0 * q * (1 / np.tanh(q * x) + self.eps_r / np.tanh(q * self.thickness_m)))
        phi[0, 0] = 0.0
        return _real(phi, self.fraction.shape) * n

    def field_z(self, gap_m: float, z_m: float) -> np.ndarray:
        """The pattern's part of the normal field (V/m, Nx x Ny map, toward the surface positive for a positive
        pattern) at height ``z_m`` in a gap ``gap_m``."""
        x = positive("gap", gap_m)
        require(0 <= z_m <= x, f"the height must lie in the gap [0, {x:g}] m, got {z_m!r}")
        s, q, n = self._modes()
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            den = EPS0 * (1 / np.tanh(q * x) + self.eps_r / np.tanh(q * self.thickness_m))
            # cosh(q (x - z))/sinh(q x), stable for large q x
            shape = np.exp(-q * z_m) * (1 + np.exp(-2 * q * (x - z_m))) / (1 - np.exp(-2 * q * x))
            e = s / den * shape
        e[0, 0] = 0.0
        return _real(e, self.fraction.shape) * n

    def uniform_field(self) -> float:
        """The uniform sheet's gap field sigma (A/S)/eps0 (V/m), open circuit, parallel plates."""
        return self.sigma_C_m2 * self.area_fraction / EPS0


def _real(spec, shape):
    """The real map of a real pattern's half spectrum (along y, :meth:`PatternField._spectrum`)."""
    return _bf.np_irfft2(spec, s=shape)
