"""The fast solver's line search: (approximate) Wolfe conditions along d, element-wise only.

Along a direction d with image K d the gap is g(α) = g + α K d, so the energy of Eq. (9)'s cell

    E(α) = ΔA [½ q·w + α d·w + ½ α² d·K d + Σ Φ(g + α K d)],
    E'(α) = E'(0) + ΔA [α d·K d − (P(g + α K d) − P(g))·K d]

needs no convolution: one sweep over the grid per trial α (the pressure change is summed point by
point, so E' keeps its precision near convergence).  Accepted: the strong Wolfe conditions, or near
round-off the approximate Wolfe conditions of Hager & Zhang (2005),
E(α) <= E_ref + 1e-11 |E(0)| and 0.9 E'(0) <= E'(α) <= −0.8 E'(0).  The bracket is narrowed by
safeguarded secant steps on E'.
"""
from __future__ import annotations

import functools
import math
from typing import NamedTuple

import numpy as np

from tengsim import backend
from tengsim.solvers import _algebra
from tengsim.solvers._algebra import HOST
from tengsim.solvers._constants import C1, C2, FIRST_MOVE, MAX_EVAL


class Ray(NamedTuple):
    """E along the direction: the current gap g and pressure P, the image K d, and the scalars of E(α)."""

    g: np.ndarray
    P: np.ndarray
    Kd: np.ndarray
    qw: float       # q·w
    dw: float       # d·w
    dKd: float      # d·K d
    E0: float       # E(0)
    slope: float    # E'(0) = ΔA d·r


class Trial(NamedTuple):
    """An accepted step: α, E(α), ΣΦ(g(α)) and ΣP(g(α)) (0 unless the search sums P)."""

    alpha: float
    E: float
    phis: float
    sum_p: float


