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

from dataclasses import dataclass

import numpy as np

from tengsim.analysis import force
from tengsim.continuation import Branch, Recorder, StateOnly, persist, secant, spent
from tengsim.errors import TengsimError, finite, positive
from tengsim.solvers import Problem, State


_D_TOL = 1e-9
"""Relative tolerance (of max(1, |D|)) within which a row's D is a requested ``maps_at`` D."""


@dataclass(frozen=True)
class PathSpec:
    """Approach from ``d_min`` to ``d_max`` then retraction back, in steps of ``d_step``.

    Every branch has a row at each D = d_min + k·d_step; step refinement only adds rows between.
    ``maps_at`` lists D values whose pressure and gap maps are kept, on both branches, each exactly at
    its D: a value off the rows the walk visits gets an extra row there (``on_grid`` False: ``on_grid``
    keeps meaning "on the d_step lattice"), solved from the two rows around it on the branch (their
    states interpolated; across a jump, from the state before it), without entering the continuation,
    so every other row is the one the run has without ``maps_at``.  A value outside [d_min, the last D
    of the lattice] is refused.

    ``adaptive=True``: the step h takes the values d_step/2^k (k = 0 … ``refine_levels``) and stays on
    the lattice D = d_min + j·d_step/2^k, so every row lies on the finest lattice and every
    D = d_min + k·d_step is still visited (those rows keep ``on_grid`` True: they are the rows a
    fixed-step run with the same ``d_step`` has; the others are the adaptive run's own).  After each
    step the solved state is compared with the linear extrapolation of the two before it (the
    secant predictor): the force error e_F = |F − F_pred| against ``adapt_tol`` × max(|F|, the most
    tensile |F| met so far on the path), and the gap error max|H − H_pred| (ε) against
    ``adapt_h``.  A step whose larger ratio ρ exceeds 1 keeps its (exact) end state and is refined by
    midpoints (recursively, each half judged by the midpoint's deviation from the chord), and the
    next step is divided by 2^⌈log₄ ρ⌉ (the error goes as h²); ρ < 1/4 lets the next step double
    (where the lattice allows).  The same second difference, centred on the step's start, also
    judges the step before it (look-back), which is refined the same way; each branch starts with
    d_step (its second step's look-back judges it).  Jumps are bisected to the smallest step as in
    the fixed scheme (a step that jumps is retried at half its length).  With refine_levels three
    above a fixed run's and d_step eight times its d_step, the smallest steps (and so the jump
    resolution) agree.  Measured (benchmarks/adaptive_path.py, dx 0.2): the defaults adapt_tol = 0.15,
    adapt_h = 0.5 reproduce the fixed curve of the paper's groups A, B, C to 0.15 % of
    max(|F|, |pull-off F|) with 2.4–2.9× fewer solves (the gap test sets the step out of contact,
    where the force is small against the pull-off scale).
    """

    d_min: float
    d_max: float
    d_step: float
    refine_levels: int = 4
    jump_h: float = 0.3
    predictor: bool = True
    retract: bool = True
    maps_at: tuple = ()
    adaptive: bool = False
    adapt_tol: float = 0.15
    adapt_h: float = 0.5

    def __post_init__(self):
        finite("d_min", self.d_min)
        finite("d_max", self.d_max)
        positive("d_step", self.d_step)
        if not self.d_max > self.d_min:
            raise TengsimError(f"d_max ({self.d_max}) must be greater than d_min ({self.d_min})")
        n = (self.d_max - self.d_min) / self.d_step
        if n > 200000:
            raise TengsimError(f"d_step={self.d_step} gives {n:.0f} steps; choose a larger step")
        if int(self.refine_levels) < 0:
            raise TengsimError(f"refine_levels must be >= 0, got {self.refine_levels!r}")
        object.__setattr__(self, "maps_at", tuple(finite("maps_at", d) for d in self.maps_at))
        last = float(self.targets()[-1])
        for d in self.maps_at:
            if not self.d_min - _D_TOL * max(1.0, abs(d)) <= d <= last + _D_TOL * max(1.0, abs(d)):
                raise TengsimError(f"maps_at D = {d:g} is outside the path's D range [{self.d_min:g}, {last:g}]"
                                   + (f" (the last D of the d_step lattice below d_max = {self.d_max:g})"
                                      if last < self.d_max - 1e-9 else ""))
        positive("adapt_tol", self.adapt_tol)
        positive("adapt_h", self.adapt_h)
        if self.adaptive and int(self.refine_levels) > 30:
            raise TengsimError(f"refine_levels must be <= 30 with adaptive steps, got {self.refine_levels!r}")

    def extra_params(self) -> dict:
        """Path parameters beyond d_min, d_max, d_step, refine_levels, jump_h (none for fixed steps)."""
        if not self.adaptive:
            return {}
        return {"adaptive": True, "adapt_tol": self.adapt_tol, "adapt_h": self.adapt_h}

    def targets(self) -> np.ndarray:
        k = int(np.floor((self.d_max - self.d_min) / self.d_step + 1e-9))
        return self.d_min + self.d_step * np.arange(k + 1)


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
    A load-controlled path is :func:`tengsim.loadpath.run_load_path`.
    """
    if not isinstance(spec, PathSpec):
        raise TengsimError(f"run_path walks a PathSpec (rigid approach D); got {type(spec).__name__} "
                           "(a LoadPathSpec runs with tengsim.loadpath.run_load_path)")
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


def compare_paths(ref, other, interp: str = "pchip") -> dict:
    """How far the curve ``other`` is from ``ref`` (two ContactResults of the same problem).

    Per branch, ``other`` is cut at its jumps into continuous segments and F is interpolated on each
    segment (``interp`` 'linear': the curve as plotted; 'pchip': monotone cubic, scipy's PCHIP, linear
    on a 2-row segment) at every D of ``ref`` that lies
    inside one of them; D values of ``ref`` inside a jump interval of ``other`` (between its D_before
    and D_after) are skipped, and so are rows of ``ref`` that start a jump (the state on the far
    side of ``ref``'s own jump, compared only if ``other`` has a segment there).  The difference is
    relative to max(|F_ref(D)|, F_adh), F_adh = the magnitude of the most tensile F of ``ref`` (the adhesive force
    scale), so it is a relative error where |F| is large and an error in units of the pull-off force
    where F crosses zero.  Returns {'max_rel_dF', 'where' ((branch, D) of it), 'n_compared', 'n_skipped', 'max_rel_dF_same_D'
    (rows at equal D, no interpolation), 'jumps_ref', 'jumps_other' (lists of (branch, D_before,
    D_after)), 'max_jump_dD' (largest |ΔD_after| between jumps matched by branch and order; NaN if
    the counts differ)}.
    """
    from scipy.interpolate import PchipInterpolator

    f_adh = max(abs(float(np.min(ref.table["F"]))), 1e-12)
    worst, worst_same, n_cmp, n_skip, where = 0.0, 0.0, 0, 0, None
    for br in ("approach", "retraction"):
        a, b = ref.branch(br), other.branch(br)
        if len(a["D"]) == 0 or len(b["D"]) == 0:
            continue
        cuts = [0] + [i for i in np.flatnonzero(b["jump"]) if i > 0] + [len(b["D"])]
        segs = []
        for i0, i1 in zip(cuts[:-1], cuts[1:]):
            D, F = b["D"][i0:i1], b["F"][i0:i1]
            if len(D) == 0:
                continue
            o = np.argsort(D)
            D, F = D[o], F[o]
            fn = PchipInterpolator(D, F) if len(D) >= 3 and interp == "pchip" else (lambda x, D=D, F=F: np.interp(x, D, F))
            segs.append((D[0], D[-1], fn))
        for D, F in zip(a["D"], a["F"]):
            seg = [s for s in segs if s[0] - 1e-12 <= D <= s[1] + 1e-12]
            if not seg:
                n_skip += 1
                continue
            scale = max(abs(F), f_adh)
            e = min(abs(float(s[2](D)) - F) for s in seg) / scale
            if e > worst:
                worst, where = e, (br, float(D))
            n_cmp += 1
            same = np.flatnonzero(np.abs(b["D"] - D) < 1e-9)
            if len(same):
                worst_same = max(worst_same, float(np.min(np.abs(b["F"][same] - F))) / scale)

    def jl(res):
        return [(j.branch, j.D_before, j.D_after) for j in res.jumps]

    ja, jb = jl(ref), jl(other)
    if len(ja) == len(jb) and all(x[0] == y[0] for x, y in zip(ja, jb)):
        dj = max((abs(x[2] - y[2]) for x, y in zip(ja, jb)), default=0.0)
    else:
        dj = float("nan")
    return {"max_rel_dF": worst, "where": where, "max_rel_dF_same_D": worst_same, "n_compared": n_cmp,
            "n_skipped": n_skip, "jumps_ref": ja, "jumps_other": jb, "max_jump_dD": dj}


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
