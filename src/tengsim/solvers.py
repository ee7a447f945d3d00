"""Equilibrium solvers for Eq. (9): find a stable state H of one rigid approach D from a start state.

Notation (dimensionless, paper Eq. 7): gap g = H + 1, initial gap g0 = U0 − D + 1, surface
displacement w = K q of an "elastic pressure" field q, so g = g0 + w.  The total energy of the cell is

    E(q) = ΔA [ ½ q·K q + Σ Φ(g0 + K q) ],

whose stationary points satisfy q = P(g), i.e. H = −D + U0 + K P(H): exactly Eq. (9).  The residual
of Eq. (9), r = H − (−D + U0 + K P(H)) = w − K P(g), in units of ε, is how every state is judged.
A solver returns an :class:`Equilibrium` and never silently returns an unconverged one: ``converged``
is False and ``message`` says why.

Both solvers descend E, so from a warm start they settle in a local minimum: a stable equilibrium.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from tengsim._lbfgs import KMetricLBFGS
from tengsim.errors import TengsimError


@dataclass
class Problem:
    """One equilibrium problem: initial gap g0 = U0 − D + 1, a law and a kernel."""

    g0: np.ndarray
    law: object
    kernel: object

    @property
    def dA(self) -> float:
        return self.kernel.grid.area


@dataclass
class State:
    """Solver state: q (elastic pressure) and w = K q (surface displacement)."""

    q: np.ndarray
    w: np.ndarray

    @classmethod
    def zero(cls, shape) -> "State":
        return cls(np.zeros(shape), np.zeros(shape))

    def copy(self) -> "State":
        return State(self.q.copy(), self.w.copy())


@dataclass
class Equilibrium:
    """A solved state with its convergence record."""

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

    @property
    def force_sum(self) -> float:  # pragma: no cover - convenience
        return float(self.P.sum())


def _finish(problem, state, P, r, energy, converged, it, n_conv, t0, msg):
    H = problem.g0 + state.w - 1.0
    res = float(np.max(np.abs(r)))
    return Equilibrium(state, H, P, res, converged, it, n_conv, float(energy), time.perf_counter() - t0, msg)


@dataclass(frozen=True)
class FastSolver:
    """L-BFGS on E(q) in the metric of the elastic kernel (K-preconditioned), Wolfe line search.

    Each iteration spends one convolution, K P(g) at the new state (plus one every ``resync``
    iterations to re-anchor w = K q): the direction's image K d is assembled from stored images
    (K s = Δw, K y = Δr, K G = r) by the compact L-BFGS form (tengsim._lbfgs), and the line search
    along d needs only element-wise work, since g(α) = g + α K d.  Converged when max|r| <= ``tol``.
    """

    tol: float = 1e-6
    max_iter: int = 3000
    memory: int = 10
    resync: int = 25
    name: str = "fast"

    def __post_init__(self):
        if not self.tol > 0:
            raise TengsimError(f"tol must be > 0, got {self.tol!r}")
        if int(self.memory) < 1:
            raise TengsimError(f"memory must be >= 1, got {self.memory!r}")

    def solve(self, problem: Problem, start: State) -> Equilibrium:
        t0 = time.perf_counter()
        K, law, g0, dA = problem.kernel, problem.law, problem.g0, problem.dA
        q, w = start.q.copy(), start.w.copy()
        g = g0 + w
        phi, P = law.evaluate(g)
        r = w - K.apply(P)
        n_conv = 1
        G = q - P
        E = dA * (0.5 * np.vdot(q, w) + phi.sum())
        mem = KMetricLBFGS(self.memory, q.size, dA)

        for it in range(self.max_iter + 1):
            rmax = float(np.max(np.abs(r)))
            if not math.isfinite(rmax):
                return _finish(problem, State(q, w), P, r, E, False, it, n_conv, t0, "non-finite residual")
            if rmax <= self.tol:
                return _finish(problem, State(q, w), P, r, E, True, it, n_conv, t0, "converged")
            if it == self.max_iter:
                break
            HG, KHG = mem.direction(G.ravel(), r.ravel())
            d, Kd = -HG.reshape(G.shape), -KHG.reshape(G.shape)
            # E and E'(0) from the line function itself, so the search is self-consistent
            E = dA * (0.5 * np.vdot(q, w) + phi.sum())
            slope = dA * (np.vdot(d, w) - np.vdot(P, Kd))
            if not slope < 0:  # not a descent direction: restart from the preconditioned gradient
                mem.reset()
                d, Kd = -G, -r
                slope = dA * (np.vdot(d, w) - np.vdot(P, Kd))
            alpha, E_new, phi_new, P_new = _wolfe(law, g, Kd, q, w, d, E, slope, dA, first=mem.empty)
            if alpha is None:
                return _finish(problem, State(q, w), P, r, E, False, it, n_conv, t0, "line search failed")
            s = alpha * d
            q = q + s
            phi = phi_new
            if (it + 1) % self.resync == 0:
                # the images K d are assembled, not convolved: round-off lets w drift from K q;
                # re-anchor w = K q (one extra convolution) so the metric stays exact
                w_exact = K.apply(q)
                n_conv += 1
                ks = w_exact - w
                w = w_exact
                g = g0 + w
                phi, P_new = law.evaluate(g)
            else:
                ks = alpha * Kd
                w = w + ks
                g = g0 + w
            P = P_new
            r_new = w - K.apply(P)
            n_conv += 1
            G_new = q - P
            y, ky = G_new - G, r_new - r
            sy = np.vdot(s, ky)
            if sy > 1e-14 * max(abs(np.vdot(s, ks)), 1e-300) and np.vdot(y, ky) > 0:
                mem.push(s.ravel(), ks.ravel(), y.ravel(), ky.ravel())
            r, G = r_new, G_new
        return _finish(problem, State(q, w), P, r, E, False, self.max_iter, n_conv, t0,
                       f"not converged in {self.max_iter} iterations")


def _wolfe(law, g, Kd, q, w, d, E0, slope0, dA, first, c1=1e-4, c2=0.9, max_eval=40):
    """Line search along d; element-wise only (no convolution).

    E(α) = dA[½ q·w + α d·w + ½ α² d·K d + Σ Φ(g + α K d)],
    E'(α) = dA[d·w + α d·K d − P(g + α K d)·K d].
    Accepts the strong Wolfe conditions, or near round-off the approximate Wolfe conditions of
    Hager & Zhang (2005): E(α) <= E(0) + 1e-11|E(0)| and 0.9 E'(0) <= E'(α) <= −0.8 E'(0).
    The bracket is narrowed by safeguarded secant steps on E'.
    """
    qw = 0.5 * np.vdot(q, w)
    a0 = np.vdot(d, w)
    a1 = np.vdot(d, Kd)
    eps_E = 1e-11 * max(1.0, abs(E0))

    def f(alpha):
        phi, P = law.evaluate(g + alpha * Kd)
        e = dA * (qw + alpha * a0 + 0.5 * alpha * alpha * a1 + phi.sum())
        de = dA * (a0 + alpha * a1 - np.vdot(P, Kd))
        return e, de, phi, P

    alpha = 1.0
    if first:  # scale the first trial step so that the gap moves by at most 0.25 ε
        m = float(np.max(np.abs(Kd)))
        if m > 0.25:
            alpha = 0.25 / m
    lo, de_lo = 0.0, slope0
    hi, de_hi = None, None
    best = None
    for _ in range(max_eval):
        e, de, phi, P = f(alpha)
        if not np.isfinite(e):
            hi, de_hi = alpha, None
        else:
            wolfe = e <= E0 + c1 * alpha * slope0 and abs(de) <= -c2 * slope0
            approx = e <= E0 + eps_E and c2 * slope0 <= de <= -0.8 * slope0
            if wolfe or approx:
                return alpha, e, phi, P
            if e <= E0 + eps_E and (best is None or abs(de) < best[0]):
                best = (abs(de), alpha, e, phi, P)
            if e > E0 + c1 * alpha * slope0 + eps_E or de > 0:
                hi, de_hi = alpha, (de if e <= E0 + eps_E or de > 0 else None)
            else:
                lo, de_lo = alpha, de
        if hi is None:
            alpha = 2.0 * alpha
            continue
        width = hi - lo
        if de_hi is not None and de_hi > de_lo:
            cand = lo - de_lo * width / (de_hi - de_lo)
        else:
            cand = lo + 0.5 * width
        alpha = min(max(cand, lo + 0.1 * width), hi - 0.1 * width)
    if best is not None:
        return best[1], best[2], best[3], best[4]
    return None, None, None, None


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

    tol: float = 1e-6
    max_iter: int = 200000
    dt0: float = 0.5
    growth: float = 1.2
    name: str = "vsr"

    def __post_init__(self):
        if not self.tol > 0:
            raise TengsimError(f"tol must be > 0, got {self.tol!r}")

    def solve(self, problem: Problem, start: State) -> Equilibrium:
        t0 = time.perf_counter()
        K, law, g0, dA = problem.kernel, problem.law, problem.g0, problem.dA
        q, w = start.q.copy(), start.w.copy()
        phi, P = law.evaluate(g0 + w)
        r = w - K.apply(P)
        E = dA * (0.5 * np.vdot(q, w) + phi.sum())
        n_conv, it, dt, cap = 1, 0, self.dt0, 1.0
        msg = ""
        norm = float(np.linalg.norm(r))
        while True:
            rmax = float(np.max(np.abs(r)))
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
            E_t = dA * (0.5 * np.vdot(q_try, w_try) + phi_t.sum())
            r_t = w_try - K.apply(P_t)
            n_conv += 1
            n_t = float(np.linalg.norm(r_t))
            # keep a step that lowers the energy (to round-off) without blowing up the residual;
            # a rejected Δτ caps later steps, which keeps the stiffest mode stable near convergence,
            # where energy changes fall below round-off
            if E_t <= E + 1e-13 * abs(E) and n_t <= 1.5 * norm:
                q, w, P, E, r, norm = q_try, w_try, P_t, E_t, r_t, n_t
                dt = min(dt * self.growth, cap)
            else:
                cap = 0.9 * dt
                dt *= 0.5
                if dt < 1e-14:
                    msg = f"pseudo-time step underflow (max|r| = {rmax:.2e})"
                    break
        return _finish(problem, State(q, w), P, r, E, msg == "converged", it, n_conv, t0, msg)


SOLVERS = {"fast": FastSolver, "vsr": VSRSolver}


def make_solver(name: str, tol: float = 1e-6, **kw):
    """Solver by name: 'fast' (L-BFGS) or 'vsr' (the paper's relaxation)."""
    try:
        cls = SOLVERS[name]
    except KeyError:
        raise TengsimError(f"unknown solver {name!r} (choose 'fast' or 'vsr')") from None
    return cls(tol=tol, **kw)
