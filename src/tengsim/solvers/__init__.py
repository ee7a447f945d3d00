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

from tengsim.registry import SOLVERS
from tengsim.solvers.fast import FastSolver
from tengsim.solvers.types import SOLVER_TOL, Equilibrium, Problem, State
from tengsim.solvers.vsr import VSRSolver


def make_solver(name: str, tol: float = SOLVER_TOL, **kw):
    """Solver by registered name (see ``tengsim.registry.SOLVERS``): 'fast' (L-BFGS) or 'vsr' (the paper's
    relaxation).  A registered solver is a factory ``(tol=..., **kw) -> solver``."""
    return SOLVERS.get(name)(tol=tol, **kw)


SOLVERS.register("fast", FastSolver, summary="L-BFGS in the kernel metric")
SOLVERS.register("vsr", VSRSolver, summary="the paper's relaxation")


__all__ = ["SOLVER_TOL", "Equilibrium", "FastSolver", "Problem", "State", "VSRSolver", "make_solver"]
