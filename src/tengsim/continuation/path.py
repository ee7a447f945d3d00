"""Continuation in the rigid approach D: approach (D up) then retraction (D down), paper Section 2.

Each equilibrium is warm-started from the previous one on its branch (with a secant predictor), so
the path follows the stable branch and shows jump-in, jump-out and hysteresis as the paper's VSR
does.  Step control: when the gap field changes by more than ``jump_h`` (in ε, beyond the rigid
shift |ΔD|) across a step, the step is bisected, up to ``refine_levels`` times; a change that
survives the finest step is recorded as a jump.

With ``PathSpec(adaptive=True)`` the step also adapts where the path is smooth
(:class:`tengsim.continuation.steps.AdaptiveSteps`): ``d_step`` is then the largest step and
d_step/2^refine_levels the smallest.  Both branches are walked by the one
:class:`tengsim.continuation.walker.Walker`, given the step control.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from tengsim.continuation.recorder import Recorder, spent
from tengsim.continuation.retrace import Retrace
from tengsim.continuation.specs import _D_TOL, BRANCHES, PathSpec
from tengsim.continuation.steps import AdaptiveSteps, FixedSteps
from tengsim.continuation.walker import Walker
from tengsim.errors import TengsimError
from tengsim.solvers import State


def run_path(U0, law, kernel, solver, spec: PathSpec, start: State | None = None,
             progress=None, keep_states: bool = False, observers=(), sink=None, retrace: bool = True):
    """Solve the approach–retraction path; returns a :class:`tengsim.results.ContactResult`.

    ``progress(branch, D, done, total)`` is called after each row on the D grid.  ``observers``
    (registered names or objects, see :mod:`tengsim.observers`) add their columns to every row.
    ``sink(row, maps)`` is called with each row as it is recorded (:class:`tengsim.continuation.Recorder`).
    ``retrace``: the retraction's rows on the approach's branch are the approach's, not solved again
    (:mod:`tengsim.continuation.retrace`; ``params['retraction_rows_copied']`` counts them); False solves
    every row.  A load-controlled path is :func:`tengsim.continuation.run_load_path`.
    """
    if not isinstance(spec, PathSpec):
        raise TengsimError(f"run_path walks a PathSpec (rigid approach D); got {type(spec).__name__} "
                           "(a LoadPathSpec runs with tengsim.continuation.run_load_path)")
    targets = spec.targets()
    rec = Recorder(U0, law, kernel, observers, progress, len(targets) * (2 if spec.retract else 1),
                   spec.maps_at, "D", sink=sink)
    U0 = rec.U0
    # the zero start is made in the first solve's call: not held for the whole walk (a full-grid pair beside
    # a mirror block's states)
    walkers = []  # whatever solved: the branches and the map rows (their convolutions, for n_conv_spent)
    trace = Retrace(rec, keep_states) if retrace and spec.retract else None

    def rows(branch):  # the Recorder's callback, with the extra rows at the maps_at D between the walk's rows
        record = rec.on_row(branch)
        if trace is not None:
            record = trace.wrap(record) if branch == "approach" else trace.watch(record)
        if not spec.maps_at:
            return record
        walkers.append(_MapRows(record, spec.maps_at, U0, law, kernel, solver, spec.jump_h))
        return walkers[-1]

    steps = AdaptiveSteps.of(spec) if spec.adaptive else FixedSteps(spec.refine_levels, spec.predictor)
    eq = None  # handed from branch to branch: the walker holds the current equilibrium, not this frame
    top = None  # the D the approach ended at, when it stopped at spec.stop_force
    for branch in BRANCHES[:2 if spec.retract else 1]:
        Ds = targets if branch == "approach" else _down_from(targets, top)
        callback = rows(branch)
        walker = Walker(U0, law, kernel, solver, steps, callback, spec.jump_h)
        walkers.append(walker)
        walker.begin(Ds[0], eq if eq is not None else
                     walker.solve(Ds[0], start if start is not None else State.zero(kernel.grid.shape)),
                     on_grid=top is None or _on_lattice(targets, top))
        eq = None
        if branch == "retraction" and trace is not None:
            _retrace(walker, trace, Ds, callback if spec.maps_at else None)
        elif branch == "approach" and spec.stop_force is not None:
            walker.walk(Ds[1:], until=_reached(rec, spec))
            top = walker.hist[-1][0]
            if top < targets[-1] - _D_TOL:  # stopped short of d_max: the progress counts the rows left
                left = len(_down_from(targets, top)) - (0 if _on_lattice(targets, top) else 1)
                rec.total = rec.done + (left if spec.retract else 0)
            else:
                top = None
        else:
            walker.walk(Ds[1:])
        eq = walker.take()
    final = None
    if keep_states:  # a retraction that ended on rows copied from the approach ends in the approach's first state
        final = eq.state if eq is not None else trace.state(0)
    res = rec.result(final)
    if trace is not None:
        res = replace(res, params={**res.params, "retraction_rows_copied": trace.copied})
    return spent(res, walkers)


def _on_lattice(targets, D) -> bool:
    return bool(np.any(np.abs(targets - D) <= _D_TOL * np.maximum(1.0, np.abs(targets))))


def _down_from(targets, top):
    """The retraction's stops: from ``top`` (None: the lattice's last D) down the lattice."""
    if top is None:
        return targets[::-1]
    return np.concatenate(([top], [t for t in targets[::-1] if t < top - _D_TOL * max(1.0, abs(t))]))


def _reached(rec, spec):
    """The approach's stop (``spec.stop_force``): its last recorded row's F reached it, past every map's D."""
    last_map = max(spec.maps_at, default=-np.inf)

    def until():
        row = rec.rows[-1]
        return row["branch"] == "approach" and row["F"] >= spec.stop_force and row["D"] >= last_map

    return until


