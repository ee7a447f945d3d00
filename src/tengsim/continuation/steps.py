"""Step controls for the walker (:class:`tengsim.continuation.walker.Walker`): which D a branch visits.

- :class:`FixedSteps`: the given stops, each step bisected where it jumps (up to ``refine_levels`` times;
  0: plain fixed steps);
- :class:`AdaptiveSteps`: steps d_step/2^k on the dyadic lattice of d_step, the step set by the error of
  the secant extrapolation (force and gap), refined where the path bends, widened where it is straight;
  a step that jumps is retried at half its length down to the smallest.

Each is configuration; ``plan(walker, eq, D_from, stops, on_grid)`` makes the state of one walk (the
protocol is in :mod:`tengsim.continuation.walker`).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tengsim.analysis import force
from tengsim.solvers import State


@dataclass(frozen=True)
class FixedSteps:
    """Steps from stop to stop; a step that jumps is bisected, the halves walked in turn (each bisected
    again where it jumps), up to ``refine_levels`` times; a jump that survives the finest step is recorded.
    Rows added by bisection are off the grid.  ``predictor``: secant starts (within 1.5 steps)."""

    refine_levels: int = 4
    predictor: bool = True
    c_max = 1.5

    def plan(self, walker, eq, D_from, stops, on_grid):
        return _FixedPlan(self, stops, on_grid)


class _FixedPlan:
    def __init__(self, ctl: FixedSteps, stops, on_grid):
        self.L, self.predictor, self.c_max = int(ctl.refine_levels), ctl.predictor, ctl.c_max
        self.todo = [(D, 0, on_grid) for D in reversed(stops)]  # (D, level, on_grid), the next on top

    def next(self):
        return self.todo[-1][0] if self.todo else None

    def can_refine(self) -> bool:
        return self.todo[-1][1] < self.L

    def refine(self, Da, Db):
        _, level, on_grid = self.todo[-1]
        if level >= self.L:
            return False
        self.todo[-1] = (Db, level + 1, on_grid)
        self.todo.append((0.5 * (Da + Db), level + 1, False))
        return True

    def accept(self, Da, eqa, Db, eqb, jump):
        _, _, on_grid = self.todo.pop()
        return [(Db, eqb, on_grid, jump)], ()

    def finish(self):
        return ()


class AdaptiveSteps:
    """Adaptive steps h = d_step/2^k (k = 0 … ``refine_levels``) on the lattice D = d_min + j·d_step/2^k
    (see :class:`tengsim.continuation.specs.PathSpec`, ``adaptive=True``, for the method and its
    measured accuracy).  ``adapt_tol``: the force error against max(|F|, the most tensile |F| met so far
    on the path); ``adapt_h``: the gap error (ε).  One object per path: it keeps that force scale across
    the path's branches.  Rows on the d_step lattice are on the grid."""

    predictor = True
    c_max = 2.0

    def __init__(self, d_min, d_step, refine_levels, adapt_tol, adapt_h):
        self.d_min, self.d_step, self.L = d_min, d_step, int(refine_levels)
        self.adapt_tol, self.adapt_h = adapt_tol, adapt_h
        self.f_scale = 0.0  # the most tensile |F| met so far on the path

    @classmethod
    def of(cls, spec) -> "AdaptiveSteps":
        """The step control of an adaptive PathSpec."""
        return cls(spec.d_min, spec.d_step, spec.refine_levels, spec.adapt_tol, spec.adapt_h)

    def plan(self, walker, eq, D_from, stops, on_grid):
        return _AdaptivePlan(self, walker, eq, D_from, stops[-1] if len(stops) else D_from)

    def on_grid(self, D) -> bool:
        return abs((D - self.d_min) / self.d_step - round((D - self.d_min) / self.d_step)) < 1e-9

    def scale(self, F) -> float:
        return max(abs(F), self.f_scale, 1e-12)

    def errors(self, eF, eH, F) -> float:
        """The larger of a force error and a gap error (ε) over their tolerances."""
        return max(eF / (self.adapt_tol * self.scale(F)), eH / self.adapt_h)


