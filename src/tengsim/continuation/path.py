"""Continuation in the rigid approach D: approach (D up) then retraction (D down), paper Section 2.

Each equilibrium is warm-started from the previous one on its branch (with a secant predictor), so
the path follows the stable branch and shows jump-in, jump-out and hysteresis as the paper's VSR
does.  Step control: when the gap field changes by more than ``jump_h`` (in ε, beyond the rigid
shift |ΔD|) across a step, the step is bisected, up to ``refine_levels`` times; a change that
survives the finest step is recorded as a jump.

With ``PathSpec(adaptive=True)`` the step also adapts where the path is smooth (:class:`_Adaptive`):
``d_step`` is then the largest step and d_step/2^refine_levels the smallest.
"""
from __future__ import annotations

import numpy as np

from tengsim.analysis import force
from tengsim.continuation.recorder import Recorder, spent
from tengsim.continuation.specs import _D_TOL, PathSpec
from tengsim.continuation.walker import Branch, StateOnly, persist, secant
from tengsim.errors import TengsimError
from tengsim.solvers import Problem, State


class _Adaptive(Branch):
    """Walks one branch with adaptive steps on the dyadic lattice of ``d_step`` (see PathSpec)."""

    def __init__(self, U0, law, kernel, solver, spec, on_row, f_scale):
        super().__init__(U0, law, kernel, solver, spec, on_row)
        self.f_scale = f_scale      # one-element list: the most tensile |F| met so far on the path
        self.hist_F: list = []      # F of the states in hist
        self.curve: list = []       # (D, F) of the last rows accepted on this piece, in path order
        self.level = 0  # the first step has no error estimate: the look-back of the second judges it

    def _start(self, D):
        (D1, s1) = self.hist[-1]
        if len(self.hist) >= 2:
            D0, s0 = self.hist[-2]
            c = (D - D1) / (D1 - D0)
            if 0 < c <= 2.0:
                return secant(s0, s1, c), True
        return s1, False

    def _error(self, Db, eqb):
        """Larger of the force and gap extrapolation errors over their tolerances (0 without history)."""
        if len(self.hist) < 2:
            return 0.0
        (D0, s0), (D1, s1) = self.hist
        c = (Db - D1) / (D1 - D0)
        F0, F1 = self.hist_F
        Fb = force(eqb.P, self.kernel.grid)
        scale = max(abs(Fb), self.f_scale[0], 1e-12)
        eF = abs(Fb - (F1 + c * (F1 - F0)))
        eF /= self.spec.adapt_tol * scale
        # H = U0 − D + w, and D is extrapolated exactly: the gap error is the error of w
        eH = float(np.max(np.abs(eqb.state.w - (s1.w + c * (s1.w - s0.w))))) / self.spec.adapt_h
        return max(eF, eH)

    def _ratio(self, D0, s0, F0, D1, s1, F1, Dn, sn, Fn):
        """Error ratio of the step D0 → D1 from the curvature of three states: |F''| h² (and the gap's)
        over the tolerances, F'' the second divided difference of (D0, D1, Dn); equals the look-back
        ratio err/c² for equal steps."""
        c = (Dn - D1) / (D1 - D0)
        w = 2 * (D1 - D0) ** 2 / ((Dn - D1) * (Dn - D0))
        scale = max(abs(Fn), self.f_scale[0], 1e-12)
        eF = w * abs(Fn - (F1 + c * (F1 - F0))) / (self.spec.adapt_tol * scale)
        eH = w * float(np.max(np.abs(sn.w - (s1.w + c * (s1.w - s0.w))))) / self.spec.adapt_h
        return max(eF, eH)

    def _on_grid(self, D):
        return abs((D - self.spec.d_min) / self.spec.d_step - round((D - self.spec.d_min) / self.spec.d_step)) < 1e-9

    def _insert(self, Da, eqa, Fa, Db, eqb, Fb, err, level):
        """Midpoints of a step whose error ratio ``err`` exceeds 1, in path order [(D, eq, F), …].

        The midpoint starts from the mean of the end states; its deviation δ from the chord gives
        each half its own ratio (F'' h² = 8δ, so a half's ratio is 2δ over the tolerance)."""
        if err <= 1.0 or level > int(self.spec.refine_levels):
            return []
        Dm = 0.5 * (Da + Db)
        sa, sb = eqa.state, eqb.state
        eqm = self.solve(Dm, State(0.5 * (sa.q + sb.q), 0.5 * (sa.w + sb.w)))
        Fm = force(eqm.P, self.kernel.grid)
        scale = max(abs(Fm), self.f_scale[0], 1e-12)
        eF = 2 * abs(Fm - 0.5 * (Fa + Fb)) / (self.spec.adapt_tol * scale)
        eH = 2 * float(np.max(np.abs(eqm.state.w - 0.5 * (sa.w + sb.w)))) / self.spec.adapt_h
        e = max(eF, eH)
        return (self._insert(Da, eqa, Fa, Dm, eqm, Fm, e, level + 1) + [(Dm, eqm, Fm)]
                + self._insert(Dm, eqm, Fm, Db, eqb, Fb, e, level + 1))

    def walk(self, D_from, eq, D_to):
        """From the accepted state ``eq`` at ``D_from`` to ``D_to`` (both on the d_step grid)."""
        L = int(self.spec.refine_levels)
        h_min = self.spec.d_step / 2**L
        sgn = 1 if D_to > D_from else -1
        j = int(round((D_from - self.spec.d_min) / h_min))
        j_end = int(round((D_to - self.spec.d_min) / h_min))
        Da = D_from
        pending = None  # the last row, emitted once the next step has judged the step before it
        while j != j_end:
            k = self.level
            # the step 2^(L−k) h_min must start on its own lattice and not pass the end
            while k < L and (j % 2 ** (L - k) != 0 or 2 ** (L - k) > abs(j_end - j)):
                k += 1
            nj = j + sgn * 2 ** (L - k)
            Db = self.spec.d_min + nj * h_min
            start, predicted = self._start(Db)
            eqb = self.solve(Db, start)
            if predicted and self._jumped(eq, eqb, Db - Da):
                eqb = self.solve(Db, eq.state)  # confirm without the predictor
            jump = self._jumped(eq, eqb, Db - Da)
            if jump and k < L:
                self.level = k + 1
                continue
            err = 0.0 if jump else self._error(Db, eqb)
            Fb = force(eqb.P, self.kernel.grid)
            inner, back = [], []
            if err > 1.0 and k < L:
                # the solved state is kept; the interval is refined by midpoints instead
                inner = self._insert(Da, eq, self.hist_F[-1], Db, eqb, Fb, err, k + 1)
                # the error goes as h²: shrink by enough levels to bring it under 1
                self.level = min(L, k + max(1, int(np.ceil(np.log(err) / np.log(4.0)))))
            else:
                self.level = max(k - 1, 0) if err < 0.25 else k
            if err > 0 and pending is not None and not pending[3]:
                # look back: a second difference centred on Da judges the step before it, taken with
                # the nearest state beyond Da (the first midpoint when this step was refined), so
                # curvature further on is not charged to it
                (D0, s0), (D1, s1) = self.hist
                kp = L - int(round(np.log2(abs(D1 - D0) / h_min)))
                if inner:
                    Dn, eqn, Fn = inner[0]
                    ratio = self._ratio(D0, s0, self.hist_F[0], D1, s1, self.hist_F[1], Dn, eqn.state, Fn)
                else:
                    c = (Db - D1) / (D1 - D0)
                    ratio = err / c**2
                back = self._insert(D0, StateOnly(s0), self.hist_F[0], D1, StateOnly(s1), self.hist_F[1], ratio, kp + 1)
            for Dm, eqm, Fm in back:
                self.on_row(Dm, eqm, self._on_grid(Dm), False)
            if pending is not None:
                self.on_row(*pending)
            for Dm, eqm, Fm in inner:
                self.f_scale[0] = max(self.f_scale[0], -Fm)
                self.on_row(Dm, eqm, self._on_grid(Dm), False)
            self.f_scale[0] = max(self.f_scale[0], -Fb)
            if jump:
                self.hist, self.hist_F = [(Db, eqb.state)], [Fb]
                self.curve = [(Db, Fb)]
            else:
                self.curve = (self.curve + [(d, fm) for d, _, fm in inner] + [(Db, Fb)])[-3:]
                prev = inner[-1] if inner else (Da, eq, self.hist_F[-1])
                self.hist = [(prev[0], prev[1].state), (Db, eqb.state)]
                self.hist_F = [prev[2], Fb]
            pending = (Db, eqb, nj % 2**L == 0, jump)
            j, Da, eq = nj, Db, eqb
        if pending is not None:
            self.on_row(*pending)
        return eq


