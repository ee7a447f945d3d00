"""The energy lost per approach–retraction cycle, ∮ F dD, with its quadrature uncertainty.

The two branches of a run are sampled at different D (adaptive steps, rows added for maps, a path that ends at
another D), so "trapezoid of the approach minus trapezoid of the retraction", each over its own rows, carries the
two rules' different errors: for a smooth F(D) that both branches follow (no jump: an elastic body with a
conservative law dissipates nothing) it gives a number of either sign that is quadrature error only.

:func:`loop_energy` instead

1. takes the D range both branches cover (outside it there is no cycle);
2. splits each branch into its smooth segments at its recorded jumps (the ``jump`` column; none without it);
3. puts both branches on one set of points, the union of their rows in that range: a branch's own value where it
   has a row, else a monotone cubic (PCHIP) through its own segment, never across a jump; inside a jump's D
   interval the straight line between the two rows (the trapezoid across the jump, as before);
4. integrates the difference approach − retraction on those points.

The uncertainty (``bound``) is the sum of

- the change of that number when each branch is filled in linearly instead (the trapezoid rule: the old rule's
  disagreement with the higher-order one), plus the change from the trapezoid to Simpson's rule of the
  difference itself, over the D runs between jumps (the error both branches share), and the sums' rounding:
  ``quadrature``;
- the solver's share: each row's F is known to about |dF/dD| × its residual (the ``residual`` column, a gap
  error in the units of D, times the branch's stiffness), integrated over D for both branches (two branches at
  the same D differ by about that: one converged from below, the other from above): ``solver``;
- for each jump, half of |ΔF| × ΔD over the interval in which it happened (where in it the state jumped is not
  known): ``jumps``.

A loop energy whose magnitude is within that bound is not distinguishable from zero and is reported as 0 (never
as a negative energy); a larger one keeps its value, sign included.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.integrate import simpson, trapezoid
from scipy.interpolate import PchipInterpolator


@dataclass(frozen=True)
class LoopEnergy:
    """∮ F dD of a run (approach minus retraction) in the run's units of F × D.

    ``value``: the energy lost per cycle, 0 when ``estimate`` is within ``bound``; ``estimate``: the
    higher-order number itself; ``bound``: its uncertainty, the sum of ``quadrature`` (from the rule),
    ``solver`` (from the solver's stopping residual) and ``jumps`` (from where in their D intervals the jumps
    happened); ``D_range``: the common D range integrated over."""

    value: float
    estimate: float
    bound: float
    quadrature: float
    solver: float
    jumps: float
    D_range: tuple

    @property
    def resolved(self) -> bool:
        """Whether the energy is distinguishable from zero (|estimate| > bound)."""
        return self.value != 0.0


ZERO = LoopEnergy(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, (float("nan"), float("nan")))


class _Branch:
    """One branch as a function of D: PCHIP inside its smooth segments, a straight line across its jumps."""

    def __init__(self, D, F, jump, residual):
        D, F = np.asarray(D, float), np.asarray(F, float)
        jump = np.zeros(len(D), bool) if jump is None else np.asarray(jump, bool)
        res = np.zeros(len(D)) if residual is None else np.nan_to_num(np.abs(np.asarray(residual, float)))
        ok = np.isfinite(D) & np.isfinite(F)
        D, F, jump, res = D[ok], F[ok], jump[ok], res[ok]
        cuts = [0, *[int(i) for i in np.flatnonzero(jump) if i > 0], len(D)]
        self.segments, self.residuals = [], []  # (D sorted unique, F) and the residuals, in D order
        for a, b in sorted(zip(cuts[:-1], cuts[1:]), key=lambda ab: D[ab[0]:ab[1]].min() if ab[1] > ab[0] else 0):
            if b > a:
                x, inv = np.unique(D[a:b], return_inverse=True)
                n = np.bincount(inv)
                self.segments.append((x, np.bincount(inv, weights=F[a:b]) / n))  # equal D: their mean
                self.residuals.append(np.bincount(inv, weights=res[a:b]) / n)
        self.lo = min(s[0][0] for s in self.segments)
        self.hi = max(s[0][-1] for s in self.segments)
        self._pchip = [PchipInterpolator(x, y) if len(x) >= 3 else None for x, y in self.segments]

    def gaps(self):
        """The D intervals of its jumps, (D before, D after) sorted."""
        return [tuple(sorted((x0[-1], x1[0]))) for (x0, _), (x1, _) in zip(self.segments[:-1], self.segments[1:])]

    def rows(self):
        return np.concatenate([s[0] for s in self.segments])

    def jump_error(self, lo, hi) -> float:
        """Σ |ΔF| ΔD / 2 over the jumps between consecutive segments that lie inside [lo, hi]."""
        err = 0.0
        for (x0, y0), (x1, y1) in zip(self.segments[:-1], self.segments[1:]):
            if x0[-1] >= lo and x1[0] <= hi:
                err += 0.5 * abs(y1[0] - y0[-1]) * abs(x1[0] - x0[-1])
        return err

    def at(self, x, cubic: bool):
        """F at points x (within [lo, hi]): own rows exactly, PCHIP or linear inside a segment, linear across a
        jump's interval."""
        allx = self.rows()
        order = np.argsort(allx, kind="stable")
        # linear everywhere first, across the jumps' intervals too (the trapezoid across a jump)
        out = np.interp(x, allx[order], np.concatenate([s[1] for s in self.segments])[order])
        if cubic:
            for (sx, _), p in zip(self.segments, self._pchip):
                if p is None:
                    continue
                m = (x >= sx[0]) & (x <= sx[-1])
                out[m] = p(x[m])
        return out

    def solver_error(self, x):
        """|dF/dD| × residual at x inside its segments (0 in a jump's interval): the error of F that the
        solver's stopping residual (a gap error, in the units of D) leaves, the branch's stiffness times it."""
        out = np.zeros(len(x))
        for (sx, sy), sr, p in zip(self.segments, self.residuals, self._pchip):
            m = (x >= sx[0]) & (x <= sx[-1])
            if len(sx) < 2 or not m.any():
                continue
            slope = p.derivative()(x[m]) if p is not None else (sy[-1] - sy[0]) / (sx[-1] - sx[0])
            out[m] = np.abs(slope) * np.interp(x[m], sx, sr)
        return out


