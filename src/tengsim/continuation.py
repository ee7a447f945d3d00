"""Continuation machinery shared by every path (D-controlled :mod:`tengsim.path`, load-controlled
:mod:`tengsim.loadpath`): the secant predictor, the branch walker with jump bisection, and the
recorder that turns each equilibrium into a row of the result table.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, is_dataclass, replace

import numpy as np

from tengsim import observers as obs
from tengsim.analysis import apex_index
from tengsim.errors import TengsimError
from tengsim.results import CURVE_COLUMNS, PHYSICAL_COLUMNS, ContactResult
from tengsim.solvers import Problem, State
from tengsim.status import EdgeScan, pixel_snap_number, row_status


def secant(s0: State, s1: State, c: float) -> State:
    """The state c steps of (s0 → s1) beyond s1: the secant predictor of a continuation step."""
    return State(s1.q + c * (s1.q - s0.q), s1.w + c * (s1.w - s0.w))


PERSIST_FACTOR = 10  # a fast solve stopped at its cap goes on for up to this many times max_iter more


def persist(solver, problem: Problem, eq):
    """The automatic fallback of a fast solve that stopped at its iteration cap (issue 23): go on from
    where it stopped, with ``PERSIST_FACTOR`` × max_iter more iterations.

    Where the law is stiffer than a pixel (pixel snap number ≫ 1) the fast solver's work is a long
    sequence of single pixels snapping in, then a slow settling of the stiff contact; both make progress
    every iteration, only more slowly than the cap allows (measured, docs/benchmarks.md "Stiff laws").
    Runs only on a solve that did not converge, so every equilibrium that converges within the cap is
    unchanged bit for bit.  Any other solver, or a solve that failed otherwise (line search, non-finite),
    is returned as it is; a continued solve that still fails says so in its message, with both counts."""
    inner = getattr(solver, "inner", solver)
    if (PERSIST_FACTOR < 1 or not getattr(inner, "resumes_from_state", False) or not is_dataclass(inner)
            or not np.isfinite(eq.residual)
            or not str(eq.message).startswith("not converged")):
        return eq
    more = replace(inner, max_iter=PERSIST_FACTOR * int(inner.max_iter))
    more = solver.with_inner(more) if hasattr(solver, "with_inner") else more
    eq2 = more.solve(problem, eq.state)
    what = "converged" if eq2.converged else f"not converged ({eq2.message})"
    return replace(eq2, iterations=eq.iterations + eq2.iterations, n_conv=eq.n_conv + eq2.n_conv,
                   seconds=eq.seconds + eq2.seconds,
                   message=f"{what} after the cap: {eq.iterations} + {eq2.iterations} iterations "
                           f"(max|r| {eq.residual:.2e} at the cap)")


def spent(res, walkers):
    """``res`` with ``params['n_conv_spent']``: the convolutions of every solve of the run, those of the
    rows (the table's ``n_conv``) and those discarded (a predicted start that jumped, solved again; a step
    refined after a jump; the adaptive walk's rejected steps)."""
    return replace(res, params={**res.params, "n_conv_spent": int(sum(w.spent for w in walkers))})


class Branch:
    """Walks one branch, refining steps and predicting starts."""

    def __init__(self, U0, law, kernel, solver, spec, on_row):
        self.U0, self.law, self.kernel, self.solver, self.spec = U0, law, kernel, solver, spec
        fold = getattr(solver, "fold_gap", None)  # a mirror solver takes g0 on its block
        self._U0s = U0 if fold is None else fold(U0, kernel)
        self.on_row = on_row
        self.hist: list = []  # accepted (D, state) on this branch, newest last
        self.spent = 0  # convolutions of every solve of this branch, recorded or discarded (jump checks, refining)

    def solve(self, D, start):
        problem = Problem(self._U0s - D + 1.0, self.law, self.kernel)
        eq = self.solver.solve(problem, start)
        if not eq.converged:
            eq = persist(self.solver, problem, eq)
        self.spent += int(eq.n_conv)
        return eq

    def _start(self, D):
        (D1, s1) = self.hist[-1]
        if self.spec.predictor and len(self.hist) >= 2:
            D0, s0 = self.hist[-2]
            if D1 != D0:
                c = (D - D1) / (D1 - D0)
                if 0 < c <= 1.5:
                    return secant(s0, s1, c), True
        return s1, False

    def _jumped(self, eqa, eqb, dD):
        return eqb.max_change(eqa) - abs(dD) > self.spec.jump_h

    def advance(self, Da, eqa, Db, level, on_grid):
        start, predicted = self._start(Db)
        eqb = self.solve(Db, start)
        if predicted and self._jumped(eqa, eqb, Db - Da):
            eqb = self.solve(Db, eqa.state)  # confirm without the predictor
        if self._jumped(eqa, eqb, Db - Da):
            if level < self.spec.refine_levels:
                mid = 0.5 * (Da + Db)
                eqm = self.advance(Da, eqa, mid, level + 1, False)
                return self.advance(mid, eqm, Db, level + 1, on_grid)
            jump = True
        else:
            jump = False
        self.hist = (self.hist + [(Db, eqb.state)])[-2:]
        if jump:
            self.hist = self.hist[-1:]
        self.on_row(Db, eqb, on_grid, jump)
        return eqb


@dataclass
class StateOnly:
    """A bare state holder (``.state``) for rows kept only as states."""

    state: State


class Recorder:
    """Collects what one path produces: a row per equilibrium (the built-in summary, the status inputs
    and the observers' columns), the maps asked for, and progress.  Shared by every kind of path.

    ``control`` names the path's control variable ('D' or 'F'); maps are kept at the rows whose
    control value is within ``map_tol`` of an entry of ``maps_at`` (rows on the path's grid), and at a
    row the path marks as the one for an entry (``map_at``: an extra row a path adds at that value, see
    :func:`tengsim.path.run_path`); one map per entry and branch, the first such row.

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
            s = self.summary(eq, self.ctx)
            # a state whose gap enters the law's safe extension (g < g_safe) is outside the physical law
            in_range = bool(s["min_gap"] + 1.0 >= getattr(self.law, "g_safe", -np.inf))
            more = {}
            for o in self.extra:
                more.update(self._observe(o, eq, self.ctx))
            pz = self.edges(eq.H)
            self.rows.append(dict(branch=branch, D=D, on_grid=on_grid, jump=jump, converged=eq.converged,
                                  in_law_range=in_range, process_zone=pz,
                                  status=row_status(bool(eq.converged), in_range, pz, self.grid.dx, self.snap,
                                                    self.edges.face),
                                  residual=eq.residual, iterations=eq.iterations, n_conv=eq.n_conv,
                                  seconds=eq.seconds, energy=eq.energy, **s, **more))
            value = D if self.control == "D" else s["F"]
            for m in self.maps_at:
                tol = self.map_tol * (max(1.0, abs(m)) if self.control == "D" else 1.0) + 1e-9
                hit = (map_at is not None and m == map_at) or (on_grid and abs(value - m) <= tol)
                if hit and (branch, m) not in self._map_keys:
                    self._map_keys.add((branch, m))
                    self.maps.append(dict(branch=branch, D=D, P=eq.P.copy(), H=eq.H.copy()))
            if on_grid:
                self.done += 1
                if self.progress:
                    self.progress(branch, value, self.done, self.total)
            if self.sink is not None:
                self.sink(self.rows[-1], list(self.maps[n_maps:]))
        return record

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
