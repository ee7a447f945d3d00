"""Sums and maxima over every MPI process of a distributed solve (tengsim.solvers.distributed).

The fast solver's scalars (energies, slopes, the L-BFGS products, max|r|) are sums or maxima over the
grid; when the grid is split into slabs, each process sums its own rows and :class:`Allreduce` adds
(or takes the largest of) the partial values of all processes, so every process takes the same steps.
A serial solve has no Allreduce (None) and no extra work.
"""
from __future__ import annotations

import numpy as np


class Allreduce:
    """Reductions over the communicator ``comm`` (mpi4py)."""

    def __init__(self, comm):
        from mpi4py import MPI

        self.comm, self._sum, self._max = comm, MPI.SUM, MPI.MAX

    def sum(self, values):
        """Element-wise sum over all processes of a sequence of floats or an array (same layout back)."""
        a = np.asarray(values, dtype=float)
        out = np.empty_like(a)
        self.comm.Allreduce(np.ascontiguousarray(a), out, op=self._sum)
        return out if isinstance(values, np.ndarray) else [float(x) for x in out]

    def max(self, value: float) -> float:
        return float(self.comm.allreduce(float(value), op=self._max))


def for_kernel(kernel):
    """An :class:`Allreduce` for a kernel split across processes (it has ``comm``), else None."""
    comm = getattr(kernel, "comm", None)
    return None if comm is None else Allreduce(comm)
