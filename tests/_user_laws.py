"""A user's cohesive law for the tests (tests/test_ram_solver.py, tests/test_pk_user_laws.py): it declares its
hard-wall limit as three callables, as a law written outside tengsim would."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tengsim.laws import Law
from tengsim.laws.cohesive import CohesiveFunctions


@dataclass(frozen=True)
class LinearSoftening(Law):
    """A user's law that declares its hard-wall limit: t = −σ0 (1 − u/δ) for u < δ (W = σ0 δ / 2)."""

    sigma0: float = 0.5
    delta: float = 2.0
    g_safe: float = 0.6

    def _raw(self, g, need_dp=True, xp=np):      # a soft-wall form, for the soft solvers (not used here)
        u = g - 1.0
        p = xp.where(u < 0, -self.sigma0 - 1000.0 * u, -self.sigma0 * xp.clip(1.0 - u / self.delta, 0.0, 1.0))
        return -self.sigma0 * self.delta / 2.0 * xp.clip(1.0 - u / self.delta, 0.0, 1.0) ** 2, p, None

    def hard_wall(self):
        s, d = self.sigma0, self.delta
        return CohesiveFunctions(t=lambda u, xp: -s * xp.clip(1.0 - u / d, 0.0, 1.0),
                                 phi=lambda u, xp: -0.5 * s * d * xp.clip(1.0 - u / d, 0.0, 1.0) ** 2,
                                 d2phi=lambda u, xp: xp.where(u < d, -s / d, 0.0), length=d)
