"""The paper's dimensionless variables (Eq. 7) for its pyramids, and its three groups' constants.

The core needs none of this: a physical pyramid run builds the generic :class:`tengsim.units.Scaling`
with ℓ = ε m/n and cell area L² (the same numbers); :class:`PaperScaling` keeps the paper's own
names (m, n, L, N, L̄) for the paper's cases.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from tengsim.errors import TengsimError, positive
from tengsim.units import _Units


@dataclass(frozen=True)
class PaperScaling(_Units):
    """The paper's dimensionless variables (Eq. 7) for a pyramid of base m, height n in pitch L.

    Give ε directly or the Tabor parameter μ = (m W / (n E* ε))^{2/3}; SI units throughout.
    A :class:`Scaling` with ℓ = ε m/n and cell area L².
    """

    E_star: float
    W: float
    m: float
    n: float
    L: float
    eps: float

    def __post_init__(self):
        for k in ("E_star", "W", "m", "n", "L", "eps"):
            positive(k, getattr(self, k))
        if self.m > self.L:
            raise TengsimError(f"pyramid base m = {self.m:g} m is wider than its pitch L = {self.L:g} m")

    @classmethod
    def from_tabor(cls, E_star, W, m, n, L, mu) -> "PaperScaling":
        mu = positive("tabor", mu)
        eps = m * W / (n * positive("E_star", E_star) * mu**1.5)
        return cls(E_star, W, m, n, L, eps)

    @property
    def mu(self) -> float:
        return (self.m * self.W / (self.n * self.E_star * self.eps)) ** (2.0 / 3.0)

    @property
    def N(self) -> float:
        return self.n / (2 * self.eps)

    @property
    def cell(self) -> float:
        """L̄ = L n/(ε m)."""
        return self.L * self.n / (self.eps * self.m)

    @property
    def lateral(self) -> float:
        """Length of one unit of X: ε m/n (m)."""
        return self.eps * self.m / self.n

    @property
    def cell_area(self) -> float:
        """L² (m²)."""
        return self.L**2

    def length(self, X):
        """Dimensionless in-plane length (e.g. Λc) → metres: λc = Λc ε m/n."""
        return X * self.lateral

    def force(self, F):
        """Dimensionless F (Eq. 10) → newtons per cell: f = 3π m² W ε F/n²."""
        return F * 3 * math.pi * self.m**2 * self.W * self.eps / self.n**2

    def pressure(self, F):
        """Nominal pressure on the array f/L² (Pa)."""
        return self.force(F) / self.L**2

    def params(self) -> dict:
        return {"E_star_Pa": self.E_star, "W_J_m2": self.W, "base_m": self.m, "height_m": self.n,
                "pitch_m": self.L, "eps_m": self.eps, "tabor": self.mu}


# The paper's three groups (Section 3): pitch L, base m, height n in metres; E* = 0.59 MPa,
# W = 54 mJ/m², μ = 0.5.
PAPER_GROUPS = {
    "A": dict(L=2.0e-6, m=1.0e-6, n=0.7e-6),
    "B": dict(L=5.0e-6, m=2.5e-6, n=1.75e-6),
    "C": dict(L=10.0e-6, m=5.0e-6, n=3.5e-6),
}
PAPER_E_STAR = 0.59e6
PAPER_W = 54e-3
PAPER_TABOR = 0.5


def paper_scaling(group: str) -> PaperScaling:
    """The paper's scaling for pyramid group 'A', 'B' or 'C'."""
    try:
        g = PAPER_GROUPS[group.upper()]
    except KeyError:
        raise TengsimError(f"unknown pyramid group {group!r} (choose A, B or C)") from None
    return PaperScaling.from_tabor(PAPER_E_STAR, PAPER_W, g["m"], g["n"], g["L"], PAPER_TABOR)
