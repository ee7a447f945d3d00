"""The retraction where it retraces the approach: rows taken from the approach, not solved again.

Under displacement control the retraction leaves D_max on the approach's last state.  Where the approach
stepped from one row to the next without a jump, one branch of equilibria joins the two rows and has no fold
between them (the approach passed along it); a retraction on that branch at the upper row, walked down, reaches
the lower row's equilibrium.  So while the retraction is on the approach's branch, its rows down to the next
approach jump are the approach's rows: :meth:`Retrace.copy` records them again on the retraction (iterations
and convolutions 0; a map the approach kept at such a row is kept for the retraction too), and nothing is
solved.  At an approach jump the retraction must solve: it goes on from the approach's state at the jump's
upper row, kept while the approach was walked (:data:`MAX_KEPT` of the latest jumps, in a temporary file, not in
memory: :class:`Spill`; one solve from it, which finds it converged, restores the equilibrium), with the state of
the row above it, so that the walk below goes on with the secant history it would have had had it solved its way
down (a fold's landing below is sensitive to the start the walk brings).

Back on the approach's branch: a solved retraction row at the D of an approach row is that row's equilibrium
when their energies agree to :data:`ENERGY_MATCH` (relative), their forces to :data:`FORCE_MATCH` of the
path's force scale and their charged area fractions to :data:`AREA_MATCH`.  The energy is stationary at an
equilibrium, so two solves of one equilibrium agree in it to second order in their residuals, while two
branches differ in it at first order (docs/validation.md, "The retraction where it retraces the approach":
measured margins).  A tie the test cannot separate is two states with the same energy, force and area (a
mirror image of one another): their rows are the same numbers.

A load-controlled path (:mod:`tengsim.continuation.load`) does not use this.  ``run_path(..., retrace=False)``
solves every retraction row (the reference the tests compare with).
"""
from __future__ import annotations

import tempfile

import numpy as np

from tengsim.solvers import State

MAX_KEPT = 3
"""Approach jumps whose states (q and w, and the row above's) are kept, the latest ones (in a :class:`Spill`)."""
ENERGY_MATCH = 1e-7
FORCE_MATCH = 1e-3
AREA_MATCH = 1e-3


class Spill:
    """States kept in an unnamed temporary file, not in memory: ``put(key, state)``, ``get(key)`` (the arrays
    read back bit for bit), ``pop(key)``, ``key in spill``.  A popped state's slot is reused (all states of a path
    have one size; a slot is reused only by a state of its size), so the file holds at most as many states as are
    kept at once."""

    def __init__(self):
        self._file, self._at, self._free = None, {}, []

    def put(self, key, state: State) -> None:
        q, w = np.ascontiguousarray(state.q), np.ascontiguousarray(state.w)
        if self._file is None:
            self._file = tempfile.TemporaryFile()
        if key in self._at:
            self.pop(key)
        size = q.nbytes + w.nbytes
        slot = next((i for i, (_, n) in enumerate(self._free) if n == size), None)
        off = self._free.pop(slot)[0] if slot is not None else self._file.seek(0, 2)
        self._file.seek(off)
        self._file.write(memoryview(q).cast("B"))  # the array's own bytes, no copy
        self._file.write(memoryview(w).cast("B"))
        self._at[key] = (off, q.shape, q.dtype, w.shape, w.dtype, size)

    def get(self, key) -> State:
        off, qs, qd, ws, wd, _ = self._at[key]
        self._file.seek(off)
        out = []
        for shape, dtype in ((qs, qd), (ws, wd)):
            a = np.empty(shape, dtype)
            self._file.readinto(memoryview(a).cast("B"))
            out.append(a)
        return State(*out)

    def pop(self, key) -> None:
        at = self._at.pop(key, None)
        if at is not None:
            self._free.append((at[0], at[-1]))

    def __contains__(self, key) -> bool:
        return key in self._at

    def keys(self):
        return list(self._at)


