"""The branch walker: solves each equilibrium of a branch from a predicted start (the secant predictor),
continues a fast solve stopped at its cap (:func:`persist`), and refines a step that jumps by bisection.
"""
from __future__ import annotations

from dataclasses import dataclass, is_dataclass, replace

import numpy as np

from tengsim.solvers import Problem, State


def secant(s0: State, s1: State, c: float) -> State:
    """The state c steps of (s0 → s1) beyond s1: the secant predictor of a continuation step."""
    return State(s1.q + c * (s1.q - s0.q), s1.w + c * (s1.w - s0.w))


PERSIST_FACTOR = 10  # a fast solve stopped at its cap goes on for up to this many times max_iter more


def persist(solver, problem: Problem, eq):
    """The automatic fallback of a fast solve that stopped at its iteration cap (issue 23): go on from
    where it stopped, with ``PERSIST_FACTOR`` × max_iter more iterations.

    Where the law is stiffer than a pixel (pixel snap number ≫ 1) the fast solver's work is a long
    sequence of single pixels snapping in, then a slow settling of the stiff contact; both make progress
    every iteration, only more slowly than the cap allows (measured, docs/benchmarks.md "Stiff laws").
    Runs only on a solve that did not converge, so every equilibrium that converges within the cap is
    unchanged bit for bit.  Any other solver, or a solve that failed otherwise (line search, non-finite),
    is returned as it is; a continued solve that still fails says so in its message, with both counts."""
    inner = getattr(solver, "inner", solver)
    if (PERSIST_FACTOR < 1 or not getattr(inner, "resumes_from_state", False) or not is_dataclass(inner)
            or not np.isfinite(eq.residual)
            or not str(eq.message).startswith("not converged")):
        return eq
    more = replace(inner, max_iter=PERSIST_FACTOR * int(inner.max_iter))
    more = solver.with_inner(more) if hasattr(solver, "with_inner") else more
    eq2 = more.solve(problem, eq.state)
    what = "converged" if eq2.converged else f"not converged ({eq2.message})"
    return replace(eq2, iterations=eq.iterations + eq2.iterations, n_conv=eq.n_conv + eq2.n_conv,
                   seconds=eq.seconds + eq2.seconds,
                   message=f"{what} after the cap: {eq.iterations} + {eq2.iterations} iterations "
                           f"(max|r| {eq.residual:.2e} at the cap)")


class Branch:
    """Walks one branch, refining steps and predicting starts."""

    def __init__(self, U0, law, kernel, solver, spec, on_row):
        self.U0, self.law, self.kernel, self.solver, self.spec = U0, law, kernel, solver, spec
        fold = getattr(solver, "fold_gap", None)  # a mirror solver takes g0 on its block
        self._U0s = U0 if fold is None else fold(U0, kernel)
        self.on_row = on_row
        self.hist: list = []  # accepted (D, state) on this branch, newest last
        self.spent = 0  # convolutions of every solve of this branch, recorded or discarded (jump checks, refining)

    def solve(self, D, start):
        problem = Problem(self._U0s - D + 1.0, self.law, self.kernel)
        eq = self.solver.solve(problem, start)
        if not eq.converged:
            eq = persist(self.solver, problem, eq)
        self.spent += int(eq.n_conv)
        return eq

    def _start(self, D):
        (D1, s1) = self.hist[-1]
        if self.spec.predictor and len(self.hist) >= 2:
            D0, s0 = self.hist[-2]
            if D1 != D0:
                c = (D - D1) / (D1 - D0)
                if 0 < c <= 1.5:
                    return secant(s0, s1, c), True
        return s1, False

    def _jumped(self, eqa, eqb, dD):
        return eqb.max_change(eqa) - abs(dD) > self.spec.jump_h

    def advance(self, Da, eqa, Db, level, on_grid):
        start, predicted = self._start(Db)
        eqb = self.solve(Db, start)
        if predicted and self._jumped(eqa, eqb, Db - Da):
            eqb = self.solve(Db, eqa.state)  # confirm without the predictor
        if self._jumped(eqa, eqb, Db - Da):
            if level < self.spec.refine_levels:
                mid = 0.5 * (Da + Db)
                eqm = self.advance(Da, eqa, mid, level + 1, False)
                return self.advance(mid, eqm, Db, level + 1, on_grid)
            jump = True
        else:
            jump = False
        self.hist = (self.hist + [(Db, eqb.state)])[-2:]
        if jump:
            self.hist = self.hist[-1:]
        self.on_row(Db, eqb, on_grid, jump)
        return eqb


@dataclass
class StateOnly:
    """A bare state holder (``.state``) for rows kept only as states."""

    state: State
