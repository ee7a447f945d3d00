"""Load control: a path in the total force F (Eq. 10), D an unknown of each equilibrium.

A device applies a pressure, not an approach.  Each load-controlled state is a D-controlled
equilibrium (Eq. 9) whose force equals the load: F(D) = F_target.  It is found by an outer 1-D
solve on D around the existing solver, which keeps every state exactly the one the D-controlled
path has at that D (the same warm starts, the same branch):

1. walk in D from the current state, in the direction the load moves the body (D up when the
   target is above the current F, down when below), in steps of ``d_step`` with the D path's own
   jump bisection (:class:`tengsim.continuation.walker.Walker` with
   :class:`tengsim.continuation.steps.FixedSteps`), until F crosses the target;
2. solve F(D) = F_target in that bracket by regula falsi (Illinois), each trial D warm-started
   from the bracket's states interpolated, until |F − F_target| <= ``f_tol``.

(An augmented energy E(q) − F·D with D free would need a new solver; the outer solve reuses the
one solver and is robust because each trial is a warm-started D-controlled equilibrium.)

Stability and jumps.  Under a dead load a state is stable only where dF/dD > 0.  When the walk
towards the target passes a turning point of F(D) (a fold: F first moves towards the target,
then away), the body jumps at the fold's load: the fold is located by golden-section search on
F(D) to the smallest step d_step/2^refine_levels, recorded as a row, and the walk goes on past it
to the first D where F returns to the fold's load on a rising part (the landing state), recorded
with ``jump`` True.  On the approach this is the jump-in (for an adhesive law at the very start:
the body at rest at ``d_min`` is drawn in); on the retraction the fold is the minimum of F, the
load-controlled pull-off, and the jump-out leaves the D range (separation): the retraction ends
with a row at the last D of the walk above ``d_min`` (out of contact), marked ``jump``, and the
loads below the pull-off have no state.
Approach loads below the start's F (the body stays away) are skipped.
"""
from __future__ import annotations

import dataclasses
import math

from tengsim.analysis import force
from tengsim.continuation.recorder import Recorder, spent
from tengsim.continuation.specs import BRANCHES, EXTEND_LIMIT, LoadPathSpec
from tengsim.continuation.steps import FixedSteps
from tengsim.continuation.walker import Walker, revise
from tengsim.errors import TengsimError
from tengsim.solvers import State


class _Out(Exception):
    """The walk left [d_min, d_max] without meeting the load."""


