"""Cold equilibria of laws stiff at the pixel scale: continuation in the law's range, on nested grids
(measured in docs/benchmarks.md, "Stiff laws": the range homotopy).

Where the pixel snap number (steepest softening of the law × pixel compliance) is above 1, the fast solver
from the undeformed state spends its iterations on a long sequence of junctions snapping into contact
one after another; their number, and the iterations, grow steeply with the cell (a rough surface at snap
number 3.4: 1930 iterations at 135², 21 924 at 273², none in 33 000 at 525²).

:class:`HomotopySolver` ('homotopy') reaches an equilibrium of the true law through a chain of softer
ones.  The law of stage ℓ is the true law with its range stretched by s = 2^ℓ about its contact gap g_c
(``law.g_zero``, 1 for LJ93):

    Φ_s(g) = Φ(g_c + (g − g_c)/s),   P_s(g) = P(g_c + (g − g_c)/s) / s,

the same work of adhesion and contact gap, the tension /s, the stiffness /s² (:class:`Softened`); the
rigid approach D and the gap g0 are not touched (the separation is the physical one).  On a periodic
kernel stage ℓ is solved on a grid 2^ℓ times coarser (g0 Fourier-truncated): pixel and range grow
together, so every stage has the same pixel/range ratio and its snap number is the true one / 2^ℓ.
Each stage starts from the one before (q Fourier-interpolated, w = K q: one convolution); the
coarse stages are only starts and are solved to ``stage_tol``; the last stage is the caller's problem
(true law, given grid, given kernel) from the interpolated start, solved to ``tol`` by the fast
solver.  So what is returned is judged like any fast solve: a stable equilibrium of the true law
(residual of Eq. (9) <= tol).  With adhesion a problem has many; the chain settles in one that may
differ from the cold fast solve's (measured: lower energy, slightly less contact area).

Only a cold start (q = 0 everywhere) takes the chain; a warm start (the path's next equilibrium, or a
continued solve, tengsim.continuation.persist) is a plain fast solve with the same settings, so a
branch keeps its history.  Kernels that are not periodic, distributed ones and weighted (mirror)
problems run the stages on the given grid (range only, no coarse grids).
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace

import numpy as np

from tengsim.grid import fourier_resample
from tengsim.errors import TengsimError
from tengsim.laws.safe import safe
from tengsim.grid import Grid
from tengsim.registry import SOLVERS
from tengsim.solvers.fast import FastSolver
from tengsim.solvers.types import SOLVER_TOL, Equilibrium, Problem, State
from tengsim.solvers._reduce import for_kernel


class Softened:
    """``law`` with its range stretched by ``s`` about its contact gap g_c: Φ_s(g) = Φ(x), P_s(g) = P(x)/s,
    x = g_c + (g − g_c)/s (a duck-typed law: what the solvers call; the law safe below its g_safe, so the
    softened one below its own, stretched, ``g_safe``)."""

    def __init__(self, law, s: float):
        if not (isinstance(s, (int, float)) and s >= 1 and math.isfinite(s)):
            raise TengsimError(f"the range factor must be a finite number >= 1, got {s!r}")
        gc = getattr(law, "g_zero", None)
        self.law, self.s, self.gc = safe(law), float(s), float(gc) if gc is not None else 1.0
        self.g_safe = self.gc + self.s * (float(law.g_safe) - self.gc)

    def _x(self, g):
        x = np.subtract(g, self.gc, dtype=float)
        x *= 1.0 / self.s
        x += self.gc
        return x

    def evaluate(self, g):
        phi, p = self.law.evaluate(self._x(g))
        return phi, p / self.s

    def energy_pressure(self, g, out, work) -> float:
        e = self.law.energy_pressure(self._x(g), out, work)
        out *= 1.0 / self.s
        return e

    def energy(self, g):
        return self.evaluate(g)[0]

    def pressure(self, g):
        return self.evaluate(g)[1]

    def params(self) -> dict:
        return {**self.law.params(), "range_factor": self.s}


@dataclass
class Stage:
    """One stage of a homotopy solve: its grid shape, range factor, iterations, convolutions (on its own
    grid, the interpolation's included), seconds, residual and whether it reached its tolerance."""

    shape: tuple
    s: float
    iterations: int
    n_conv: int
    seconds: float
    residual: float
    converged: bool


def plan_stages(problem: Problem, levels: int | None, min_side: int) -> list:
    """[(shape, s), ...] from the softest stage to the caller's problem ((its shape), 1.0)."""
    shape = tuple(np.shape(problem.g0))
    K = problem.kernel
    nested = (bool(getattr(K, "periodic", False)) and hasattr(K, "film_params") and hasattr(K, "coupling")
              and problem.weights is None and for_kernel(K) is None)
    if levels is None:
        if not nested:
            levels = 2
        else:
            levels = 0
            while min(shape) / 2 ** (levels + 1) >= min_side:
                levels += 1
    out = []
    for lvl in range(levels, -1, -1):
        sub = tuple(max(3, round(n / 2**lvl)) for n in shape) if nested else shape
        out.append((sub, float(2**lvl)))
    return out


def homotopy_solve(fast: FastSolver, problem: Problem, levels: int | None = None, min_side: int = 32,
                   stage_tol: float = 1e-3, on_stage=None):
    """The chain of :class:`HomotopySolver` from the undeformed state: (the last stage's equilibrium with
    every stage's iterations and convolutions added, [Stage, ...]).  ``fast`` solves each stage (its
    ``tol`` the last one's; the others' ``max(stage_tol, tol)``)."""
    t0 = time.perf_counter()
    plan = plan_stages(problem, levels, min_side)
    K, fine = problem.kernel, tuple(np.shape(problem.g0))
    stages, q, eq = [], None, None
    for i, (shape, s) in enumerate(plan):
        ts = time.perf_counter()
        last = i == len(plan) - 1
        if shape == fine:
            k, g0 = K, problem.g0
        else:
            cg = Grid(shape[0], shape[1], K.grid.lx / shape[0], K.grid.ly / shape[1])
            k = type(K)(cg, K.coupling, **K.film_params())
            g0 = fourier_resample(np.asarray(problem.g0, dtype=float), shape)
        n_conv = 0
        if q is None:
            start = State.zero(shape)
        elif q.shape == shape:
            start = eq.state
        else:
            qi = fourier_resample(q, shape)
            start = State(qi, np.asarray(k.apply(qi)))
            n_conv = 1
        law = problem.law if s == 1.0 else Softened(problem.law, s)
        solver = fast if last else replace(fast, tol=max(float(stage_tol), fast.tol))
        sub = problem if (last and shape == fine) else Problem(g0, law, k, problem.weights)
        eq = solver.solve(sub, start)
        stages.append(Stage(shape, s, eq.iterations, eq.n_conv + n_conv, time.perf_counter() - ts,
                            eq.residual, eq.converged))
        if on_stage is not None:
            on_stage(stages[-1])
        q = np.asarray(eq.state.q)
    its = sum(st.iterations for st in stages)
    nc = sum(st.n_conv for st in stages)
    fine_eq = sum(st.n_conv * np.prod(st.shape) / np.prod(fine) for st in stages)
    chain = ", ".join(f"{st.shape[0]}×{st.shape[1]} s={st.s:g}: {st.iterations}" for st in stages)
    msg = (f"{eq.message} (range homotopy, iterations per stage: {chain}; "
           f"{fine_eq:.0f} fine-grid convolutions' worth)")
    out = replace(eq, iterations=its, n_conv=nc, seconds=time.perf_counter() - t0, message=msg)
    return out, stages


@dataclass(frozen=True)
class HomotopySolver:
    """The fast solver, reaching a cold equilibrium through laws of stretched range on coarser grids
    (module doc).  ``tol``, ``max_iter`` (per stage), ``memory``, ``resync``, ``monitor``,
    ``monitor_every``: the fast solver's (``inner``); ``levels``: the number of softened stages (None:
    on a periodic kernel halve the grid while its shorter side stays >= ``min_side``; otherwise 2, i.e.
    ranges 4, 2, 1 on the given grid); ``stage_tol``: the softened stages' tolerance (ε).  Warm starts:
    a plain fast solve.  ``iterations`` and ``n_conv`` of a cold solve add every stage's (a coarse
    grid's convolutions are cheaper: the message gives their fine-grid worth)."""

    tol: float = SOLVER_TOL
    max_iter: int = 3000
    memory: int = 10
    resync: int = 25
    levels: int | None = None
    min_side: int = 32
    stage_tol: float = 1e-3
    name: str = "homotopy"
    monitor: object = None
    monitor_every: int = 100

    def __post_init__(self):
        if self.levels is not None and (isinstance(self.levels, bool) or not isinstance(self.levels, int)
                                        or not 0 <= self.levels <= 12):
            raise TengsimError(f"homotopy levels must be an integer from 0 to 12 (or None: automatic), "
                               f"got {self.levels!r}")
        if isinstance(self.min_side, bool) or not isinstance(self.min_side, int) or self.min_side < 3:
            raise TengsimError(f"homotopy min_side must be an integer >= 3, got {self.min_side!r}")
        if not (isinstance(self.stage_tol, (int, float)) and self.stage_tol > 0 and math.isfinite(self.stage_tol)):
            raise TengsimError(f"homotopy stage_tol must be a finite number > 0, got {self.stage_tol!r}")
        # the fast solver (its own checks: tol, memory, monitor_every), kept with its workspace; no field
        object.__setattr__(self, "_inner", FastSolver(tol=self.tol, max_iter=self.max_iter, memory=self.memory,
                                                      resync=self.resync, monitor=self.monitor,
                                                      monitor_every=self.monitor_every))

    @property
    def inner(self) -> FastSolver:
        return self._inner

    def with_inner(self, inner: FastSolver) -> "HomotopySolver":
        """The same chain around another fast solver's settings (tengsim.continuation.persist)."""
        return replace(self, tol=inner.tol, max_iter=inner.max_iter, memory=inner.memory, resync=inner.resync,
                       monitor=inner.monitor, monitor_every=inner.monitor_every)

    def solve(self, problem: Problem, start: State) -> Equilibrium:
        fast = self.inner
        if np.any(start.q) or np.any(start.w):
            return fast.solve(problem, start)
        return homotopy_solve(fast, problem, self.levels, self.min_side, self.stage_tol)[0]


SOLVERS.register("homotopy", HomotopySolver,
                 summary="fast, cold starts through laws of longer range on coarser grids (stiff laws)")
