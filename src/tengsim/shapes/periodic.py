"""Periodic surfaces: the 1-D sinusoid (Westergaard/Johnson) and self-affine random roughness."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tengsim.backend import fft as _bf
from tengsim.errors import positive
from tengsim.grid import Grid
from tengsim.registry import SHAPES
from tengsim.shapes.base import Shape, _length
from tengsim.shapes.heightmap import HeightMap


@dataclass(frozen=True)
class Sinusoid1D(Shape):
    """1-D sinusoid U0 = Δ (1 − cos(2πX/λ)) (peak-to-valley 2Δ); use the periodic kernel.

    Physical input (wavelength, amplitude): ℓ = ε, every length divided by ε.
    """

    contact_family = "line"

    wavelength: float = 10.0
    amplitude: float = 1.0

    physical_fields = (_length("wavelength", "wavelength λ (the cell side)"), _length("amplitude", "amplitude Δ"))
    field_help = {"wavelength": "wavelength λ (the cell side)", "amplitude": "amplitude Δ in ε"}
    si_map = {"wavelength": "wavelength"}
    lateral_unit = "ε"
    mirror_axes = (0, 1)  # cos(2πX/λ) about the crest, uniform along Y

    def __post_init__(self):
        positive("wavelength", self.wavelength)
        positive("amplitude", self.amplitude)

    @property
    def cell(self) -> float:
        return self.wavelength

    def gap(self, grid: Grid) -> np.ndarray:
        X, _ = grid.mesh()  # an odd, cell-centred grid puts the crest (U0 = 0) on the centre pixel
        return self.amplitude * (1 - np.cos(2 * np.pi * X / self.wavelength))


def random_rough(n: int, cell: float, hurst: float = 0.8, rms_height: float = 1.0,
                 short_cutoff: float | None = None, seed: int = 0) -> HeightMap:
    """Periodic self-affine random surface (power spectrum C(q) ~ q^{-2(1+H)}) with given rms height."""
    rng = np.random.default_rng(seed)
    qx = 2 * np.pi * _bf.fftfreq(n, d=cell / n)
    q = np.hypot(*np.meshgrid(qx, qx, indexing="ij"))
    q0 = 2 * np.pi / cell
    qs = 2 * np.pi / short_cutoff if short_cutoff else np.inf
    amp = np.where((q >= q0) & (q <= qs), np.maximum(q, q0) ** (-(1 + hurst)), 0.0)
    spec = amp * np.exp(2j * np.pi * rng.random((n, n)))
    z = _bf.np_ifft2(spec).real
    z *= rms_height / z.std()
    return HeightMap(z, cell)



SHAPES.register("sinusoid", Sinusoid1D, summary="1-D sinusoid (periodic kernel)")