class _LoadBranch:
    """One branch under load control; ``emit(D, eq, on_grid, jump[, map_at])`` receives its rows in order.

    ``misses`` collects a line for each load the branch recorded without meeting it to f_tol."""

    max_root_steps = 60  # regula-falsi steps of one load (a class attribute: tests lower it)

    def __init__(self, U0, law, kernel, solver, spec: LoadPathSpec, emit, name=""):
        self.spec, self.emit, self.grid = spec, emit, kernel.grid
        self.name, self.misses, self.bracket = name, [], None
        self.trail: list = []
        self.walker = Walker(U0, law, kernel, solver, FixedSteps(spec.refine_levels),
                             lambda D, eq, on_grid, jump: self.trail.append((D, eq, jump)), spec.jump_h)
        self.h_min = spec.d_step / 2 ** int(spec.refine_levels)
        self.d_max = spec.d_max  # with spec.extend, raised as the approach needs (_walk)
        self.d_limit = spec.d_min + EXTEND_LIMIT * (spec.d_max - spec.d_min) if spec.extend else spec.d_max

    def F(self, eq) -> float:
        return force(eq.P, self.grid)

    def set(self, D, eq):
        self.D, self.eq, self.Fc = D, eq, self.F(eq)
        self.walker.reset(D, eq)

    def _walk(self, s):
        """One D step in direction s from the current end of the walk; returns its new points."""
        D0, eq0 = self.pts[-1][0], self.pts[-1][1]
        D1 = D0 + s * self.spec.d_step
        while D1 > self.d_max + 1e-12 and self.d_max < self.d_limit:  # extend: the span doubled, to the limit
            self.d_max = min(self.d_limit, self.d_max + (self.d_max - self.spec.d_min))
        if D1 < self.spec.d_min - 1e-12 or D1 > self.d_max + 1e-12:
            raise _Out()
        self.trail = []
        self.walker.walk([D1], on_grid=False, start=(D0, eq0))
        new = [(D, eq, self.F(eq), jump) for D, eq, jump in self.trail]
        self.pts += new
        return new

    def _root(self, a, b, Ft):
        """Regula falsi (Illinois) for F(D) = Ft between walk points a and b (F on either side)."""
        (Da, ea, Fa), (Db, eb, Fb) = a[:3], b[:3]
        side = 0
        best = min((a, b), key=lambda p: abs(p[2] - Ft))
        n = 0
        for n in range(self.max_root_steps + 1):
            if abs(best[2] - Ft) <= self.spec.tol_F or abs(Db - Da) < 1e-12 or n == self.max_root_steps:
                break
            t = (Ft - Fa) / (Fb - Fa)
            D = Da + t * (Db - Da)
            start = State(ea.state.q + t * (eb.state.q - ea.state.q), ea.state.w + t * (eb.state.w - ea.state.w))
            eq = self.walker.solve(D, start)
            F = self.F(eq)
            best = (D, eq, F) if abs(F - Ft) < abs(best[2] - Ft) else best
            if (F - Ft) * (Fa - Ft) > 0:
                Da, ea, Fa = D, eq, F
                if side == -1:
                    Fb = Ft + 0.5 * (Fb - Ft)
                side = -1
            else:
                Db, eb, Fb = D, eq, F
                if side == 1:
                    Fa = Ft + 0.5 * (Fa - Ft)
                side = 1
        self.bracket = (min(Da, Db), max(Da, Db), f"after {n} regula-falsi step{'' if n == 1 else 's'}")
        return best[0], best[1]

    def _fold(self, i, s):
        """Refine the fold around walk point i (largest s·F) by golden section; returns (D, eq, F)."""
        lo = self.pts[max(i - 1, 0)][0]
        hi = self.pts[min(i + 1, len(self.pts) - 1)][0]
        if i == 0:
            return self.pts[0][:3]
        a, b = min(lo, hi), max(lo, hi)
        best = self.pts[i][:3]

        def at(D):
            near = min(self.pts, key=lambda p: abs(p[0] - D))
            eq = self.walker.solve(D, near[1].state)
            return D, eq, self.F(eq)
        g = 0.5 * (math.sqrt(5.0) - 1.0)
        x1, x2 = b - g * (b - a), a + g * (b - a)
        p1, p2 = at(x1), at(x2)
        while b - a > self.h_min:
            if s * p1[2] >= s * p2[2]:
                b, x2, p2 = x2, x1, p1
                x1 = b - g * (b - a)
                p1 = at(x1)
            else:
                a, x1, p1 = x1, x2, p2
                x2 = a + g * (b - a)
                p2 = at(x2)
        for p in (p1, p2):
            if s * p[2] > s * best[2]:
                best = p
        return best

    def _cross(self, Ft, s, fold_check):
        """Walk from the current state to F = Ft; returns ('root', D, eq) or ('fold', D, eq, F)."""
        self.pts = [(self.D, self.eq, self.Fc, False)]
        ibest = 0
        noise = self.spec.tol_F
        below = s * (self.Fc - Ft) < 0
        while True:
            start = len(self.pts)
            self._walk(s)
            for i in range(start, len(self.pts)):
                Fi = self.pts[i][2]
                if s * (Fi - Ft) >= 0 and below:
                    if self.pts[i][3]:  # crossed through a D-controlled jump: take the far state
                        self.bracket = (*sorted((self.pts[i - 1][0], self.pts[i][0])), "across a jump in D")
                        return ("root", self.pts[i][0], self.pts[i][1])
                    D, eq = self._root(self.pts[i - 1], self.pts[i], Ft)
                    return ("root", D, eq)
                below = below or s * (Fi - Ft) < 0
                if fold_check:
                    if s * Fi > s * self.pts[ibest][2]:
                        ibest = i
                    elif s * Fi < s * self.pts[ibest][2] - noise:
                        return ("fold",) + tuple(self._fold(ibest, s))

    def to(self, Ft, on_grid, map_at=None) -> bool:
        """Bring the branch to load Ft, emitting fold/landing rows on the way; False if it left.  The row at
        Ft keeps the map of the ``maps_at`` entry ``map_at``."""
        self.bracket = None
        while abs(self.Fc - Ft) > self.spec.tol_F:
            s = 1 if Ft > self.Fc else -1
            try:
                res = self._cross(Ft, s, fold_check=True)
            except _Out:
                return self._left(s)
            if res[0] == "root":
                self.set(res[1], res[2])
                break
            _, Df, eqf, Ff = res
            if abs(Df - self.D) > 1e-12:
                self.set(Df, eqf)
                self.emit(Df, eqf, False, False)  # the last stable state before the jump
            try:
                land = self._cross(Ff, s, fold_check=False)
            except _Out:
                return self._left(s)
            self.set(land[1], land[2])
            self.emit(land[1], self._checked(land[2], Ff, "the landing load"), False, True)
        self.emit(self.D, self._checked(self.eq, Ft, "load"), on_grid, False, map_at)
        return True

    def _checked(self, eq, Ft, what):
        """``eq`` as recorded at load ``Ft``: marked not converged, with a line in ``misses`` naming the load
        and the D bracket of its search, when its force misses Ft by more than f_tol."""
        err = abs(self.F(eq) - Ft)
        if err <= self.spec.tol_F:
            return eq
        lo, hi, how = self.bracket if self.bracket is not None else (self.D, self.D, "")
        msg = (f"{self.name}: {what} {self.spec.load_text(Ft)} not met: |F - target| = {err:.3g} > f_tol = "
               f"{self.spec.tol_F:.3g} (D in [{lo:.6g}, {hi:.6g}]{', ' + how if how else ''})")
        self.misses.append(msg)
        return revise(eq, converged=False, message=msg)

    def _left(self, s):
        """The body left the D range under this load: record the state at the end of the walk."""
        D, eq, F, _ = self.pts[-1]
        if abs(D - self.D) > 1e-12:
            self.set(D, eq)
            self.emit(D, eq, False, True)
        return False


