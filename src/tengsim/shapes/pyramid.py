"""The paper's square pyramid (Eqs. 5/11)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tengsim.errors import TengsimError, positive
from tengsim.grid import Grid
from tengsim.registry import SHAPES
from tengsim.shapes.base import Shape, _length


@dataclass(frozen=True)
class Pyramid(Shape):
    """Square pyramid in a square unit cell, paper Eqs. (5)/(11).

    U0 = |X − Y| + |X + Y| = 2 max(|X|, |Y|) inside [−N, N]², 2N outside; the cell is
    [−L̄/2, L̄/2]² with ``cell`` = L̄.  ``N`` = n/(2ε).
    """

    N: float
    cell: float

    physical_fields = (_length("pitch", "pitch L (cell side)"), _length("base", "base width m"),
                       _length("height", "height n"))
    field_help = {"N": "n/(2ε): half the base in X, the height in ε over 2", "cell": "cell side L̄ = L n/(ε m)"}
    lateral_unit = "ε m/n"
    mirror_axes = (0, 1)

    def __post_init__(self):
        positive("pyramid N", self.N)
        positive("cell", self.cell)
        if 2 * self.N > self.cell * (1 + 1e-12):
            raise TengsimError(
                f"pyramid base 2N = {2 * self.N:g} is wider than its cell L̄ = {self.cell:g}"
            )

    def full_contact_length(self) -> float:
        """The base, 2N."""
        return 2 * float(self.N)

    def edge_offsets(self) -> tuple:
        """The base edge, N from the apex."""
        return (float(self.N),)

    @classmethod
    def from_physical(cls, pitch: float, base: float, height: float, eps: float) -> "Pyramid":
        """From pitch L, base m, height n and interaction range ε (any one length unit), Eq. (7)."""
        pitch, base = positive("pitch", pitch), positive("base", base)
        height, eps = positive("height", height), positive("eps", eps)
        if base > pitch:
            raise TengsimError(f"pyramid base {base:g} is wider than its pitch {pitch:g}")
        return cls(N=height / (2 * eps), cell=pitch * height / (eps * base))

    @classmethod
    def lateral_scale(cls, values, eps):
        """ℓ = ε m/n (paper Eq. 7)."""
        return eps * positive("base", values["base"]) / positive("height", values["height"])

    @classmethod
    def cell_area_si(cls, values):
        """L² (m²), the cell's area from its pitch."""
        return positive("pitch", values["pitch"]) ** 2

    @classmethod
    def from_si(cls, values, eps):
        if values["base"] > values["pitch"] > 0:  # said in the user's units (SI with a prefix)
            from tengsim.units import format_si

            raise TengsimError(f"pyramid base {format_si(values['base'], 'm')} is wider than its pitch "
                               f"{format_si(values['pitch'], 'm')}")
        return cls.from_physical(values["pitch"], values["base"], values["height"], eps)

    @classmethod
    def eps_from_tabor(cls, values, E_star, W, mu):
        """Closed form: ε = m W/(n E* μ^{3/2})."""
        return values["base"] * W / (values["height"] * positive("E_star", E_star) * positive("tabor", mu) ** 1.5)

    def gap(self, grid: Grid) -> np.ndarray:
        X, Y = grid.mesh()
        return np.minimum(2 * np.maximum(np.abs(X), np.abs(Y)), 2 * self.N)


SHAPES.register("pyramid", Pyramid, summary="the paper's square pyramid, Eq. (11)")