def _retrace(walker, trace, Ds, maprows):
    """Walk the retraction (``Ds``, D down) from the walker's first row, copying the approach's rows where it
    is on the approach's branch (:mod:`tengsim.continuation.retrace`); the walker's last equilibrium is the
    retraction's, unless the retraction ends on copied rows (then the walker holds nothing)."""
    end = Ds[-1]
    while True:
        pos, trace.hit = trace.hit, None
        if pos is not None:
            low = trace.copy(pos)
            D = trace.D(low)
            if low == 0 or D <= end + _D_TOL:
                walker.take()
                if maprows is not None:
                    maprows.skip(D, None)
                return
            eq = walker.solve(D, trace.state(low))  # the approach's state at its jump, restored
            walker.reset(D, eq, trace.before(low))
            if maprows is not None:
                maprows.skip(D, eq)
        else:  # the walk goes on where it stopped (a step control starts from one state)
            walker.reset(walker.hist[-1][0], walker.eq)
        D = walker.hist[-1][0]
        stops = [d for d in Ds if d < D - _D_TOL]
        if not stops:
            return
        walker.walk(stops, until=lambda: trace.hit is not None)
        if walker.hist[-1][0] <= end + _D_TOL and trace.hit is None:
            return


class _MapRows:
    """Passes a branch's rows to the Recorder's callback ``record``, in path order, adding a row at each
    requested D (``maps_at``) the walk steps over: when a row arrives whose step from the row before
    passes such a D, the state there is solved first (from the two rows' states interpolated; from the
    state before when the step is a jump) and recorded as an extra row (``on_grid`` False, its map kept:
    ``map_at``).  The walk's own continuation never sees these states.  A row at a requested D (to
    :data:`_D_TOL`) is the one that D's map is kept at."""

    def __init__(self, record, maps_at, U0, law, kernel, solver, jump_h):
        self.record, self.walker = record, Walker(U0, law, kernel, solver, jump_h=jump_h)
        self.wanted, self.last = sorted(set(maps_at)), None

    @property
    def spent(self) -> int:
        """Convolutions of the extra rows' solves."""
        return self.walker.spent

    def skip(self, D, eq) -> None:
        """The rows down to ``D`` were recorded without this object (copied from the approach): the asked D
        they passed are done, and the walk goes on from ``eq`` at D."""
        if self.last is not None:
            lo, hi = sorted((self.last[0], D))
            self.wanted = [m for m in self.wanted if not lo - _D_TOL <= m <= hi + _D_TOL]
        self.last = None if eq is None else (D, eq)

    def _hit(self, D):
        return next((m for m in self.wanted if abs(D - m) <= _D_TOL * max(1.0, abs(m))), None)

    def __call__(self, D, eq, on_grid, jump):
        if self.last is not None:
            Da, eqa = self.last
            lo, hi = min(Da, D), max(Da, D)
            passed = [m for m in self.wanted if lo < m < hi and self._hit(D) != m and self._hit(Da) != m]
            for m in sorted(passed, reverse=bool(D < Da)):  # in path order
                t = (m - Da) / (D - Da)
                start = eqa.state if jump else State(eqa.state.q + t * (eq.state.q - eqa.state.q),
                                                      eqa.state.w + t * (eq.state.w - eqa.state.w))
                eqm = self.walker.solve(m, start)
                jm = bool(jump) and self.walker.jumped(eqa, eqm, m - Da)
                self.record(m, eqm, False, jm, m)
                self.wanted.remove(m)
                if jump:  # the jump lies on one side of the extra row: flag the row after it
                    jump = self.walker.jumped(eqm, eq, D - m)
                Da, eqa = m, eqm
        m = self._hit(D)
        self.record(D, eq, on_grid, jump, m)
        if m is not None:
            self.wanted.remove(m)
        self.last = (D, eq)


def walk_states(U0, law, kernel, solver, Ds, start: State | None = None):
    """Equilibria of Eq. (9) at the displacements ``Ds``, in the order given (up or down), each solved
    from the secant extrapolation of the two before (the first from ``start``, default zero).

    One branch only: no jump detection or step refinement (use :func:`run_path` for that); meant for
    short, finely stepped walks along a branch from a state already on it.  Yields (D, Equilibrium).
    """
    walker = Walker(U0, law, kernel, solver)
    state = start if start is not None else State.zero(kernel.grid.shape)
    for D in Ds:
        D = float(D)
        if walker.hist:  # the secant of the last two, at any distance, either way
            state, _ = walker.predict(D, c_max=np.inf, c_min=-np.inf)
        eq = walker.solve(D, state)
        walker.push(D, eq.state)
        yield D, eq