class WolfeLineSearch:
    """Wolfe line search on one grid: its constants and the trial buffers g(α), P(α).

    ``sum_p``: also sum P(g(α)) (the periodic gauge needs ΣP).  After :meth:`search` accepts α the
    trial buffers hold g(α) and P(α); :meth:`swap` hands them over and takes the old current arrays
    as the next trial buffers.
    """

    def __init__(self, law, sweeper, dA, g_trial, P_trial, sum_p=False, c1=C1, c2=C2, max_eval=MAX_EVAL,
                 first_move=FIRST_MOVE, lines=None, red=None):
        self.law, self.sweeper, self.dA = law, sweeper, float(dA)
        # a SafeLaw: its own hot path unchecked, the gaps' minimum checked once per sweep (laws.safe)
        self.unchecked = hasattr(law, "energy_pressure_unchecked")
        self.lines = lines  # a weighted problem's deficit pixels (tengsim.solvers._weights), or None
        self.red = red      # a distributed solve's sums over all ranks (tengsim.solvers._reduce), or None
        self.g_trial, self.P_trial = g_trial, P_trial
        self.sum_p = bool(sum_p)
        self.c1, self.c2, self.max_eval, self.first_move = c1, c2, int(max_eval), first_move

    def first_step(self, hi, lo) -> float:
        """α for a first direction (empty memory) from max K d and min K d (host floats): the gap moves by
        at most ``first_move`` (0.25 ε)."""
        m = max(hi, -lo)
        if self.red is not None:
            m = self.red.max(m)
        return _algebra.first_step(HOST, m, self.first_move)

    def swap(self, g, P):
        """The accepted (g(α), P(α)); ``g``, ``P`` become the trial buffers."""
        gt, Pt = self.g_trial, self.P_trial
        self.g_trial, self.P_trial = g, P
        return gt, Pt

    def block(self, sl, m, sc, acc, a, g, P, Kd, unchecked, o=0):
        """One block of a trial's sweep: g(α), P(α) into the trial buffers, [ΣΦ, Σ(P(α) − P)·K d, ΣP,
        min g] added to ``acc[o:o + 4]`` (backend scalars: no host sync inside a sweep; min g only
        ``unchecked``).  Block by block, the gap, the law's scratch and the pressure stay in cache; the
        fast solver also runs it inside its direction's sweep (the first trial, α = 1)."""
        buf = self.sweeper.buf
        gb, pb, kb = self.g_trial[sl], self.P_trial[sl], Kd[sl]
        np.multiply(kb, a, out=gb)
        np.add(gb, g[sl], out=gb)
        work = (buf(sc, "a", m), buf(sc, "b", m))
        if unchecked:
            e, g_min = self.law.energy_pressure_unchecked(gb, pb, work)
            acc[o] += e
            acc[o + 3] = np.minimum(acc[o + 3], g_min)
        else:
            acc[o] += self.law.energy_pressure(gb, pb, work)
        dp = buf(sc, "c", m)
        np.subtract(pb, P[sl], out=dp)
        acc[o + 1] += np.vdot(dp, kb)
        if self.sum_p:
            acc[o + 2] += pb.sum()

    def _sweep(self, a, ray: Ray, unchecked: bool):
        """[ΣΦ, Σ(P(α) − P)·K d, ΣP, min g(α)] of one sweep, backend scalars (min g: +inf unless
        ``unchecked``); the sums added over the groups as Sweeper.sum adds them."""
        accs = self.sweeper.run(self.block, [0.0, 0.0, 0.0, np.inf], a, ray.g, ray.P, ray.Kd, unchecked)
        if len(accs) == 1:
            return accs[0]
        out = [sum(acc[j] for acc in accs) for j in range(3)]
        return out + [functools.reduce(np.minimum, (acc[3] for acc in accs))]

    def evaluate(self, a, ray: Ray):
        """(E(α), E'(α), ΣΦ, ΣP) at α = ``a``, with g(α), P(α) written into the trial buffers.

        One host sync: the sweep's sums (and the weighted corrections) come over together, with the
        smallest trial gap, which says whether the law's unchecked hot path was right (else a second
        sweep, checked block by block: a trial far into contact)."""
        phis, dpk, sp, g_min = self._sweep(a, ray, self.unchecked)
        if self.lines is not None:  # the deficit pixels' share off, taken with the unchecked P(α) first
            phis, dpk, sp, g_min = backend.sync(self.weigh(phis, dpk, sp, ray.P, ray.Kd) + [g_min]).tolist()
            if self.unchecked and not self.law.covers(g_min):  # P(α) was not right there: checked anew
                phis, dpk, sp, _ = self._sweep(a, ray, False)
                phis, dpk, sp = backend.sync(self.weigh(phis, dpk, sp, ray.P, ray.Kd)).tolist()
        else:
            phis, dpk, sp, g_min = backend.sync((phis, dpk, sp, g_min)).tolist()
            if self.unchecked and not self.law.covers(g_min):
                phis, dpk, sp, _ = backend.sync(self._sweep(a, ray, False)).tolist()
        return self.finish(a, ray, phis, dpk, sp)

    def weigh(self, phis, dpk, sp, P, Kd) -> list:
        """A trial sweep's [ΣΦ, Σ(P(α) − P)·K d, ΣP] m-weighted (ΔA carries the interior weight): the
        deficit pixels' share off, from the trial buffers g(α), P(α) (backend values)."""
        L = self.lines
        i, c, Pt = L.idx, L.c, self.P_trial
        phis = phis - np.dot(c, _energy_at(self.law, self.g_trial[i]))
        dpk = dpk - np.dot(c * (Pt[i] - P[i]), Kd[i])
        if self.sum_p:
            sp = sp - np.dot(c, Pt[i])
        return [phis, dpk, sp]

    def finish(self, a, ray: Ray, phis, dpk, sp):
        """(E(α), E'(α), ΣΦ, ΣP) from a trial sweep's sums on this process (host floats)."""
        if self.red is not None:  # every rank's share of the grid
            phis, dpk, sp = self.red.sum([phis, dpk, sp])
        e = self.dA * (0.5 * ray.qw + a * ray.dw + 0.5 * a * a * ray.dKd + phis)
        de = ray.slope + self.dA * (a * ray.dKd - dpk)
        return e, de, phis, sp

    def search(self, alpha0: float, ray: Ray, E_ref: float = math.inf, first=None) -> Trial | None:
        """The accepted step from the trial α = ``alpha0`` (doubled until bracketed), or None.

        ``E_ref``: the caller's lowest energy so far; the approximate test is measured from
        min(E(0), E_ref), so round-off rises of E cannot add up over many accepted steps.  ``first``:
        :meth:`evaluate`'s answer at ``alpha0`` when the caller has swept it already (the trial
        buffers then hold g(α0), P(α0))."""
        E0, slope0, c1, c2 = ray.E0, ray.slope, self.c1, self.c2
        eps_E = _algebra.energy_slack(HOST, E0, "float64")
        E_lo = min(E0, E_ref)
        alpha = alpha0
        lo, de_lo = 0.0, slope0
        hi, de_hi, has_hi, has_de_hi = 0.0, 0.0, False, False   # no upper end yet
        best = None
        for _ in range(self.max_eval):
            if first is not None:
                (e, de, phis, sp), first = first, None
            else:
                e, de, phis, sp = self.evaluate(alpha, ray)
            if not np.isfinite(e):
                hi, has_hi, has_de_hi = alpha, True, False
            else:
                if _algebra.accepts(e, de, alpha, E0, E_lo, slope0, eps_E, c1, c2):
                    return Trial(alpha, e, phis, sp)
                if e <= E_lo + eps_E and (best is None or abs(de) < best[0]):
                    best = (abs(de), alpha)
                if _algebra.overshoots(e, de, alpha, E0, slope0, eps_E, c1):
                    hi, de_hi, has_hi = alpha, de, True
                    has_de_hi = _algebra.slope_usable(e, de, E0, eps_E)
                else:
                    lo, de_lo = alpha, de
            alpha = _algebra.next_trial(HOST, alpha, lo, de_lo, hi, de_hi, has_hi, has_de_hi)
        if best is not None:
            e, _, phis, sp = self.evaluate(best[1], ray)  # the buffers must hold the accepted point
            return Trial(best[1], e, phis, sp)
        return None


def _energy_at(law, g):
    """Φ(g) on a few pixels: a SafeLaw's without a host sync (tengsim.laws.safe), else the law's own."""
    fn = getattr(law, "energy_at", None)
    return law.energy(g) if fn is None else fn(g)
