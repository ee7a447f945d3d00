"""The hard-wall limit of a law: what a constrained solver (tengsim.solvers.ram) asks of it.

A law with a wall at g = 1 and adhesion beyond it declares its limit wall_stiffness → ∞ by
``Law.hard_wall()``, a :class:`CohesiveLimit`: the gap above the wall u = g − 1 >= 0 (ε) is the
unknown, the wall is the constraint u >= 0 (any pressure there), and outside the contact the law's
traction t(u) (W/ε, t <= 0: tension) acts, with its energy φ(u) (W per area, φ' = −t) and curvature
φ''(u) (W/ε²) — three functions of u, array-generic (``xp`` the array namespace, NumPy by default).
A law without such a limit (LJ93's smooth repulsion) returns None from ``hard_wall()``.

Built in: :class:`NoAdhesion` (``repulsive``'s limit), :class:`DugdaleZone` (``md``: Maugis' Dugdale
zone, t = −σ0 for u < h0 = W/σ0, 0 beyond, its step the law's own smoothstep of width ``smoothing`` (the
law as written, never widened; ``ramp=0``: the sharp step), :class:`ExponentialZone` (``exp``:
t = −(W/ρ) e^{−u/ρ}).  A
user's law gives its own by overriding ``hard_wall`` with a subclass of :class:`CohesiveLimit`, or
:class:`CohesiveFunctions` of three callables.
"""
from __future__ import annotations

from dataclasses import dataclass, replace
from typing import ClassVar

import numpy as np


class CohesiveLimit:
    """The hard-wall limit of a law (module doc): ``traction``, ``energy``, ``curvature`` of u >= 0,
    ``tension`` σ0 = −t(0) (W/ε), ``work`` W = −φ(0) (W), ``length`` a gap scale of the adhesion (ε; the
    solvers' trust step), and ``smooth`` (False where t jumps: the solver then restarts its conjugacy
    whenever a pixel crosses the jump)."""

    tension: float = 0.0
    work: float = 0.0
    length: float = 1.0
    smooth: bool = True
    #: a Dugdale zone (module doc): 'pk' solves it as a zone of pixels at −σ0, its step ``ramp`` wide
    plateau: ClassVar[bool] = False
    #: the width (ε) of a plateau's step at u = ``length`` (0: a sharp step)
    ramp: float = 0.0
    #: the constrained solver this limit is best solved by ('ram' solves any limit; 'pk' the ones it says)
    solver: ClassVar[str] = "ram"

    def traction(self, u, xp=np):  # pragma: no cover - abstract
        raise NotImplementedError

    def energy(self, u, xp=np):  # pragma: no cover - abstract
        raise NotImplementedError

    def curvature(self, u, xp=np):  # pragma: no cover - abstract
        raise NotImplementedError

    def side(self, u, xp=np):
        """Which side of a jump of t each gap lies on (a non-smooth law; None for a smooth one)."""
        return None

    def with_ramp(self, ramp: float) -> "CohesiveLimit":  # pragma: no cover - a plateau's
        """The same plateau with its step ``ramp`` wide (ε; 0: sharp)."""
        raise NotImplementedError

    def step_gap(self, p, xp=np):  # pragma: no cover - a plateau's
        """The gap u (ε) on a plateau's step where the traction is ``p`` (−σ0 < p < 0): t's inverse there."""
        raise NotImplementedError


@dataclass(frozen=True)
class NoAdhesion(CohesiveLimit):
    """The hard wall alone (t = φ = 0)."""

    solver: ClassVar[str] = "pk"

    def traction(self, u, xp=np):
        return xp.zeros_like(u)

    def energy(self, u, xp=np):
        return xp.zeros_like(u)

    def curvature(self, u, xp=np):
        return xp.zeros_like(u)


