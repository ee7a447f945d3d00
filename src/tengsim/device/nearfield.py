"""The charged pattern's near field: the field and gap voltage of the contact map's charge in the first
micrometres of separation, against the uniform sigma A/S the device model uses.

The tribo charge sits on the charged area of a periodic contact map (a fraction map f(x, y) in [0, 1] on an
N x N grid of one pitch p, each cell a constant). Its mean sigma <f> = sigma A/S is the device model's uniform
sheet; the rest is a sum of Fourier modes of wavenumber q = 2 pi |k|/p, each solved exactly in the layered
geometry: the grounded back electrode under the dielectric (thickness T, eps_r), the sheet on its surface,
the air gap x and the moving electrode (held at the sheet's mean potential: modes k != 0 carry no net charge).
For a mode of amplitude s_k the surface potential is

    phi_k = s_k / (eps0 q (coth(q x) + eps_r coth(q T))),

and in the gap (height z above the surface) the normal field is E_k(z) = phi_k q cosh(q (x - z))/sinh(q x),
which decays like exp(-q z) away from the surface when x >> p. No equivalent-thickness approximation here:
the pattern's pitch is rarely >> T. Cells are constants, so the map's modes are its DFT times the cell's
sinc factor; modes above the grid's Nyquist limit are dropped (they decay like exp(-2 pi N z/(2 p))).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tengsim.backend import fft as _bf
from tengsim.device.params import EPS0
from tengsim.errors import positive, require


@dataclass(frozen=True, eq=False)
class PatternField:
    """The near field of a periodic charged pattern (SI): ``fraction`` (N x N map in [0, 1]), ``pitch_m``,
    ``sigma_C_m2`` (the density on the charged area), the dielectric ``thickness_m`` and ``eps_r``."""

    fraction: np.ndarray
    pitch_m: float
    sigma_C_m2: float
    thickness_m: float
    eps_r: float

    def __post_init__(self):
        f = np.asarray(self.fraction, dtype=float)
        require(f.ndim == 2 and f.shape[0] == f.shape[1] and f.shape[0] >= 2,
                f"the contact map must be a square 2-D array, got shape {f.shape}")
        require(bool(np.all((f >= 0) & (f <= 1))), "the contact map's fractions must be in [0, 1]")
        object.__setattr__(self, "fraction", f)
        for name in ("pitch_m", "thickness_m", "eps_r"):
            object.__setattr__(self, name, positive(name, getattr(self, name)))

    @property
    def area_fraction(self) -> float:
        """A/S of the map: the mean of the fraction map."""
        return float(self.fraction.mean())

    def _modes(self):
        n = self.fraction.shape[0]
        k = _bf.fftfreq(n, d=1.0 / n)  # integer mode numbers
        kx, ky = np.meshgrid(k, k, indexing="ij")
        cell = np.sinc(kx / n) * np.sinc(ky / n)  # piecewise-constant cells
        s = self.sigma_C_m2 * _bf.np_fft2(self.fraction) / (n * n) * cell
        q = 2 * np.pi * np.hypot(kx, ky) / self.pitch_m
        nyq = (np.abs(kx) < n / 2) & (np.abs(ky) < n / 2)
        s = np.where(nyq, s, 0.0)
        s[0, 0] = 0.0
        return s, q, n

    def surface_potential(self, gap_m: float) -> np.ndarray:
        """The pattern's part of the surface potential (V, N x N map) at gap ``gap_m``: the local gap voltage
        is the uniform sheet's plus this."""
        x = positive("gap", gap_m)
        s, q, n = self._modes()
        with np.errstate(divide="ignore", invalid="ignore"):
            phi = s / (EPS0 * q * (1 / np.tanh(q * x) + self.eps_r / np.tanh(q * self.thickness_m)))
        phi[0, 0] = 0.0
        return np.real(_bf.np_ifft2(phi) * n * n)

    def field_z(self, gap_m: float, z_m: float) -> np.ndarray:
        """The pattern's part of the normal field (V/m, N x N map, toward the surface positive for a positive
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
        return np.real(_bf.np_ifft2(e) * n * n)

    def uniform_field(self) -> float:
        """The uniform sheet's gap field sigma (A/S)/eps0 (V/m), open circuit, parallel plates."""
        return self.sigma_C_m2 * self.area_fraction / EPS0