def run_path(U0, law, kernel, solver, spec: PathSpec, start: State | None = None,
             progress=None, keep_states: bool = False, observers=(), sink=None):
    """Solve the approach–retraction path; returns a :class:`tengsim.results.ContactResult`.

    ``progress(branch, D, done, total)`` is called after each row on the D grid.  ``observers``
    (registered names or objects, see :mod:`tengsim.observers`) add their columns to every row.
    ``sink(row, maps)`` is called with each row as it is recorded (:class:`tengsim.continuation.Recorder`).
    A load-controlled path is :func:`tengsim.continuation.run_load_path`.
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

    def rows(branch):  # the Recorder's callback, with the extra rows at the maps_at D between the walk's rows
        if not spec.maps_at:
            return rec.on_row(branch)
        walkers.append(_MapRows(rec.on_row(branch), spec.maps_at, U0, law, kernel, solver, spec.jump_h))
        return walkers[-1]

    if spec.adaptive:
        eq = _run_adaptive(U0, law, kernel, solver, spec, start, targets, rows, walkers)
        return spent(rec.result(eq.state if keep_states else None), walkers)
    walker = Branch(U0, law, kernel, solver, spec, rows("approach"))
    walkers.append(walker)
    eq = walker.solve(targets[0], start if start is not None else State.zero(kernel.grid.shape))
    walker.hist = [(targets[0], eq.state)]
    walker.on_row(targets[0], eq, True, False)
    for Da, Db in zip(targets[:-1], targets[1:]):
        eq = walker.advance(Da, eq, Db, 0, True)
    if spec.retract:
        back = Branch(U0, law, kernel, solver, spec, rows("retraction"))
        walkers.append(back)
        back.hist = [(targets[-1], eq.state)]
        back.on_row(targets[-1], eq, True, False)
        rev = targets[::-1]
        for Da, Db in zip(rev[:-1], rev[1:]):
            eq = back.advance(Da, eq, Db, 0, True)
    return spent(rec.result(eq.state if keep_states else None), walkers)



class _MapRows:
    """Passes a branch's rows to the Recorder's callback ``record``, in path order, adding a row at each
    requested D (``maps_at``) the walk steps over: when a row arrives whose step from the row before
    passes such a D, the state there is solved first (from the two rows' states interpolated; from the
    state before when the step is a jump) and recorded as an extra row (``on_grid`` False, its map kept:
    ``map_at``).  The walk's own continuation never sees these states.  A row at a requested D (to
    :data:`_D_TOL`) is the one that D's map is kept at."""

    def __init__(self, record, maps_at, U0, law, kernel, solver, jump_h):
        self.record, self.U0, self.law, self.kernel, self.solver = record, U0, law, kernel, solver
        self.wanted, self.jump_h, self.last = sorted(set(maps_at)), jump_h, None
        self.spent = 0  # convolutions of the extra rows' solves

    def _hit(self, D):
        return next((m for m in self.wanted if abs(D - m) <= _D_TOL * max(1.0, abs(m))), None)

    def _jumped(self, eqa, eqb, dD):
        return eqb.max_change(eqa) - abs(dD) > self.jump_h

    def __call__(self, D, eq, on_grid, jump):
        if self.last is not None:
            Da, eqa = self.last
            lo, hi = min(Da, D), max(Da, D)
            passed = [m for m in self.wanted if lo < m < hi and self._hit(D) != m and self._hit(Da) != m]
            for m in sorted(passed, reverse=bool(D < Da)):  # in path order
                t = (m - Da) / (D - Da)
                start = eqa.state if jump else State(eqa.state.q + t * (eq.state.q - eqa.state.q),
                                                      eqa.state.w + t * (eq.state.w - eqa.state.w))
                pm = Problem(self.U0 - m + 1.0, self.law, self.kernel)
                eqm = persist(self.solver, pm, self.solver.solve(pm, start))  # past the cap (issue 23)
                self.spent += int(eqm.n_conv)
                jm = bool(jump) and self._jumped(eqa, eqm, m - Da)
                self.record(m, eqm, False, jm, m)
                self.wanted.remove(m)
                if jump:  # the jump lies on one side of the extra row: flag the row after it
                    jump = self._jumped(eqm, eq, D - m)
                Da, eqa = m, eqm
        m = self._hit(D)
        self.record(D, eq, on_grid, jump, m)
        if m is not None:
            self.wanted.remove(m)
        self.last = (D, eq)


