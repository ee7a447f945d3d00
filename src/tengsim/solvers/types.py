"""The values the solvers exchange: a :class:`Problem` and a start :class:`State` go in, an
:class:`Equilibrium` comes out.  All three are frozen (their arrays are the solver's own)."""
from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from tengsim import backend

SOLVER_TOL = 1e-6
"""The default tolerance of every solver: the largest residual of Eq. (9) (or of the gap, for the constrained
solvers) an equilibrium may keep, in ε; the [contact] table's ``tol``.  Defined here only."""


@dataclass(frozen=True)
class Problem:
    """One equilibrium problem: initial gap g0 = U0 − D + 1, a law and a kernel.

    ``weights`` (shape of g0, or None: uniform): the multiplicity of each pixel, for a problem posed on
    the irreducible block of a mirror-symmetric one (tengsim.solvers.mirror).  Then the energy is
    E = ΔA Σ m_i [½ q_i w_i + Φ(g_i)], and every inner product and sum of the solvers is m-weighted
    (the block's kernel K is not symmetric in the plain product, but M K is); max|r| stays a plain max.
    """

    g0: np.ndarray
    law: object
    kernel: object
    weights: np.ndarray | None = None

    @property
    def dA(self) -> float:
        return self.kernel.grid.area


@dataclass(frozen=True)
class State:
    """Solver state: q (elastic pressure) and w = K q (surface displacement)."""

    q: np.ndarray
    w: np.ndarray

    @classmethod
    def zero(cls, shape) -> "State":
        return cls(backend.zeros(shape), backend.zeros(shape))

    def copy(self) -> "State":
        return State(self.q.copy(), self.w.copy())


@dataclass(frozen=True)
class Equilibrium:
    """A solved state with its convergence record (a value: build a changed one with
    ``dataclasses.replace``)."""

    state: State
    H: np.ndarray
    P: np.ndarray
    residual: float          # max |r| of Eq. (9), units of ε
    converged: bool
    iterations: int
    n_conv: int              # convolutions (FFT pairs) spent
    energy: float
    seconds: float
    message: str = ""
    capped: bool = False     # stopped at its iteration cap while still descending (a solver that resumes
    # from its state may go on from here: tengsim.continuation.walker.persist); False on every other stop

    def max_change(self, other: "Equilibrium") -> float:
        """max |H − other.H| over the grid (the path's jump test)."""
        return float(np.max(np.abs(self.H - other.H)))


def finish(problem, state, P, r, energy, converged, it, n_conv, t0, msg, capped=False):
    H = problem.g0 + state.w - 1.0
    res = float(np.max(np.abs(r)))
    return Equilibrium(state, H, P, res, converged, it, n_conv, float(energy), time.perf_counter() - t0, msg,
                       capped)


def check_settings(solver, counts=("max_iter", "monitor_every")) -> None:
    """A constrained solver's settings at construction: ``tol`` a finite number > 0, each of ``counts`` an
    integer >= 1 (one line naming the bad value)."""
    from tengsim.errors import TengsimError

    tol = solver.tol
    if isinstance(tol, bool) or not (isinstance(tol, (int, float)) and tol > 0 and math.isfinite(tol)):
        raise TengsimError(f"tol must be a finite number > 0, got {tol!r}")
    for key in counts:
        v = getattr(solver, key)
        if isinstance(v, bool) or not isinstance(v, int) or v < 1:
            raise TengsimError(f"{key} must be an integer >= 1, got {v!r}")
