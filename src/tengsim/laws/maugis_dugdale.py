"""The Maugis–Dugdale law: constant tension over a range, a stiff wall below (Maugis 1992)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tengsim.errors import TengsimError, positive
from tengsim.laws.base import LJ_PEAK_TENSION, WallLaw, _check_common, _wall
from tengsim.registry import LAWS


@dataclass(frozen=True)
class MaugisDugdale(WallLaw):
    """Dugdale law (Maugis 1992): constant tension σ0 = ``tension`` over 1 < g < 1 + h0, a wall below.

    Wall (g < 1): P = −σ0 + k(1 − g), k = ``wall_stiffness`` (W/ε²), so the contact zone g <= 1 carries
    any pressure down to −σ0, as in Maugis' model, and is rigid as k → ∞ (its compliance σ0/k ε).
    Beyond the range the law is zero.  The range is h0 = 1/σ0 − σ0/(2k) (ε), so that the work of
    adhesion, −Φ at the zero-load gap 1 − σ0/k, is exactly 1 (= W); h0 → W/σ0 as k → ∞.  With the
    default σ0 = 16/(9√3), the LJ93 peak tension, Maugis' λ = 2σ0 (R/(πWK²))^{1/3} = 1.157 μ
    (Greenwood 1997), so ``tabor`` means the same as for LJ93.  The step at g = 1 + h0 is a smoothstep
    ramp 3t² − 2t³ of width ``smoothing`` centred on it (area, hence W, unchanged), so P and dP/dg are
    continuous for the solvers.  Φ is in W, P in W/ε.

    Declared numbers (closed forms): the tension σ0 is reached at g = 1 (the plateau's start, the wall's
    edge), zero load at g0 = 1 − σ0/k, W = σ0 h0 + σ0²/(2k) = 1, and the steepest softening is the
    ramp's centre g = 1 + h0, dP/dg = 6σ0 t(1 − t)/smoothing at t = 1/2: 1.5 σ0/smoothing.
    """

    tension: float = LJ_PEAK_TENSION
    wall_stiffness: float = 1000.0
    smoothing: float = 0.2
    g_safe: float = 0.6
    field_help = {"tension": "Dugdale tension σ0, in W/ε (default: the LJ93 peak 16/(9√3))",
                  "wall_stiffness": "stiffness k of the wall g < 1, in W/ε²",
                  "smoothing": "width of the smoothstep ramp at the range's end g = 1 + h0, in ε"}

    def __post_init__(self):
        positive("tension", self.tension)
        _check_common(self)
        if not self.smoothing > 0:
            raise TengsimError(f"smoothing must be > 0, got {self.smoothing!r}")
        if not self.range > 0:
            raise TengsimError(f"wall_stiffness={self.wall_stiffness!r} is too small for tension={self.tension!r}: "
                               "the range h0 = 1/σ0 − σ0/(2k) must be > 0")
        if not self.smoothing < self.range:
            raise TengsimError(f"smoothing must be smaller than the range h0 = {self.range:.4g}, "
                               f"got {self.smoothing!r}")

    @property
    def range(self) -> float:
        """h0 = 1/σ0 − σ0/(2k) in ε (W = σ0 h0 + σ0²/(2k) = 1)."""
        return 1.0 / self.tension - self.tension / (2.0 * self.wall_stiffness)

    # declared numbers (Law): closed forms; max_tension, g_peak, g_zero from WallLaw
    @property
    def work(self) -> float:
        return self.tension * self.range + self.tension**2 / (2.0 * self.wall_stiffness)

    @property
    def max_softening(self) -> float:
        return 1.5 * self.tension / self.smoothing

    def hard_wall(self):
        """Its limit k → ∞: σ0 over h0 = W/σ0, the step its own smoothstep of width ``smoothing``."""
        from tengsim.laws.cohesive import DugdaleZone

        return DugdaleZone(float(self.tension), float(self.work), float(self.smoothing))

    def _raw(self, g, need_dp=True, xp=np):
        s0, k, s = self.tension, self.wall_stiffness, self.smoothing
        h0 = self.range
        ge = 1.0 + h0                                    # the range's end, centre of the ramp
        hi = ge + 0.5 * s
        phi_w, p_w, dp_w = _wall(g, s0, k, -s0 * h0, xp)
        t = xp.clip((hi - g) / s, 0.0, 1.0)              # 1 inside the zone, 0 beyond
        phi_z = xp.where(g > ge - 0.5 * s, -s0 * s * (t**3 - 0.5 * t**4), -s0 * (ge - g))
        p_z = -s0 * t * t * (3.0 - 2.0 * t)               # smoothstep: P and dP/dg continuous
        dp_z = 6.0 * s0 / s * t * (1.0 - t)
        wall = g < 1.0
        phi = xp.where(wall, phi_w, phi_z)
        p = xp.where(wall, p_w, p_z)
        dp = xp.where(wall, dp_w, dp_z) if need_dp else None
        return phi, p, dp


LAWS.register("md", MaugisDugdale, aliases=("maugis_dugdale", "dugdale"),
              summary="Maugis–Dugdale: constant tension over a range, stiff wall")
