"""Solve a mirror-symmetric problem on its irreducible block (issue 22: symmetry-reduced kernels).

A :class:`MirrorSolver` wraps a solver ('fast', 'vsr').  Given a :class:`~tengsim.solvers.Problem` whose
kernel carries a mirror (duck-typed: ``kernel.mirror`` a :class:`tengsim.grid.Mirror`, ``kernel.reduced``
the kernel acting on the block; tengsim.kernels.mirror builds one) and ``g0`` on the full grid, it
solves the weighted problem on the block (g0 reduced, weights = the block pixels' multiplicities) and
returns an :class:`~tengsim.solvers.Equilibrium` whose ``state`` lives on the block (the path's secant
predictions and starts then cost a block's memory) and whose ``H`` and ``P`` are unfolded to the full
grid, so that everything reading a solution (path, recorder, observers, status, maps) sees the full grid.
A start on the full grid (the path's ``State.zero``) is reduced first.

For a symmetric g0 the block's iterates are the full grid's (the full solver keeps a symmetric iterate
symmetric, and the weighted sums are the full grid's sums), so the answers agree to round-off.
A block solve cannot leave the symmetry it imposes: an equilibrium that turns unstable to a mode breaking a
mirror stays put here (``symmetry = "off"`` checks).
This module imports no kernel: the kernels and the solvers are independent packages.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from tengsim.errors import TengsimError
from tengsim.solvers import Equilibrium, Problem, State


class MirrorSolver:
    """``inner`` on the irreducible block of a mirror kernel's problem; its settings (``name``, ``tol``,
    ``memory``, ...) are the inner solver's."""

    def __init__(self, inner):
        if isinstance(inner, MirrorSolver):
            inner = inner.inner
        self.inner = inner
        self._weights = (None, None)  # (mirror, its weights): one array per grid, not one per solve

    def __getattr__(self, name):  # name, tol, memory, max_iter, monitor, ... of the inner solver
        if name in ("inner", "_weights"):
            raise AttributeError(name)
        return getattr(self.inner, name)

    def __repr__(self):
        return f"MirrorSolver({self.inner!r})"

    def __eq__(self, other):
        return isinstance(other, MirrorSolver) and other.inner == self.inner

    def __hash__(self):
        return hash(("mirror", self.inner))

    def with_inner(self, inner) -> "MirrorSolver":
        return MirrorSolver(inner)

    def replace(self, **changes) -> "MirrorSolver":
        """The same wrapper around ``dataclasses.replace(inner, **changes)``."""
        return MirrorSolver(replace(self.inner, **changes))

    def solve(self, problem: Problem, start: State) -> Equilibrium:
        K = problem.kernel
        mirror, reduced = getattr(K, "mirror", None), getattr(K, "reduced", None)
        if mirror is None or reduced is None:
            raise TengsimError("MirrorSolver needs a mirror kernel (with .mirror and .reduced)")
        full, block = tuple(mirror.grid.shape), tuple(mirror.reduced_shape)
        g0 = np.asarray(problem.g0, dtype=float)
        g0b = mirror.reduce(g0) if g0.shape == full else g0
        if g0b.shape != block:
            raise TengsimError(f"g0 of shape {g0.shape} is neither the full {full} grid nor the {block} block")
        start_b = _reduce_state(start, mirror, full, block)
        cached, m = self._weights
        if cached is not mirror:
            m = mirror.weights()
            self._weights = (mirror, m)
        if problem.weights is not None:
            raise TengsimError("MirrorSolver: the problem is weighted already")
        eq = self.inner.solve(Problem(g0b, problem.law, reduced, weights=m), start_b)
        return Equilibrium(eq.state, mirror.unfold(eq.H), mirror.unfold(eq.P), eq.residual, eq.converged,
                           eq.iterations, eq.n_conv, eq.energy, eq.seconds, eq.message)


def _reduce_state(start: State, mirror, full, block) -> State:
    q, w = np.asarray(start.q), np.asarray(start.w)
    if q.shape == block and w.shape == block:
        return start
    if q.shape == full and w.shape == full:
        return State(mirror.reduce(q), mirror.reduce(w))
    raise TengsimError(f"start state of shape {q.shape} is neither the full {full} grid nor the {block} block")
