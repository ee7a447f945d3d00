"""A solver over a slab-distributed periodic kernel (tengsim.kernels.distributed): each MPI rank
solves for its own rows, the solver unchanged but for its sums and maxima, which the kernel's
communicator reduces over all ranks (tengsim.solvers._reduce).

:class:`SlabSolver` wraps a solver (fast or vsr): it takes a Problem on the full grid, poses it on this
rank's rows, and returns an Equilibrium whose ``state`` holds the rank's rows (the path's
predictions then combine slabs) and whose ``H`` and ``P`` are gathered onto the full grid on every
rank, so the path, the recorder and the observers run unchanged.  (The gather keeps the full H and P
on each rank: right up to what one machine holds; beyond it the recorder's sums must be reduced in
place instead — docs/benchmarks.md, the plan for 32768² and 65536².)
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from tengsim.errors import TengsimError
from tengsim.solvers.types import Equilibrium, Problem, State


@dataclass(frozen=True)
class SlabSolver:
    """``inner`` solved on this rank's rows of a slab-distributed problem (duck-typed kernel with
    ``comm``, ``rows``, ``local_shape``, ``gather``)."""

    inner: object

    def __getattr__(self, name):  # name, tol, memory, max_iter, … of the wrapped solver
        if name == "inner":
            raise AttributeError(name)
        return getattr(self.inner, name)

    def _local(self, a, K):
        a = np.asarray(a)
        if a.shape == K.local_shape:
            return a
        if a.shape != K.grid.shape:
            raise TengsimError(f"field of shape {a.shape} is neither the grid {K.grid.shape} nor the slab {K.local_shape}")
        r0, r1 = K.rows
        return np.ascontiguousarray(a[r0:r1])

    def solve(self, problem: Problem, start: State) -> Equilibrium:
        K = problem.kernel
        if not hasattr(K, "comm") or not hasattr(K, "rows"):
            raise TengsimError("SlabSolver needs a slab-distributed kernel (tengsim.kernels.distributed)")
        local = Problem(self._local(problem.g0, K), problem.law, K)
        st = State(self._local(start.q, K), self._local(start.w, K))
        eq = self.inner.solve(local, st)
        return dataclasses.replace(eq, H=K.gather(eq.H), P=K.gather(eq.P),
                                   residual=K.comm.allreduce(eq.residual, op=_max_op()))


def _max_op():
    from mpi4py import MPI

    return MPI.MAX
