"""Solve a mirror-symmetric problem on its irreducible block (symmetry-reduced kernels).

A :class:`MirrorSolver` wraps a solver ('fast', 'vsr').  Given a :class:`~tengsim.solvers.Problem` whose
kernel carries a mirror (duck-typed: ``kernel.mirror`` a :class:`tengsim.grid.Mirror`, ``kernel.reduced``
the kernel acting on the block; tengsim.kernels.mirror builds one) and ``g0`` on the full grid, it
solves the weighted problem on the block (g0 reduced, weights = the block pixels' multiplicities) and
returns a :class:`FoldedEquilibrium`, the block's equilibrium wrapped: its ``state`` lives on the block (the
path's secant predictions and starts then cost a block's memory) and its ``H`` and ``P`` are unfolded to
the full grid when read, so that everything reading a solution (path, recorder, observers, status, maps) sees the full grid.
A start on the full grid (the path's ``State.zero``) is reduced first.

For a symmetric g0 the block's iterates are the full grid's (the full solver keeps a symmetric iterate
symmetric, and the weighted sums are the full grid's sums), so the answers agree to round-off.
A block solve cannot leave the symmetry it imposes: an equilibrium that turns unstable to a mode breaking a
mirror stays put here (``symmetry = "off"`` checks).
This module imports no kernel: the kernels and the solvers are independent packages.
"""
from __future__ import annotations

from dataclasses import dataclass, fields, replace

import numpy as np

from tengsim.errors import TengsimError
from tengsim.solvers.types import Equilibrium, Problem, State


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

    def fold_gap(self, U0, kernel):
        """The block of the full-grid gap ``U0`` for problems on ``kernel`` (its mirror's; ``U0`` itself
        when the kernel has none): a path's g0 = U0 − D + 1 then costs a block's memory."""
        mirror = getattr(kernel, "mirror", None)
        U0 = np.asarray(U0, dtype=float)
        if mirror is None or U0.shape != tuple(mirror.grid.shape):
            return U0
        return mirror.reduce(U0)

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
        return FoldedEquilibrium(eq, mirror)


@dataclass(frozen=True)
class FoldedEquilibrium:
    """The equilibrium of a mirror-symmetric problem: the block's :class:`~tengsim.solvers.Equilibrium`
    (``block``) wrapped with the ``mirror`` that unfolds it, read as the full grid's.  ``H`` and ``P`` are
    unfolded when read (a new read-only array each read), every other field is the block's.  The
    equilibria a path holds (secant, jump tests) then cost a block's memory, and no full-grid field
    outlives its reader; a reader of many fields takes :meth:`unfolded` once."""

    block: Equilibrium
    mirror: object

    def _full(self, block):
        full = self.mirror.unfold(block)
        full.flags.writeable = False  # as a plain equilibrium's: a reader that wants to write copies
        return full

    H = property(lambda self: self._full(self.block.H))
    P = property(lambda self: self._full(self.block.P))

    def unfolded(self) -> Equilibrium:
        """The plain equilibrium on the full grid (H and P unfolded once)."""
        return replace(self.block, H=self.H, P=self.P)

    def replace(self, **changes) -> "FoldedEquilibrium":
        """``dataclasses.replace`` on the block (its H and P stay the block's)."""
        return FoldedEquilibrium(replace(self.block, **changes), self.mirror)

    def max_change(self, other) -> float:
        """max |H − other.H|: on the blocks when both are folded by the same mirror (the unfolded fields
        only repeat the block's values)."""
        if isinstance(other, FoldedEquilibrium) and other.mirror is self.mirror:
            return float(np.max(np.abs(self.block.H - other.block.H)))
        return float(np.max(np.abs(self.H - other.H)))


for _f in fields(Equilibrium):  # the rest of the record reads through to the block's
    if _f.name not in ("H", "P"):
        setattr(FoldedEquilibrium, _f.name, property(lambda self, _n=_f.name: getattr(self.block, _n)))
del _f


def _reduce_state(start: State, mirror, full, block) -> State:
    q, w = np.asarray(start.q), np.asarray(start.w)
    if q.shape == block and w.shape == block:
        return start
    if q.shape == full and w.shape == full:
        return State(mirror.reduce(q), mirror.reduce(w))
    raise TengsimError(f"start state of shape {q.shape} is neither the full {full} grid nor the {block} block")
