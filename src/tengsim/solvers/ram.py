"""The adhesive constrained solver 'ram': a hard wall with the law's adhesion beyond it, the total energy
minimised over the gap by a projected, preconditioned conjugate gradient (Rey, Anciaux & Molinari, Comput.
Mech. 2017; the loop is tengsim.solvers._ram_core, its doc gives the iteration and the convergence criterion).

Laws.  The solver asks the law for its hard-wall limit, ``law.hard_wall()`` (tengsim.laws.cohesive): the
traction, energy and curvature beyond a rigid wall at g = 1 — ``repulsive``: the wall alone; ``md``: Maugis'
sharp Dugdale zone (σ0 over h0 = W/σ0, as Maugis wrote it); ``exp``: −(W/ρ) e^{−u/ρ}; a plugin's law: the limit
it declares.  A law that declares none (LJ93) is refused in one line naming the solvers that can.

Unlike 'pk''s cohesive loops (a zone updated around or inside the contact's solve), the contact set and the
cohesive tractions are one descent of one energy: every iteration lowers it, so the solve converges at every
load to a local minimum (a stable state) and a warm start keeps its branch.  Displacement control (the mean
gap of a periodic half-space, the approach of an isolated cell; a kernel that is not periodic is embedded in a
periodic domain of twice the cell, tengsim.solvers._ram_core.Compliance).

Returned: q = P = p the pressure (W/ε), w = K p, H = u the gap above the wall (0 exactly on the contact),
``residual`` the gap residual (ε), ``n_conv`` the FFT pairs (K or K⁻¹), ``iterations`` the CG's.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from tengsim import backend
from tengsim.errors import TengsimError
from tengsim.registry import SOLVERS
from tengsim.solvers._ram_core import Compliance, solve_gap
from tengsim.solvers.types import SOLVER_TOL, Equilibrium, Problem, State, check_settings


def limit_of(law, solver: str = "ram"):
    """The law's hard-wall limit, or one line naming the solvers that solve a law without one."""
    lim = law.hard_wall() if hasattr(law, "hard_wall") else None
    if lim is None:
        raise TengsimError(f"solver '{solver}' solves a law's hard-wall limit; law {type(law).__name__} declares "
                           "none (Law.hard_wall): use solver 'fast' (or 'homotopy' for a law stiff at the pixel scale)")
    return lim


def supports(law) -> bool:
    """Does ``law`` declare a hard-wall limit (can 'ram' solve it)?"""
    return hasattr(law, "hard_wall") and law.hard_wall() is not None


@dataclass(frozen=True)
class RAMSolver:
    """The adhesive constrained CG (module doc).  ``tol``: the gap residual (ε); ``max_iter``: iterations;
    ``start``: where the mean gap is held (a periodic half-space), 'shifted' (the default) starts from the start
    state's displacement at the new gap, h + w (every tengsim solver's warm start), 'scaled' from the start
    state's own gap (its contact kept) scaled to the new mean; the problem is non-convex, so a large step may
    end in another local minimum from each (docs/benchmarks.md: on the 256² rough path 'shifted' lands in
    Tamaas' states at every step, 'scaled' keeps more contact on a retraction); elsewhere always h + w;
    ``monitor(iteration, residual, nan)``: progress every ``monitor_every`` iterations."""

    tol: float = SOLVER_TOL
    max_iter: int = 20000
    name: str = "ram"
    start: str = "shifted"
    monitor: object = None
    monitor_every: int = 50
    weighted_block: ClassVar[bool] = False
    splits_over_mpi: ClassVar[bool] = False
    resumes_from_state: ClassVar[bool] = False

    def __post_init__(self):
        check_settings(self, ("max_iter", "monitor_every"))
        if self.start not in ("scaled", "shifted"):
            raise TengsimError(f"start must be 'scaled' or 'shifted', got {self.start!r}")

    @staticmethod
    def solves(law) -> bool:
        return supports(law)

    def solve(self, problem: Problem, start: State) -> Equilibrium:
        """The equilibrium at the problem's gap g0 (displacement control), from ``start``."""
        t0 = time.perf_counter()
        if problem.weights is not None:
            raise TengsimError(f"solver '{self.name}' does not solve weighted (mirror-block) problems; "
                               "use solver 'fast' for a mirror-symmetric cell")
        lim = limit_of(problem.law, self.name)
        shape = np.shape(problem.g0)
        op = Compliance(problem.kernel, shape)
        h_cell = np.asarray(problem.g0, dtype=float) - 1.0
        if op.pinned and not h_cell.mean() > 0:
            z = backend.zeros(shape)
            msg = (f"the mean gap {h_cell.mean() + 1.0:.6g} ε is at or below the wall (1 ε) on a periodic "
                   "half-space: no state under displacement control")
            return Equilibrium(State(z, z.copy()), h_cell.copy(), z.copy(), math.inf, False, 0, 0, math.nan,
                               time.perf_counter() - t0, msg)
        h = op.embed(h_cell)
        cell = op.embed(~backend.zeros(shape, bool), False).astype(bool) if op.embedded else None
        q = np.asarray(start.q, dtype=float)
        u = h + op.apply(op.embed(q)) if np.any(q) else h.copy()
        if op.pinned and self.start == "scaled" and np.any(q):
            u -= float(u.min())                       # the start's own gap (its contact at 0)
        if cell is None:
            np.maximum(u, 0.0, out=u)
        else:
            u[cell & (u < 0)] = 0.0
        if op.pinned:
            u *= float(h.mean()) / float(u.mean())                       # ... scaled to the held mean
        every = self.monitor_every
        mon = None if self.monitor is None else (
            lambda it, res: self.monitor(it, res, math.nan) if it % every == 0 else None)
        r = solve_gap(op, h, cell, lim, u, float(self.tol), self.max_iter, mon)
        u_c, p_c = op.crop(r.u), op.crop(r.p)
        w = u_c - h_cell
        E = problem.dA * r.energy
        msg = r.message if not r.converged else (
            f"converged (gap residual {r.residual:.3g} ε, unbalanced pressure {r.pressure_residual:.3g} W/ε)")
        return Equilibrium(State(p_c, w), u_c, p_c.copy(), float(r.residual), bool(r.converged), int(r.iterations),
                           int(op.count), float(E), time.perf_counter() - t0, msg)


SOLVERS.register("ram", RAMSolver, summary="adhesive constrained CG on the gap (Rey–Anciaux–Molinari): hard wall "
                 "+ the law's cohesive limit (md sharp, exp, a plugin's)")

__all__ = ["RAMSolver", "limit_of", "supports"]