class Retrace:
    """What the retraction takes from the approach of one path: the approach's rows (their indices in the
    recorder, in path order, by D) and the states at its latest jumps.  ``wrap(record)`` gives the approach's
    row callback that notes them; ``watch(record)`` the retraction's, which notes whether its last row is on
    the approach's branch with rows to copy below it (:attr:`hit`)."""

    def __init__(self, rec, keep_first: bool = False):
        self.rec, self.keep_first = rec, keep_first
        self.rows: list = []   # recorder indices of the approach's rows, in path order (D up)
        self.by_D: dict = {}   # round(D, 9) -> position in self.rows
        self.kept = Spill()    # position -> State, at rows whose step from the row before jumped; ("above",
        # position) -> the State of the row above a kept one (the predictor's second state)
        self.hit = None        # position of the approach row the retraction's last row is, if it can copy on
        self.copied = 0

    def wrap(self, record):
        def on_approach(D, eq, on_grid, jump, map_at=None):
            record(D, eq, on_grid, jump, map_at)
            pos = len(self.rows)
            self.rows.append(len(self.rec.rows) - 1)
            self.by_D[round(float(D), 9)] = pos
            if pos - 1 > 0 and pos - 1 in self.kept:
                self.kept.put(("above", pos - 1), eq.state)
            if (jump and pos > 0) or (pos == 0 and self.keep_first):  # the first: a copied retraction's end state
                self.kept.put(pos, eq.state)
                jumps = sorted(k for k in self.kept.keys() if isinstance(k, int) and k > 0)
                for k in jumps[:max(len(jumps) - MAX_KEPT, 0)]:
                    self.kept.pop(k)
                    self.kept.pop(("above", k))
        return on_approach

    def watch(self, record):
        def on_retraction(D, eq, on_grid, jump, map_at=None):
            record(D, eq, on_grid, jump, map_at)
            pos = self.by_D.get(round(float(D), 9))
            low = None if pos is None else self.lower(pos)
            self.hit = pos if low is not None and low != pos and self._same(self.rec.rows[-1], pos) else None
        return on_retraction

    def _row(self, pos) -> dict:
        return self.rec.rows[self.rows[pos]]

    def _same(self, row, pos) -> bool:
        """Whether the solved ``row`` is the approach row at ``pos``'s equilibrium (module doc)."""
        a = self._row(pos)
        Ea, Er = float(a["energy"]), float(row["energy"])
        if not (np.isfinite(Ea) and np.isfinite(Er)):
            return False
        scale = max(abs(float(a["F"])), abs(float(row["F"])),
                    max(-min(float(self._row(k)["F"]) for k in range(len(self.rows))), 0.0), 1e-300)
        same = (abs(Ea - Er) <= ENERGY_MATCH * max(abs(Ea), abs(Er), 1e-300)
                and abs(float(a["F"]) - float(row["F"])) <= FORCE_MATCH * scale)
        if "charged_fraction" in a and "charged_fraction" in row:
            same = same and abs(float(a["charged_fraction"]) - float(row["charged_fraction"])) <= AREA_MATCH
        return bool(same)

    def lower(self, pos):
        """The lowest position the retraction copies down to from ``pos``: the first row at or below it whose
        step from the row before jumped (0 without one); None where that row's state was not kept."""
        low = pos
        while low > 0 and not self._row(low)["jump"]:
            low -= 1
        return low if low == 0 or low in self.kept else None

    def copy(self, pos) -> int:
        """Record the approach's rows below ``pos`` down to :meth:`lower` on the retraction; returns that
        position."""
        low = self.lower(pos)
        for k in range(pos - 1, low - 1, -1):
            self.rec.copy_row(self.rows[k], "retraction")
            self.copied += 1
        return low

    def state(self, pos) -> State:
        """The approach's state kept at ``pos``."""
        return self.kept.get(pos)

    def before(self, pos):
        """(D, State, F) of the approach's row above the kept ``pos``: the state a retraction walked down to
        ``pos`` would have as its predictor's older one; None where it was not kept (the approach's last row)."""
        if ("above", pos) not in self.kept:
            return None
        row = self._row(pos + 1)
        return float(row["D"]), self.kept.get(("above", pos)), float(row["F"])

    def D(self, pos) -> float:
        return float(self._row(pos)["D"])