def _rule_change(g, x, gaps) -> float:
    """Σ |trapezoid − Simpson| of g over the runs of x between the jumps' intervals (where g is smooth)."""
    inside = np.zeros(len(x) - 1, bool)  # interval k = [x_k, x_k+1] within a jump's D interval
    for g0, g1 in gaps:
        inside |= (x[:-1] >= g0) & (x[1:] <= g1)
    err, start = 0.0, 0
    for k in [*np.flatnonzero(inside), len(x) - 1]:
        n = k + 1 - start
        if n >= 3:  # at least three points; an odd count (Simpson's rule proper: SciPy's handling of an even
            # count changed between releases), the run's last interval left to the trapezoid alone
            end = start + (n if n % 2 else n - 1)
            xs, gs = x[start:end], g[start:end]
            err += abs(float(trapezoid(gs, xs)) - float(simpson(gs, x=xs)))
        start = k + 1
    return err


def loop_energy(D, F, branch, jump=None, residual=None) -> LoopEnergy:
    """∮ F dD (approach minus retraction) of a run's rows with its uncertainty (module doc); columns in path order.
    Zero (with a zero bound) when either branch has fewer than two rows or the branches share no D range."""
    D, F, branch = np.asarray(D, float), np.asarray(F, float), np.asarray(branch).astype(str)
    parts = {}
    for name in ("approach", "retraction"):
        m = branch == name
        if np.count_nonzero(m & np.isfinite(D) & np.isfinite(F)) < 2:
            return ZERO
        parts[name] = _Branch(D[m], F[m], *(None if c is None else np.asarray(c)[m] for c in (jump, residual)))
    a, r = parts["approach"], parts["retraction"]
    lo, hi = max(a.lo, r.lo), min(a.hi, r.hi)
    if not hi > lo:
        return ZERO
    x = np.unique(np.r_[a.rows(), r.rows(), lo, hi])
    x = x[(x >= lo) & (x <= hi)]
    g = a.at(x, True) - r.at(x, True)
    est = float(trapezoid(g, x))
    quad = abs(est - float(trapezoid(a.at(x, False) - r.at(x, False), x))) + _rule_change(g, x, a.gaps() + r.gaps())
    solver = float(trapezoid(a.solver_error(x) + r.solver_error(x), x))
    jumps = float(a.jump_error(lo, hi) + r.jump_error(lo, hi))
    roundoff = 64 * np.finfo(float).eps * float(trapezoid(np.abs(a.at(x, True)) + np.abs(r.at(x, True)), x))
    quad += roundoff  # the sums' own rounding: a loop of two identical branches is 0, not ±1e-17
    bound = quad + solver + jumps
    value = est if abs(est) > bound else 0.0
    return LoopEnergy(value, est, bound, quad, solver, jumps, (float(lo), float(hi)))
