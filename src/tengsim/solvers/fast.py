"""The fast solver: L-BFGS on E(q) in the metric of the elastic kernel (see :class:`FastSolver`)."""
from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from tengsim.errors import TengsimError
from tengsim.solvers._reduce import for_kernel
from tengsim.solvers._weights import Weights
from tengsim.solvers._descent import _Descent
from tengsim.solvers._workspace import Spare
from tengsim.solvers.types import SOLVER_TOL, Equilibrium, Problem, State


@dataclass(frozen=True)
class FastSolver:
    """L-BFGS on E(q) in the metric of the elastic kernel (K-preconditioned), Wolfe line search.

    Cost in convolutions (FFT pairs, the unit of ``Equilibrium.n_conv``): one to start (K P at the
    start state), one per iteration (K P(g) at the new state), and one more every ``resync``
    iterations to re-anchor w = K q; one solve of k iterations spends 1 + k + ⌊k / resync⌋.  Nothing
    else convolves: the direction's image K d is assembled from stored images (K s = Δw, K y = Δr,
    K G = r) by the compact L-BFGS form (tengsim.solvers._lbfgs), and the line search along d needs only
    element-wise work, since g(α) = g + α K d (tengsim.solvers._linesearch).  Converged when max|r| <= ``tol``.
    ``monitor(iteration, max|r|, energy)``, if given, is called every ``monitor_every`` iterations
    (progress on long solves).

    The arrays of an iteration live in a workspace (tengsim.solvers._workspace), allocated once per grid and,
    on grids up to 512² points, kept by the solver for its next solve (a path's equilibria share one).
    Host syncs: at most one per iteration, plus one per line-search trial swept on its own.  A sweep's
    sums stay backend scalars and come over in one ``backend.sync`` at its end; the new residual's
    sweep has none of its own: its numbers (max|r|, the new L-BFGS pair's curvature test) ride on the
    next direction's sync, with the direction's sums and the line search's first trial α = 1 swept
    along (or max|K d| for a first step).  So the convergence test sees a residual one sweep late (a
    converged solve sweeps one direction in vain), and the memory stores each pair unconfirmed, on
    backend arrays, and takes it back exactly in the rare case its test fails (then the direction is
    swept again).  A re-anchoring step adds one (its law sweep's sums with q·w); the start two; a
    weighted (mirror) solve syncs as the plain one, a distributed one syncs each residual (its sums
    must be added over the ranks before the memory's update).  The law is evaluated through its safe
    extension (tengsim.laws.safe), its hot path unchecked and the sweep's smallest gap checked in
    that same sync.
    """

    tol: float = SOLVER_TOL
    max_iter: int = 3000
    memory: int = 10
    resync: int = 25
    name: str = "fast"
    weighted_block: ClassVar[bool] = True  # solves on a mirror block with weighted sums (solvers.mirror)
    splits_over_mpi: ClassVar[bool] = True  # runs on one MPI rank's slab (solvers.distributed)
    resumes_from_state: ClassVar[bool] = True  # continuation.persist may go on from its capped state
    monitor: object = None
    monitor_every: int = 100

    def __post_init__(self):
        if not self.tol > 0:
            raise TengsimError(f"tol must be > 0, got {self.tol!r}")
        if int(self.memory) < 1:
            raise TengsimError(f"memory must be >= 1, got {self.memory!r}")
        if int(self.monitor_every) < 1:
            raise TengsimError(f"monitor_every must be >= 1, got {self.monitor_every!r}")
        # the spare workspace is no field: not in fields(), repr, ==, hash or replace()
        object.__setattr__(self, "_spare", Spare())

    def __getstate__(self):  # copies and pickles start without a spare workspace
        return {k: v for k, v in self.__dict__.items() if k != "_spare"}

    def __setstate__(self, state):
        self.__dict__.update(state, _spare=Spare())

    def solve(self, problem: Problem, start: State) -> Equilibrium:
        t0 = time.perf_counter()
        lines = None if problem.weights is None else Weights(problem.weights, np.shape(problem.g0))
        dA = problem.dA if lines is None else problem.dA * lines.scale
        ws = self._spare.take(np.size(problem.g0), self.memory, dA)
        ws.memory.lines = lines
        ws.memory.red = red = for_kernel(problem.kernel)  # a slab-distributed kernel: sums over all ranks
        if red is not None and lines is not None:
            raise TengsimError("a distributed solve cannot also be a weighted (mirror) one")
        try:
            # the law's unchecked hot path may meet g <= 0 in a pass that is then redone checked
            # (tengsim.laws.safe): no warnings from it (sweeps on threads take this state along)
            with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
                return self._descend(_Descent(problem, start, ws, lines), t0)
        finally:
            self._spare.give(ws)

    def _descend(self, run: "_Descent", t0: float) -> Equilibrium:
        search = run.search
        for it in range(self.max_iter + 1):
            # the residual of the last step comes over with the next direction's sweep (one sync)
            got = run.direction(self.tol) if it < self.max_iter else run.settle()
            if not math.isfinite(run.rmax):
                return run.finish(False, it, "non-finite residual", t0)
            if run.rmax <= self.tol:
                return run.finish(True, it, "converged", t0)
            if it == self.max_iter:
                break
            if self.monitor is not None and it % self.monitor_every == 0:
                self.monitor(it, run.rmax, run.E)
            ray, alpha0 = got
            first = None if run.first is None else search.finish(alpha0, ray, *run.first)  # swept with d
            trial = search.search(alpha0, ray, run.lowest_energy(), first)
            if trial is None:
                return run.finish(False, it, "line search failed", t0)
            resync = (it + 1) % self.resync == 0
            run.accept(trial, ray, resync)                     # E at the new point (re-anchor w = K q)
            pair = run.new_residual(trial.alpha, resync)       # one convolution: r, G, y, K y
            run.remember(trial.alpha, ray, pair, resync)       # the L-BFGS memory (the pair unconfirmed)
        return run.finish(False, self.max_iter, f"not converged in {self.max_iter} iterations", t0, capped=True)
