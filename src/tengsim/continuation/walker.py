"""The branch walker: the one loop every path runs.  It solves each equilibrium of a branch from a
predicted start (the secant predictor), continues a fast solve stopped at its cap (:func:`persist`),
tests each step for a jump, and hands the choice of the steps to a step control it is given
(:mod:`tengsim.continuation.steps`: fixed steps bisected at jumps, or adaptive steps).

A step control is any object with ``plan(walker, eq, D_from, stops, on_grid)`` returning the walk's plan:

- ``predictor`` (bool) and ``c_max`` (the secant's reach, in steps of the last one);
- ``next()``: the D of the next step, or None at the end;
- ``refine(Da, Db)``: the step Da → Db jumped; True if the plan takes a shorter one instead (the solved
  state is then discarded), False to accept it as a jump;
- ``can_refine()`` (optional): whether ``refine`` would take a shorter step now.  A step whose predicted
  start jumped is then shortened at once, without the second solve from the step's start that confirms
  the jump (that solve would be discarded with the step; near a fold it is the walk's costliest, ~3× a
  row's iterations).  Without it, or when False, every jump is confirmed before it is refined or
  recorded, so a recorded jump is always one the unpredicted start makes too;
- ``accept(Da, eqa, Db, eqb, jump)``: the step is taken; returns ``(rows, inner)``: the rows to record
  now, in path order, each ``(D, eq, on_grid, jump)``, and the ``(D, eq)`` the plan solved strictly
  between Da and Db (they come before Db in the predictor's history);
- ``finish()``: the rows still held back at the end.
"""
from __future__ import annotations

from dataclasses import is_dataclass, replace
from typing import final

import numpy as np

from tengsim.solvers import Problem, State


def secant(s0: State, s1: State, c: float) -> State:
    """The state c steps of (s0 → s1) beyond s1: the secant predictor of a continuation step."""
    return State(s1.q + c * (s1.q - s0.q), s1.w + c * (s1.w - s0.w))


def jumped(eqa, eqb, dD: float, jump_h: float) -> bool:
    """Whether the gap field changed across a step by more than ``jump_h`` (ε) beyond the rigid shift |dD|."""
    return eqb.max_change(eqa) - abs(dD) > jump_h


def revise(eq, **changes):
    """``eq`` with ``changes``: ``dataclasses.replace``, or a wrapped equilibrium's own ``replace``
    (:class:`tengsim.solvers.mirror.FoldedEquilibrium`, which keeps the block)."""
    own = getattr(eq, "replace", None)
    return own(**changes) if own is not None else replace(eq, **changes)


PERSIST_FACTOR = 10  # a fast solve stopped at its cap goes on for up to this many times max_iter more


def persist(solver, problem: Problem, eq):
    """The automatic fallback of a fast solve that stopped at its iteration cap: go on from
    where it stopped, with ``PERSIST_FACTOR`` × max_iter more iterations.

    Where the law is stiffer than a pixel (pixel snap number ≫ 1) the fast solver's work is a long
    sequence of single pixels snapping in, then a slow settling of the stiff contact; both make progress
    every iteration, only more slowly than the cap allows (measured, docs/benchmarks.md "Stiff laws").
    Runs only on a solve that did not converge, so every equilibrium that converges within the cap is
    unchanged bit for bit.  Any other solver, or a solve that failed otherwise (line search, non-finite: not
    ``eq.capped``, which the solver sets by value),
    is returned as it is; a continued solve that still fails says so in its message, with both counts."""
    inner = getattr(solver, "inner", solver)
    if (PERSIST_FACTOR < 1 or not getattr(inner, "resumes_from_state", False) or not is_dataclass(inner)
            or not np.isfinite(eq.residual)
            or not getattr(eq, "capped", False)):
        return eq
    more = replace(inner, max_iter=PERSIST_FACTOR * int(inner.max_iter))
    more = solver.with_inner(more) if hasattr(solver, "with_inner") else more
    eq2 = more.solve(problem, eq.state)
    what = "converged" if eq2.converged else f"not converged ({eq2.message})"
    return revise(eq2, iterations=eq.iterations + eq2.iterations, n_conv=eq.n_conv + eq2.n_conv,
                   seconds=eq.seconds + eq2.seconds,
                   message=f"{what} after the cap: {eq.iterations} + {eq2.iterations} iterations "
                           f"(max|r| {eq.residual:.2e} at the cap)")


