"""The recorder: turns each equilibrium of a path into a row of the result table (the built-in summary,
the status inputs, the observers' columns), keeps the maps asked for, reports progress, and builds the
:class:`tengsim.results.ContactResult`.
"""
from __future__ import annotations

import time
from dataclasses import replace

import numpy as np

from tengsim import observers as obs
from tengsim.analysis import apex_index
from tengsim.errors import TengsimError
from tengsim.results import CURVE_COLUMNS, PHYSICAL_COLUMNS, ContactResult
from tengsim.status import EdgeScan, pixel_snap_number, row_status


def spent(res, walkers):
    """``res`` with ``params['n_conv_spent']``: the convolutions of every solve of the run, those of the
    rows (the table's ``n_conv``) and those discarded (a predicted start that jumped, solved again; a step
    refined after a jump; the adaptive walk's rejected steps)."""
    return replace(res, params={**res.params, "n_conv_spent": int(sum(w.spent for w in walkers))})


class Recorder:
    """Collects what one path produces: a row per equilibrium (the built-in summary, the status inputs
    and the observers' columns), the maps asked for, and progress.  Shared by every kind of path.

    ``control`` names the path's control variable ('D' or 'F'); maps are kept at the rows whose
    control value is within ``map_tol`` of an entry of ``maps_at`` (rows on the path's grid), and at a
    row the path marks as the one for an entry (``map_at``: an extra row a path adds at that value, see
    :func:`tengsim.continuation.run_path`); one map per entry and branch, the first such row.

    ``sink`` (a plain callable or None) is called as ``sink(row, maps)`` once each equilibrium is
    recorded, in path order: ``row`` the row's dict (the table's columns), ``maps`` the list of the maps
    kept at it (usually empty).  It lets a caller write results as they are computed.
    """

    def __init__(self, U0, law, kernel, observers=(), progress=None, total=0, maps_at=(), control="D",
                 map_tol=1e-9, sink=None):
        grid = kernel.grid
        U0 = np.asarray(U0, dtype=float)
        if U0.shape != grid.shape:
            raise TengsimError(f"U0 shape {U0.shape} does not match the grid {grid.shape}")
        if not np.all(np.isfinite(U0)):
            raise TengsimError("the initial gap U0 contains NaN or infinite values")
        self.U0, self.law, self.grid = U0, law, grid
        # the run's pixel snap number (one convolution), so that each row is classified once, as recorded
        self.snap = pixel_snap_number(law, kernel)
        self.edges = EdgeScan(U0, law, grid.dx, grid.dy, getattr(kernel, "coupling", None))  # every contact edge
        self.apex = apex_index(U0)
        self.summary = obs.Summary()
        self.extra = obs.resolve(observers)
        self.extra_cols = obs.check_columns(self.extra, CURVE_COLUMNS + PHYSICAL_COLUMNS)
        self.ctx = obs.Context(grid, self.apex, U0, law, kernel)
        self._observe = obs.observe
        self.progress, self.total, self.maps_at = progress, total, tuple(maps_at)
        self.control, self.map_tol = control, map_tol
        self.rows, self.maps, self.done, self._map_keys = [], [], 0, set()
        self.t_start = time.perf_counter()
        self.sink = sink

    def on_row(self, branch):
        """The callback ``(D, eq, on_grid, jump, map_at=None)`` that records a row of ``branch``."""
        def record(D, eq, on_grid, jump, map_at=None):
            n_maps = len(self.maps)  # for the sink: the maps this row adds
            unfold = getattr(eq, "unfolded", None)  # a block's equilibrium: its full-grid fields once a row
            eq = unfold() if unfold is not None else eq
            s = self.summary(eq, self.ctx)
            # a state whose gap enters the law's safe extension (g < g_safe) is outside the physical law
            in_range = bool(s["min_gap"] + 1.0 >= getattr(self.law, "g_safe", -np.inf))
            more = {}
            for o in self.extra:
                more.update(self._observe(o, eq, self.ctx))
            value = D if self.control == "D" else s["F"]
            for m in self.maps_at:
                tol = self.map_tol * (max(1.0, abs(m)) if self.control == "D" else 1.0) + 1e-9
                hit = (map_at is not None and m == map_at) or (on_grid and abs(value - m) <= tol)
                if hit and (branch, m) not in self._map_keys:
                    self._map_keys.add((branch, m))
                    self.maps.append(dict(branch=branch, D=D, P=eq.P.copy(), H=eq.H.copy()))
            H, rec = eq.H, dict(converged=eq.converged, residual=eq.residual, iterations=eq.iterations,
                                n_conv=eq.n_conv, seconds=eq.seconds, energy=eq.energy)
            del eq  # the edge scan needs H only: a block's unfolded P is freed before it
            pz = self.edges(H)
            del H
            self.rows.append(dict(branch=branch, D=D, on_grid=on_grid, jump=jump, converged=rec["converged"],
                                  in_law_range=in_range, process_zone=pz,
                                  status=row_status(bool(rec["converged"]), in_range, pz, self.grid.dx, self.snap,
                                                    self.edges.face),
                                  residual=rec["residual"], iterations=rec["iterations"], n_conv=rec["n_conv"],
                                  seconds=rec["seconds"], energy=rec["energy"], **s, **more))
            if on_grid:
                self.done += 1
                if self.progress:
                    self.progress(branch, value, self.done, self.total)
            if self.sink is not None:
                self.sink(self.rows[-1], list(self.maps[n_maps:]))
        return record

    def copy_row(self, index, branch) -> None:
        """Record the row ``index`` again as a row of ``branch``: the same equilibrium, not solved again
        (:mod:`tengsim.continuation.retrace`; its iterations, convolutions and seconds 0, no jump into it);
        the map kept at its D, if any, is kept for ``branch`` too (the same arrays)."""
        src = self.rows[index]
        row = dict(src, branch=branch, jump=False, iterations=0, n_conv=0, seconds=0.0)
        n_maps = len(self.maps)
        D = float(src["D"])
        for m in self.maps_at:
            tol = self.map_tol * max(1.0, abs(m)) + 1e-9
            if abs(D - m) <= tol and (branch, m) not in self._map_keys:
                kept = next((mp for mp in self.maps if mp["branch"] == src["branch"] and mp["D"] == D), None)
                if kept is not None:
                    self._map_keys.add((branch, m))
                    self.maps.append(dict(kept, branch=branch))
        self.rows.append(row)
        if row["on_grid"]:
            self.done += 1
            if self.progress:
                self.progress(branch, D, self.done, self.total)
        if self.sink is not None:
            self.sink(row, list(self.maps[n_maps:]))

    def maps_missing(self, branches) -> list:
        """[(branch, value)] of the ``maps_at`` entries with no map kept on those branches (a load path:
        a load with no state on a branch)."""
        return [(b, m) for b in branches for m in self.maps_at if (b, m) not in self._map_keys]

    def result(self, final_state=None):
        """The :class:`tengsim.results.ContactResult` of the recorded rows."""
        units = {}
        for o in self.extra:
            units.update(getattr(o, "units", None) or {})
        return ContactResult.from_rows(self.rows, self.maps, self.grid, seconds=time.perf_counter() - self.t_start,
                                       final_state=final_state, extra_columns=self.extra_cols, units=units,
                                       params={"pixel_snap_number": self.snap, "face_uncertainty": self.edges.face})
