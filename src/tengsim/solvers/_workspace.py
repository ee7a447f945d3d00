"""The fast solver's workspace: every array an iteration touches, preallocated for one grid.

Its arrays come from the seam (tengsim.backend).  An iteration allocates nothing: the current and trial gap and pressure, the direction and its image,
residual, gradient and their next values, the new pair (y, K y), the convolution's output, the
sweeper with its per-thread scratch (tengsim.solvers._sweep) and the L-BFGS rows (tengsim.solvers._lbfgs).  A
workspace holds no result: the state a solve returns (q, w, P) lives in arrays of its own, so one
workspace serves the equilibria of a path one after the other (``FastSolver`` keeps a spare one per
solver, see :class:`Spare`).
"""
from __future__ import annotations

from tengsim import backend
from tengsim.solvers import _sweep
from tengsim.solvers._lbfgs import KMetricLBFGS
from tengsim.solvers._sweep import Sweeper

#: grids up to this many points keep their workspace between solves (the allocation matters only
#: there; a large grid's workspace, ~(13 + 4 (m + 1)) arrays, is given back with its solve)
KEEP_MAX_SIZE = 512 * 512

_ARRAYS = ("g", "gt", "P", "Pt", "d", "Kd", "r", "rn", "G", "Gn", "y", "ky", "cP")


class Workspace:
    """Preallocated arrays of n points, the sweeper and an L-BFGS memory of ``memory`` pairs."""

    def __init__(self, n: int, memory: int, dA: float):
        self.n = int(n)
        self.key = Workspace.key_for(n, memory, dA)
        for name in _ARRAYS:
            setattr(self, name, backend.empty(self.n))
        self.sweeper = Sweeper(self.n)
        self.memory = KMetricLBFGS(memory, self.n, dA)

    @staticmethod
    def key_for(n: int, memory: int, dA: float) -> tuple:
        """What a workspace is made for: size, memory, ΔA and the sweeper's blocks and threads."""
        return (int(n), int(memory), float(dA), _sweep.BLOCK, _sweep.thread_count(int(n)))


class Spare:
    """At most one idle workspace, lent to one solve at a time.

    :meth:`take` hands the spare out when it fits (else a new one); :meth:`give` returns it after the
    solve.  Two solves running at once on one solver (threads) get separate workspaces: the spare is
    taken out while in use.
    """

    def __init__(self):
        self._slot: dict = {}

    def take(self, n: int, memory: int, dA: float) -> Workspace:
        ws = self._slot.pop(Workspace.key_for(n, memory, dA), None)
        if ws is None:
            ws = Workspace(n, memory, dA)
        ws.memory.reset()
        return ws

    def give(self, ws: Workspace) -> None:
        if ws.n <= KEEP_MAX_SIZE:
            self._slot.clear()
            self._slot[ws.key] = ws

    def __len__(self) -> int:
        return len(self._slot)