def _not_reached(spec: LoadPathSpec, branch: _LoadBranch, Ft: float) -> str:
    """The error of a load the approach did not reach: the load, the highest reached, and the D range."""
    best = max((p[2] for p in getattr(branch, "pts", ())), default=branch.Fc)
    best = max(best, branch.Fc)
    how = (f"the search in D was extended to {spec.d_text(branch.d_max)} (the limit, {EXTEND_LIMIT} times the "
           f"first range)" if spec.extend else f"within d_max = {spec.d_text(spec.d_max)}; raise d_max")
    return (f"load {spec.load_text(Ft)} is not reached: the highest load reached is {spec.load_text(best)}, "
            f"{how}")


MISS_SEPARATOR = "; "
"""Between the loads a load-controlled run missed in its ``params['load_not_met']`` (one text, so that it is written
to a file's attributes as it is); :func:`misses_in` reads it back."""


def joined_misses(misses) -> str:
    """The missed loads (each 'branch F = …: D bracket …', no separator inside) as one ``load_not_met`` text."""
    return MISS_SEPARATOR.join(misses)


def misses_in(params: dict) -> list:
    """The missed loads of a result's ``params`` (:func:`joined_misses` inverted; [] where every load was met)."""
    return [m for m in str(params.get("load_not_met") or "").split(MISS_SEPARATOR) if m]


def run_load_path(U0, law, kernel, solver, spec: LoadPathSpec, start: State | None = None,
                  progress=None, keep_states: bool = False, observers=(), sink=None):
    """Solve the load-controlled approach–retraction path; returns a ContactResult (same columns as
    :func:`tengsim.continuation.run_path`: D is an output, F the control).  ``progress(branch, F, done, total)``;
    ``sink(row, maps)`` as for run_path."""

    targets = spec.targets()
    rec = Recorder(U0, law, kernel, observers, progress, len(targets) * (2 if spec.retract else 1),
                   spec.maps_at, "F", map_tol=2 * spec.tol_F, sink=sink)
    U0 = rec.U0
    state = start if start is not None else State.zero(kernel.grid.shape)
    visit = spec.path_targets()  # the lattice and the maps_at loads off it

    def map_at(Ft):  # the maps_at entry of the load Ft, if any
        return next((m for m in spec.maps_at if abs(m - Ft) <= 1e-9 * spec.f_step), None)

    up = _LoadBranch(U0, law, kernel, solver, spec, rec.on_row(BRANCHES[0]), BRANCHES[0])
    eq0 = up.walker.solve(spec.d_min, state)
    up.set(spec.d_min, eq0)
    up.emit(spec.d_min, eq0, False, False)  # at rest, out of contact
    for Ft, on_lattice in visit:
        if Ft < up.Fc - spec.tol_F and up.D == spec.d_min:
            continue  # a load pulling harder than the far field: the body stays away
        if not up.to(Ft, on_lattice, map_at(Ft)):
            raise TengsimError(_not_reached(spec, up, Ft))
    branches = [up]
    if spec.retract:
        down = _LoadBranch(U0, law, kernel, solver, spec, rec.on_row(BRANCHES[1]), BRANCHES[1])
        branches.append(down)
        down.set(up.D, up.eq)
        met = bool(abs(up.Fc - targets[-1]) <= spec.tol_F)  # (a miss there is flagged on the approach's row)
        down.emit(up.D, up.eq, met, False, map_at(targets[-1]) if met else None)
        for Ft, on_lattice in visit[::-1][1:]:
            if not down.to(Ft, on_lattice, map_at(Ft)):
                break  # pulled off: no state under the lower loads
    eq_last = (down if spec.retract else up).eq
    res = spent(rec.result(eq_last.state if keep_states else None), [b.walker for b in branches])
    misses = [m for b in branches for m in b.misses]
    more = {}
    if misses:
        more["load_not_met"] = joined_misses(misses)
    if up.d_max > spec.d_max:
        more["d_max_reached"] = up.d_max  # the search range the approach extended itself to
    absent = rec.maps_missing([b.name for b in branches])
    if absent:  # requested, but that branch has no state at that load: said, not dropped silently
        more["maps_not_made"] = "; ".join(f"{b} {spec.load_text(m)}" for b, m in absent) + (
            " (no state at that load on that branch: below the load at rest on the approach, past the "
            "pull-off on the retraction)")
    return dataclasses.replace(res, params={**res.params, **more})