@dataclass(frozen=True)
class DugdaleZone(CohesiveLimit):
    """Maugis' Dugdale zone: t = −σ0 for 0 <= u <= h0 = W/σ0, 0 beyond; φ = −σ0 (h0 − u)⁺.  ``ramp`` > 0: the
    step is the smoothstep 3s² − 2s³ of that width centred on h0 (``MaugisDugdale``'s formula, its
    ``smoothing``; W unchanged); 0: the sharp step.  A plateau (module doc), best solved by 'pk'."""

    tension: float = 1.0
    work: float = 1.0
    ramp: float = 0.0
    plateau: ClassVar[bool] = True
    solver: ClassVar[str] = "pk"

    @property
    def length(self) -> float:
        return self.work / self.tension

    @property
    def smooth(self) -> bool:
        return self.ramp > 0

    def with_ramp(self, ramp: float) -> "DugdaleZone":
        return replace(self, ramp=float(ramp))

    def _s(self, u, xp):
        """s = 1 inside the zone, 0 beyond, the step's linear coordinate between."""
        return xp.clip((self.length + 0.5 * self.ramp - u) * (1.0 / self.ramp), 0.0, 1.0)

    def traction(self, u, xp=np):
        if not self.ramp > 0:
            return xp.where(u <= self.length, -self.tension, 0.0)
        s = self._s(u, xp)
        return s * (s * (3.0 - 2.0 * s)) * -self.tension

    def energy(self, u, xp=np):
        if not self.ramp > 0:
            return -self.tension * xp.maximum(self.length - u, 0.0)
        s = self._s(u, xp)
        return xp.where(u > self.length - 0.5 * self.ramp, -self.tension * self.ramp * (s**3 - 0.5 * s**4),
                        -self.tension * (self.length - u))

    def curvature(self, u, xp=np):
        if not self.ramp > 0:
            return xp.zeros_like(u)
        s = self._s(u, xp)
        return -6.0 * self.tension / self.ramp * s * (1.0 - s)

    def side(self, u, xp=np):
        return u <= self.length if not self.ramp > 0 else None

    def step_gap(self, p, xp=np):
        y = -p / self.tension
        s = 0.5 - xp.sin(xp.arcsin(1.0 - 2.0 * y) / 3.0)         # the smoothstep's inverse
        return self.length + 0.5 * self.ramp - self.ramp * s


@dataclass(frozen=True)
class ExponentialZone(CohesiveLimit):
    """t = −(W/ρ) e^{−u/ρ}, φ = −W e^{−u/ρ}, φ'' = −(W/ρ²) e^{−u/ρ}; ρ = ``length`` (u < 0: as u = 0).  Best
    solved by 'pk' (its outer fixed point)."""

    work: float = 1.0
    length: float = 1.0
    solver: ClassVar[str] = "pk"

    @property
    def tension(self) -> float:
        return self.work / self.length

    def _decay(self, u, xp):
        return xp.exp(xp.maximum(u, 0.0) * (-1.0 / self.length))

    def traction(self, u, xp=np):
        return self._decay(u, xp) * -self.tension

    def energy(self, u, xp=np):
        return self._decay(u, xp) * -self.work

    def curvature(self, u, xp=np):
        return self._decay(u, xp) * -(self.work / self.length**2)


@dataclass(frozen=True)
class CohesiveFunctions(CohesiveLimit):
    """A user's limit from three callables of (u, xp): ``t`` (traction, W/ε), ``phi`` (energy, W; φ' = −t)
    and ``d2phi`` (φ'', W/ε²); ``length`` (ε) its range, ``smooth`` False if t jumps."""

    t: object = None
    phi: object = None
    d2phi: object = None
    length: float = 1.0
    smooth: bool = True

    @property
    def tension(self) -> float:
        return -float(np.asarray(self.t(np.zeros(1), np))[0])

    @property
    def work(self) -> float:
        return -float(np.asarray(self.phi(np.zeros(1), np))[0])

    def traction(self, u, xp=np):
        return self.t(u, xp)

    def energy(self, u, xp=np):
        return self.phi(u, xp)

    def curvature(self, u, xp=np):
        return self.d2phi(u, xp)