@final
class Walker:
    """Walks one branch of a path with the step control ``steps``; ``on_row(D, eq, on_grid, jump)``
    receives its rows in path order.  ``jump_h``: the jump criterion (:func:`jumped`).

    ``hist`` holds the last two accepted (D, state) of the branch (one after a jump), for the predictor,
    ``eq`` the last accepted equilibrium (a caller hands it over, so that no frame keeps an older one alive);
    ``spent`` counts the convolutions of every solve, recorded or discarded (jump checks, refining)."""

    def __init__(self, U0, law, kernel, solver, steps=None, on_row=None, jump_h: float = 0.3):
        self.law, self.kernel, self.solver, self.steps = law, kernel, solver, steps
        fold = getattr(solver, "fold_gap", None)  # a mirror solver takes g0 on its block
        self._U0s = U0 if fold is None else fold(U0, kernel)
        self.on_row, self.jump_h = on_row, jump_h
        self.hist: list = []
        self.F_before = None  # the force of hist[0] where reset() was given it
        self.eq = None  # the current (last accepted) equilibrium; the walker holds it, not its caller
        self.spent = 0

    def solve(self, D, start):
        """The equilibrium at D from ``start`` (continued past the cap, :func:`persist`)."""
        problem = Problem(self._U0s - D + 1.0, self.law, self.kernel)
        eq = self.solver.solve(problem, start)
        if not eq.converged:
            eq = persist(self.solver, problem, eq)
        self.spent += int(eq.n_conv)
        return eq

    def reset(self, D, eq, before=None) -> None:
        """Start afresh at the accepted ``eq`` at D: the predictor's history and the current equilibrium.
        ``before`` = (D0, state0, F0): the accepted state before it on the same branch and its force (the
        history then has two states; a step control's plan reads F0 as :attr:`F_before`)."""
        self.hist, self.eq = [(D, eq.state)], eq
        self.F_before = None
        if before is not None:
            D0, s0, self.F_before = before
            self.hist = [(D0, s0), (D, eq.state)]

    def take(self):
        """The current equilibrium, handed over: the walker keeps no reference to it."""
        eq, self.eq = self.eq, None
        return eq

    def push(self, D, state) -> None:
        """Accept (D, state) as the newest of the predictor's history."""
        self.hist = (self.hist + [(D, state)])[-2:]

    def begin(self, D, eq, on_grid: bool = True) -> None:
        """The branch's first row: ``eq`` at D, the history started there."""
        self.reset(D, eq)
        self.on_row(D, eq, on_grid, False)

    def predict(self, D, c_max: float = 1.5, c_min: float = 0.0):
        """(start, predicted): the secant start at D from the last two accepted states when D lies
        (c_min, c_max] steps of the last step beyond the newest, else the newest state."""
        D1, s1 = self.hist[-1]
        if len(self.hist) >= 2:
            D0, s0 = self.hist[-2]
            if D1 != D0:
                c = (D - D1) / (D1 - D0)
                if c_min < c <= c_max:
                    return secant(s0, s1, c), True
        return s1, False

    def jumped(self, eqa, eqb, dD) -> bool:
        return jumped(eqa, eqb, dD, self.jump_h)

    def step(self, Da, eqa, Db, predictor: bool = True, c_max: float = 1.5, shorten: bool = False):
        """(eqb, jump): the step Da → Db from the predicted start, solved again from ``eqa`` when the
        predicted one jumped (a predictor can overshoot onto another branch), unless ``shorten``: the
        caller then takes a shorter step instead, and the predicted jump is returned unconfirmed."""
        start, predicted = self.predict(Db, c_max) if predictor else (self.hist[-1][1], False)
        eqb = self.solve(Db, start)
        del start  # the solver copied it
        if predicted and self.jumped(eqa, eqb, Db - Da):
            if shorten:
                return eqb, True
            eqb = None  # discarded: freed before the solve again
            eqb = self.solve(Db, eqa.state)  # confirm without the predictor
        return eqb, self.jumped(eqa, eqb, Db - Da)

    def walk(self, stops, on_grid: bool = True, start=None, until=None):
        """From the current equilibrium (or ``start`` = (D, eq), the history kept as it is) through
        ``stops`` (the D the walk must visit, in path order, the last its end), the steps chosen by
        ``self.steps``; returns the last equilibrium, also the walker's current one.
        ``on_grid``: whether the stops are rows of the path's grid.  ``until()`` (optional), asked after
        each accepted step: True ends the walk there (its held-back rows recorded)."""
        D_from, eq = start if start is not None else (self.hist[-1][0], self.eq)
        plan = self.steps.plan(self, eq, D_from, stops, on_grid)
        Da = D_from
        can_refine = getattr(plan, "can_refine", None)
        while (Db := plan.next()) is not None:
            eqb, jump = self.step(Da, eq, Db, plan.predictor, plan.c_max,
                                  shorten=can_refine is not None and can_refine())
            if jump and plan.refine(Da, Db):
                eqb = None  # discarded: freed before the shorter step's solve
                continue
            rows, inner = plan.accept(Da, eq, Db, eqb, jump)
            for row in rows:
                self.on_row(*row)
            if jump:
                self.hist = [(Db, eqb.state)]
            else:
                self.hist = (self.hist + [(d, e.state) for d, e in inner] + [(Db, eqb.state)])[-2:]
            Da, eq = Db, eqb
            self.eq = eq
            if until is not None and until():
                break
        for row in plan.finish():
            self.on_row(*row)
        return eq

