"""Exponential attraction with a stiff wall (the contact-mechanics challenge's kind)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tengsim.errors import positive
from tengsim.laws.base import LJ_PEAK_TENSION, WallLaw, _check_common, _sqrt, _wall
from tengsim.registry import LAWS


@dataclass(frozen=True)
class Exponential(WallLaw):
    """Exponential attraction with a wall (the contact-mechanics challenge's kind, Müser et al. 2017).

    g >= 1: Φ = −A exp(−(g − 1)/ρ), P = −(A/ρ) exp(−(g − 1)/ρ), range ρ = ``range`` (ε); peak
    tension A/ρ at g = 1.  Wall (g < 1): P = −A/ρ + k(1 − g), k = ``wall_stiffness`` (W/ε²), as in
    :class:`MaugisDugdale`.  A = 2/(1 + sqrt(1 + 2/(kρ²))) makes the work of adhesion exactly 1 (= W).
    The default ρ = 1/σ − σ/(2k) with σ = 16/(9√3) gives the LJ93 peak tension, so ``tabor``
    means the same as for LJ93.  Φ in W, P in W/ε.

    Declared numbers (closed forms): peak tension σ0 = A/ρ at g = 1 (the wall's edge), zero load at
    g0 = 1 − σ0/k, W = A + σ0²/(2k) = 1, and the steepest softening is at g = 1⁺, dP/dg = A/ρ².
    """

    range: float = 1.0 / LJ_PEAK_TENSION - LJ_PEAK_TENSION / 2000.0
    wall_stiffness: float = 1000.0
    g_safe: float = 0.6
    field_help = {"range": "decay length ρ of the attraction, in ε (default: peak tension A/ρ = LJ93's)",
                  "wall_stiffness": "stiffness k of the wall g < 1, in W/ε²"}

    def __post_init__(self):
        positive("range", self.range)
        _check_common(self)

    @property
    def amplitude(self) -> float:
        """The depth A = −Φ(1) of the attraction, in units of W, from A + (A/ρ)²/(2k) = 1."""
        return 2.0 / (1.0 + _sqrt(1.0 + 2.0 / (self.wall_stiffness * self.range**2)))

    @property
    def tension(self) -> float:
        """Peak tension A/ρ (W/ε), at g = 1."""
        return self.amplitude / self.range

    # declared numbers (Law): closed forms; max_tension, g_peak, g_zero from WallLaw
    @property
    def work(self) -> float:
        return self.amplitude + self.tension**2 / (2.0 * self.wall_stiffness)

    @property
    def max_softening(self) -> float:
        return self.amplitude / self.range**2

    def hard_wall(self):
        """Its limit k → ∞: −(W/ρ) e^{−u/ρ} beyond a rigid wall."""
        from tengsim.laws.cohesive import ExponentialZone

        return ExponentialZone(float(self.work), float(self.range))

    def _raw(self, g, need_dp=True, xp=np):
        A, rho, k = self.amplitude, self.range, self.wall_stiffness
        e = xp.exp(-xp.maximum(g - 1.0, 0.0) / rho)
        phi_w, p_w, dp_w = _wall(g, A / rho, k, -A, xp)
        wall = g < 1.0
        phi = xp.where(wall, phi_w, -A * e)
        p = xp.where(wall, p_w, -(A / rho) * e)
        dp = xp.where(wall, dp_w, (A / rho**2) * e) if need_dp else None
        return phi, p, dp


LAWS.register("exp", Exponential, aliases=("exponential",), summary="exponential attraction, stiff wall")