def _run_adaptive(U0, law, kernel, solver, spec, start, targets, make_on_row, walkers):
    f_scale = [0.0]
    walker = _Adaptive(U0, law, kernel, solver, spec, make_on_row("approach"), f_scale)
    walkers.append(walker)
    eq = walker.solve(targets[0], start if start is not None else State.zero(kernel.grid.shape))
    walker.hist, walker.hist_F = [(targets[0], eq.state)], [force(eq.P, kernel.grid)]
    walker.curve = [(targets[0], walker.hist_F[0])]
    walker.on_row(targets[0], eq, True, False)
    eq = walker.walk(targets[0], eq, targets[-1])
    if spec.retract:
        back = _Adaptive(U0, law, kernel, solver, spec, make_on_row("retraction"), f_scale)
        walkers.append(back)
        back.hist, back.hist_F = [(targets[-1], eq.state)], [force(eq.P, kernel.grid)]
        back.curve = [(targets[-1], back.hist_F[0])]
        back.on_row(targets[-1], eq, True, False)
        eq = back.walk(targets[-1], eq, targets[0])
    return eq


def walk_states(U0, law, kernel, solver, Ds, start: State | None = None):
    """Equilibria of Eq. (9) at the displacements ``Ds``, in the order given (up or down), each solved
    from the secant extrapolation of the two before (the first from ``start``, default zero).

    One branch only: no jump detection or step refinement (use :func:`run_path` for that); meant for
    short, finely stepped walks along a branch from a state already on it.  Yields (D, Equilibrium).
    """
    prev = []
    state = start if start is not None else State.zero(kernel.grid.shape)
    for D in Ds:
        D = float(D)
        if len(prev) == 2 and prev[1][0] != prev[0][0]:
            (D0, s0), (D1, s1) = prev
            c = (D - D1) / (D1 - D0)
            state = secant(s0, s1, c)
        problem = Problem(U0 - D + 1.0, law, kernel)
        eq = persist(solver, problem, solver.solve(problem, state))  # past the cap (issue 23)
        prev = (prev + [(D, eq.state)])[-2:]
        state = eq.state
        yield D, eq
