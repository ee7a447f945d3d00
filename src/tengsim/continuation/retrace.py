"""The retraction where it retraces the approach: rows taken from the approach, not solved again.

Under displacement control the retraction leaves D_max on the approach's last state.  Where the approach
stepped from one row to the next without a jump, one branch of equilibria joins the two rows and has no fold
between them (the approach passed along it); a retraction on that branch at the upper row, walked down, reaches
the lower row's equilibrium.  So while the retraction is on the approach's branch, its rows down to the next
approach jump are the approach's rows: :meth:`Retrace.copy` records them again on the retraction (iterations
and convolutions 0; a map the approach kept at such a row is kept for the retraction too), and nothing is
solved.  At an approach jump the retraction must solve: it goes on from the approach's state at the jump's
upper row, kept while the approach was walked (:data:`MAX_KEPT` of the latest jumps; one solve from it, which
finds it converged, restores the equilibrium), with the state of the row above it, so that the walk below goes on
with the secant history it would have had had it solved its way down (a fold's landing below is sensitive to the
start the walk brings).

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

import numpy as np

from tengsim.solvers import State

MAX_KEPT = 3
"""States (q and w) kept at the approach's latest jumps (tengsim.run.memory counts them)."""
ENERGY_MATCH = 1e-7
FORCE_MATCH = 1e-3
AREA_MATCH = 1e-3


class Retrace:
    """What the retraction takes from the approach of one path: the approach's rows (their indices in the
    recorder, in path order, by D) and the states at its latest jumps.  ``wrap(record)`` gives the approach's
    row callback that notes them; ``watch(record)`` the retraction's, which notes whether its last row is on
    the approach's branch with rows to copy below it (:attr:`hit`)."""

    def __init__(self, rec, keep_first: bool = False):
        self.rec, self.keep_first = rec, keep_first
        self.rows: list = []   # recorder indices of the approach's rows, in path order (D up)
        self.by_D: dict = {}   # round(D, 9) -> position in self.rows
        self.kept: dict = {}   # position -> State, at rows whose step from the row before jumped
        self.above: dict = {}  # position -> State of the row above a kept one (the predictor's second state)
        self.hit = None        # position of the approach row the retraction's last row is, if it can copy on
        self.copied = 0

    def wrap(self, record):
        def on_approach(D, eq, on_grid, jump, map_at=None):
            record(D, eq, on_grid, jump, map_at)
            pos = len(self.rows)
            self.rows.append(len(self.rec.rows) - 1)
            self.by_D[round(float(D), 9)] = pos
            if pos - 1 in self.kept and pos - 1 > 0:
                self.above[pos - 1] = eq.state.copy()
            if (jump and pos > 0) or (pos == 0 and self.keep_first):  # the first: a copied retraction's end state
                self.kept[pos] = eq.state.copy()
                while sum(k > 0 for k in self.kept) > MAX_KEPT:
                    k = next(k for k in self.kept if k > 0)
                    self.kept.pop(k)
                    self.above.pop(k, None)
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
        return self.kept[pos]

    def before(self, pos):
        """(D, State, F) of the approach's row above the kept ``pos``: the state a retraction walked down to
        ``pos`` would have as its predictor's older one; None where it was not kept (the approach's last row)."""
        if pos not in self.above:
            return None
        row = self._row(pos + 1)
        return float(row["D"]), self.above[pos], float(row["F"])

    def D(self, pos) -> float:
        return float(self._row(pos)["D"])