class _AdaptivePlan:
    """One adaptive walk: the lattice index, the level, the force of the walker's history, the row held
    back until the next step has judged the step before it (the look-back)."""

    def __init__(self, ctl: AdaptiveSteps, walker, eq, D_from, D_to):
        self.ctl, self.walker, self.grid = ctl, walker, walker.kernel.grid
        self.predictor, self.c_max, L = ctl.predictor, ctl.c_max, ctl.L
        self.h_min = ctl.d_step / 2**L
        self.sgn = 1 if D_to > D_from else -1
        self.j = int(round((D_from - ctl.d_min) / self.h_min))
        self.j_end = int(round((D_to - ctl.d_min) / self.h_min))
        self.hist_F = [force(eq.P, self.grid)]  # F of the states in walker.hist
        self.level = 0  # the first step has no error estimate: the look-back of the second judges it
        if len(walker.hist) == 2 and getattr(walker, "F_before", None) is not None:
            # going on from a history given to the walker (a retraction restored at an approach jump): the
            # step of that history's level first, as a walk that came down through it would take
            (D0, _), (D1, _) = walker.hist
            self.hist_F.insert(0, float(walker.F_before))
            self.level = int(np.clip(L - round(np.log2(max(abs(D1 - D0), self.h_min) / self.h_min)), 0, L))
        self.pending = None

    def next(self):
        if self.j == self.j_end:
            return None
        L, k, j = self.ctl.L, self.level, self.j
        # the step 2^(L−k) h_min must start on its own lattice and not pass the end
        while k < L and (j % 2 ** (L - k) != 0 or 2 ** (L - k) > abs(self.j_end - j)):
            k += 1
        self.k, self.nj = k, j + self.sgn * 2 ** (L - k)
        return self.ctl.d_min + self.nj * self.h_min

    def can_refine(self) -> bool:
        return self.k < self.ctl.L

    def refine(self, Da, Db):
        if self.k >= self.ctl.L:
            return False
        self.level = self.k + 1
        return True

    def _error(self, Db, eqb):
        """The step's error ratio: the solved state against the secant extrapolation (0 without history)."""
        hist = self.walker.hist
        if len(hist) < 2:
            return 0.0
        (D0, s0), (D1, s1) = hist
        c = (Db - D1) / (D1 - D0)
        F0, F1 = self.hist_F
        Fb = force(eqb.P, self.grid)
        # H = U0 − D + w, and D is extrapolated exactly: the gap error is the error of w
        eH = float(np.max(np.abs(eqb.state.w - (s1.w + c * (s1.w - s0.w)))))
        return self.ctl.errors(abs(Fb - (F1 + c * (F1 - F0))), eH, Fb)

    def _ratio(self, D0, s0, F0, D1, s1, F1, Dn, sn, Fn):
        """Error ratio of the step D0 → D1 from the curvature of three states: |F''| h² (and the gap's)
        over the tolerances, F'' the second divided difference of (D0, D1, Dn); equals the look-back
        ratio err/c² for equal steps."""
        c = (Dn - D1) / (D1 - D0)
        w = 2 * (D1 - D0) ** 2 / ((Dn - D1) * (Dn - D0))
        eH = float(np.max(np.abs(sn.w - (s1.w + c * (s1.w - s0.w)))))
        return self.ctl.errors(w * abs(Fn - (F1 + c * (F1 - F0))), w * eH, Fn)

    def _insert(self, Da, sa, Fa, Db, sb, Fb, err, level):
        """Midpoints of a step (end states ``sa``, ``sb``) whose error ratio ``err`` exceeds 1, in path
        order [(D, eq, F), …].

        The midpoint starts from the mean of the end states; its deviation δ from the chord gives
        each half its own ratio (F'' h² = 8δ, so a half's ratio is 2δ over the tolerance)."""
        if err <= 1.0 or level > self.ctl.L:
            return []
        Dm = 0.5 * (Da + Db)
        eqm = self.walker.solve(Dm, State(0.5 * (sa.q + sb.q), 0.5 * (sa.w + sb.w)))
        Fm = force(eqm.P, self.grid)
        e = self.ctl.errors(2 * abs(Fm - 0.5 * (Fa + Fb)),
                            2 * float(np.max(np.abs(eqm.state.w - 0.5 * (sa.w + sb.w)))), Fm)
        return (self._insert(Da, sa, Fa, Dm, eqm.state, Fm, e, level + 1) + [(Dm, eqm, Fm)]
                + self._insert(Dm, eqm.state, Fm, Db, sb, Fb, e, level + 1))

    def accept(self, Da, eqa, Db, eqb, jump):
        ctl, L, k = self.ctl, self.ctl.L, self.k
        err = 0.0 if jump else self._error(Db, eqb)
        Fb = force(eqb.P, self.grid)
        inner, back = [], []
        if err > 1.0 and k < L:
            # the solved state is kept; the interval is refined by midpoints instead
            inner = self._insert(Da, eqa.state, self.hist_F[-1], Db, eqb.state, Fb, err, k + 1)
            # the error goes as h²: shrink by enough levels to bring it under 1
            self.level = min(L, k + max(1, int(np.ceil(np.log(err) / np.log(4.0)))))
        else:
            self.level = max(k - 1, 0) if err < 0.25 else k
        if err > 0 and self.pending is not None and not self.pending[3]:
            # look back: a second difference centred on Da judges the step before it, taken with
            # the nearest state beyond Da (the first midpoint when this step was refined), so
            # curvature further on is not charged to it
            (D0, s0), (D1, s1) = self.walker.hist
            kp = L - int(round(np.log2(abs(D1 - D0) / self.h_min)))
            if inner:
                Dn, eqn, Fn = inner[0]
                ratio = self._ratio(D0, s0, self.hist_F[0], D1, s1, self.hist_F[1], Dn, eqn.state, Fn)
            else:
                c = (Db - D1) / (D1 - D0)
                ratio = err / c**2
            back = self._insert(D0, s0, self.hist_F[0], D1, s1, self.hist_F[1], ratio, kp + 1)
        rows = [(Dm, eqm, ctl.on_grid(Dm), False) for Dm, eqm, _ in back]
        if self.pending is not None:
            rows.append(self.pending)
        for Dm, eqm, Fm in inner:
            ctl.f_scale = max(ctl.f_scale, -Fm)
            rows.append((Dm, eqm, ctl.on_grid(Dm), False))
        ctl.f_scale = max(ctl.f_scale, -Fb)
        self.hist_F = [Fb] if jump else [inner[-1][2] if inner else self.hist_F[-1], Fb]
        self.pending = (Db, eqb, self.nj % 2**L == 0, jump)
        self.j = self.nj
        return rows, [(Dm, eqm) for Dm, eqm, _ in inner]

    def finish(self):
        return [self.pending] if self.pending is not None else []
