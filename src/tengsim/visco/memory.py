"""The state with memory of a viscoelastic surface and its exact update over a time step.

With the displacement w = K_ref p at the reference modulus E_ref, the surface obeys
K_ref p(t) = (E∞/E_ref) w(t) + Σ_i q_i(t), one internal field per Maxwell branch with
dq_i/dt + q_i/τ_i = (E_i/E_ref) dw/dt.  With w linear over a step Δt (a_i = e^{−Δt/τ_i},
γ_i = (τ_i/Δt)(1 − a_i)):

    q_i(t+Δt) = a_i q_i(t) + c_i [w(t+Δt) − w(t)],   c_i = (E_i/E_ref) γ_i,

so that w(t+Δt) = (E_ref/E_eff) K_ref p(t+Δt) + u_h: an elastic step at E_eff = E∞ + Σ E_i γ_i with the known
displacement offset u_h = −(E_ref/E_eff) Σ_i [a_i q_i(t) − c_i w(t)] (docs/viscoelastic.md).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tengsim.relaxation import Prony


@dataclass(frozen=True)
class MaxwellMemory:
    """The internal fields q_i (one per branch, units of w) and the total displacement w of the last step."""

    q: tuple
    w: np.ndarray

    @classmethod
    def rest(cls, shape, branches: int) -> "MaxwellMemory":
        """A surface at rest, never loaded."""
        return cls(tuple(np.zeros(shape) for _ in range(branches)), np.zeros(shape))


@dataclass(frozen=True)
class StepOperator:
    """The exact update of one step dt of ``material`` with the reference modulus ``E_ref`` (Pa)."""

    material: Prony
    E_ref: float
    dt: float

    def __post_init__(self):
        a, gamma = self.material.step_factors(self.dt)
        object.__setattr__(self, "_a", a)
        object.__setattr__(self, "_c", np.asarray(self.material.E, float) / self.E_ref * gamma)
        object.__setattr__(self, "E_eff", self.material.effective(self.dt))

    @property
    def ratio(self) -> float:
        """E_ref/E_eff: the step's kernel is the reference kernel times this."""
        return self.E_ref / self.E_eff

    def offset(self, mem: MaxwellMemory) -> np.ndarray:
        """u_h: the displacement the history adds to the step's elastic response."""
        h = np.zeros_like(mem.w)
        for a, c, q in zip(self._a, self._c, mem.q):
            h += a * q - c * mem.w
        return -self.ratio * h

    def update(self, mem: MaxwellMemory, w_new: np.ndarray) -> MaxwellMemory:
        """The memory after the step, whose total displacement is ``w_new``."""
        dw = w_new - mem.w
        return MaxwellMemory(tuple(a * q + c * dw for a, c, q in zip(self._a, self._c, mem.q)), np.array(w_new))
