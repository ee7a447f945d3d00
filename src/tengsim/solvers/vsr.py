"""The paper's solver: virtual-state relaxation (see :class:`VSRSolver`)."""
from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from tengsim import backend
from tengsim.errors import TengsimError
from tengsim.laws.safe import safe
from tengsim.solvers.types import SOLVER_TOL, Equilibrium, Problem, State, finish


@dataclass(frozen=True)
class VSRSolver:
    """Virtual-state relaxation (the paper's method): pseudo-time relaxation of Eq. (9).

    Evolution equation:  dH/dτ = −r(H),  r(H) = H − (−D + U0 + K P(H)),
    integrated by explicit Euler in τ with an adaptive step Δτ <= 1: a step is kept when it lowers
    the energy E (then Δτ grows by ``growth``, default ×1.2; ``growth=1`` keeps Δτ fixed once it
    is stable) and retried with Δτ/2 when it does not (or when it raises ‖r‖ by half); a rejected
    Δτ caps the later ones at 0.9 of it, the explicit-Euler stability limit of the stiffest mode.  Since r = K(q − P)
    with w = K q, the same step reads q ← q − Δτ (q − P), so E is known without extra work.  It is
    a K-preconditioned gradient flow of E (dE/dτ = −ΔA r·K⁻¹r <= 0), so it comes to rest in a
    stable equilibrium.  One convolution per pseudo-time step.
    """

    tol: float = SOLVER_TOL
    max_iter: int = 200000
    dt0: float = 0.5
    growth: float = 1.2
    name: str = "vsr"
    weighted_block: ClassVar[bool] = True  # solves on a mirror block with weighted sums (solvers.mirror)

    def __post_init__(self):
        if not self.tol > 0:
            raise TengsimError(f"tol must be > 0, got {self.tol!r}")

    def solve(self, problem: Problem, start: State) -> Equilibrium:
        t0 = time.perf_counter()
        K, law, g0, dA = problem.kernel, safe(problem.law), problem.g0, problem.dA
        m = problem.weights
        if m is None:  # uniform: plain sums
            def energy(q, w, phi):
                return dA * (0.5 * np.vdot(q, w) + phi.sum())

            def rnorm(r):
                return np.linalg.norm(r)
        else:  # a weighted problem (a mirror block): m-weighted sums, a plain max|r|
            m = np.asarray(m, dtype=float)
            if m.shape != np.shape(g0):
                raise TengsimError(f"weights of shape {m.shape} do not match the problem's {np.shape(g0)}")

            def energy(q, w, phi):
                return dA * (0.5 * np.vdot(m * q, w) + np.vdot(m, phi))

            def rnorm(r):
                return np.sqrt(np.vdot(m * r, r))
        q, w = start.q.copy(), start.w.copy()
        phi, P = law.evaluate(g0 + w)
        r = w - K.apply(P)
        # E, ‖r‖ and max|r| of a state come to the host together (one backend.sync per step)
        E, norm, rmax = backend.sync((energy(q, w, phi), rnorm(r), np.max(np.abs(r)))).tolist()
        n_conv, it, dt, cap = 1, 0, self.dt0, 1.0
        msg = ""
        while True:
            if rmax <= self.tol:
                msg = "converged"
                break
            if not math.isfinite(rmax) or it >= self.max_iter:
                msg = f"not converged in {it} pseudo-time steps (max|r| = {rmax:.2e})"
                break
            G = q - P
            q_try, w_try = q - dt * G, w - dt * r
            it += 1
            if it % 1000 == 0:  # re-anchor w = K q against round-off drift
                w_try = K.apply(q_try)
                n_conv += 1
            phi_t, P_t = law.evaluate(g0 + w_try)
            r_t = w_try - K.apply(P_t)
            n_conv += 1
            E_t, n_t, rmax_t = backend.sync((energy(q_try, w_try, phi_t), rnorm(r_t), np.max(np.abs(r_t)))).tolist()
            # keep a step that lowers the energy (to round-off) without blowing up the residual;
            # a rejected Δτ caps later steps, which keeps the stiffest mode stable near convergence,
            # where energy changes fall below round-off
            if E_t <= E + 1e-13 * abs(E) and n_t <= 1.5 * norm:
                q, w, P, E, r, norm, rmax = q_try, w_try, P_t, E_t, r_t, n_t, rmax_t
                dt = min(dt * self.growth, cap)
            else:
                cap = 0.9 * dt
                dt *= 0.5
                if dt < 1e-14:
                    msg = f"pseudo-time step underflow (max|r| = {rmax:.2e})"
                    break
        return finish(problem, State(q, w), P, r, E, msg == "converged", it, n_conv, t0, msg)
