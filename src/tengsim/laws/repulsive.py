"""A non-adhesive power-law wall (Hertz-type checks)."""
from __future__ import annotations

from dataclasses import dataclass

from tengsim.errors import TengsimError, positive
from tengsim.laws.base import Law, check_g_safe
from tengsim.registry import LAWS


@dataclass(frozen=True)
class Repulsive(Law):
    """Non-adhesive wall: P = c g^{−k}, Φ = c g^{1−k}/(k − 1) (k > 1); for Hertz-type checks.

    With c = 8/3, k = 9 it is the repulsive half of the paper's law; the wall sits near g ≈ 1.  No
    tension (P > 0 everywhere): its declared numbers say so (``max_tension`` = ``work`` =
    ``max_softening`` = 0, ``g_peak`` = ``g_zero`` = ``cohesive_range`` = None), so it has no cohesive
    window.
    """

    scale: float = 8.0 / 3.0
    exponent: float = 9.0
    g_safe: float = 0.6
    field_help = {"scale": "prefactor c of the wall P = c g^-k, in W/ε",
                  "exponent": "power k > 1 of the wall P = c g^-k (pure number)"}

    def __post_init__(self):
        positive("scale", self.scale)
        if not self.exponent > 1:
            raise TengsimError(f"exponent must be > 1, got {self.exponent!r}")
        check_g_safe(self)

    # declared numbers (Law): no tension
    @property
    def max_tension(self) -> float:
        return 0.0

    @property
    def g_peak(self) -> None:
        return None

    @property
    def g_zero(self) -> None:
        return None

    @property
    def work(self) -> float:
        return 0.0

    @property
    def max_softening(self) -> float:
        return 0.0

    def hard_wall(self):
        """Its limit k → ∞: the hard wall, no adhesion."""
        from tengsim.laws.cohesive import NoAdhesion

        return NoAdhesion()

    def _raw(self, g, need_dp=True, xp=None):
        k, c = self.exponent, self.scale
        gk = g ** (-k)
        p = c * gk
        phi = c * gk * g / (k - 1)
        dp = -k * p / g
        return phi, p, dp


LAWS.register("repulsive", Repulsive, aliases=("hertz", "nonadhesive"), summary="non-adhesive wall")
