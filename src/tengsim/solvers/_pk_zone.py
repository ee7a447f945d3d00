"""The Maugis–Dugdale cohesive zone solved in the same loop as the contact of the ``pk`` solver (after Rey,
Anciaux & Molinari, Comput. Mech. 60 (2017) 69–81: the zone's tractions are set from the current gap at every
iteration of the contact's constrained solve, not by an outer fixed point around whole contact solves).  The
solver's ``zone='inner'`` (tengsim.solvers.pk.PKSolver).

The unknown is the total pressure p (W/ε) and a contact mask.  Every pixel is, at each iteration, one of

* contact: the gap above the wall u = 0, p >= −σ0 free (p + σ0 the contact pressure of the hard-wall problem);
* off the contact: the law's tension at its gap, p = p_a(u) (−σ0 in the zone, 0 beyond it, the smoothstep
  between where the zone has a ramp: the law's hard-wall limit's traction, tengsim.laws.cohesive).

One iteration: u = h + K p (one convolution); on the contact Polonsky & Keer's step along the preconditioned
gradient t = P_S M⁻¹ P_S u (tengsim.solvers._pk_core's |q| preconditioner M⁻¹ ≈ K⁻¹: one FFT pair), a fixed
fraction ``STEP`` of it (no K t: a kernel without the preconditioner takes the exact step along u, one
convolution more); contact pixels pulled below −σ0 leave (p = −σ0: the zone at the wall), overlapping pixels
off the contact enter, every other pixel off the contact takes its law's tension at the gap; then the new
iterate is Anderson-mixed with the last ``anderson`` ones (the mixing restarted whenever a pixel enters or
leaves the contact or crosses the zone's middle).  The conjugate directions of the hard-wall CG are not kept:
the zone moves the problem at every iteration, and kept directions made the ramp's collective modes grow
(as did a per-pixel Newton step of the zone); the mixing is what accelerates the loop, over the contact and
the zone together.  Like the outer loop's mixing it is not a descent: it finds an equilibrium (below), whose
stability it does not check.

Converged when every pixel's gap is within ``tol`` (ε) of the gaps its pressure allows: 0 on the contact,
[0, h0 − ramp/2] at −σ0, [h0 + ramp/2, ∞) at 0, the smoothstep's inverse between (:func:`zone_residual`: the
hard-wall residual with the law's graph in place of the wall's).  The set update is not the gradient of a
convex problem and the mixing can stagnate near a jump: the loop stops after ``max_iter`` iterations or
``stall`` without a new lowest residual, unconverged, and the caller falls back (unmixed, then the outer
fixed point) and says so.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tengsim import backend
from tengsim.solvers.mixing import mixing_coefficients

#: the fraction of the preconditioned gradient a contact step takes (M⁻¹ ≈ K⁻¹: 1 would be Newton's step in
#: full contact; 0.4–0.8 alike on the Maugis–Dugdale path of benchmarks/md_path_pk.py at dx 0.2; 0.7 cycled on
#: the contact's edge at dx 0.05 from a cold start)
STEP = 0.5


@dataclass
class ZoneResult:
    """What :func:`zone_inner` returns: the total pressure ``p``, ``Kp`` = K p, the gap above the wall ``u``, the
    contact mask, iterations, the residual (ε), whether it met ``tol``, and the set changes it made."""

    p: np.ndarray
    Kp: np.ndarray
    u: np.ndarray
    contact: np.ndarray
    iterations: int
    residual: float
    converged: bool
    changes: int


def zone_residual(zone, u, p, contact, work) -> float:
    """The largest distance (ε) of a pixel's gap from the gaps its pressure allows (module doc); ``zone`` a
    plateau (tengsim.laws.cohesive.CohesiveLimit: its tension, length, ramp and step_gap)."""
    s0, h0, r = zone.tension, zone.length, zone.ramp
    lo, hi = h0 - 0.5 * r, h0 + 0.5 * r
    full, none = p <= -s0, p >= 0.0
    np.abs(u, out=work)                                          # the contact: u = 0
    off = ~contact
    m = off & full                                               # the zone at full tension: 0 <= u <= lo
    work[m] = np.maximum(np.maximum(-u[m], u[m] - lo), 0.0)
    m = off & none                                               # beyond the zone: u >= hi
    work[m] = np.maximum(hi - u[m], 0.0)
    m = off & ~full & ~none                                      # the ramp: u = its inverse at p
    if m.any():
        work[m] = np.abs(u[m] - zone.step_gap(p[m], np))
    return float(work.max()) if work.size else 0.0


class _Mix:
    """Anderson mixing (type II, memory ``m``) of the iterates p of the whole solve (contact and zone): ``step(x,
    gx)`` turns gx, the map's image of x, into the mixed next iterate x + f − (ΔX + ΔF) γ, f = gx − x, γ the
    least-squares fit of f by the stored differences (kept as m columns, their Gram matrix updated a column at a
    time)."""

    def __init__(self, n, m):
        self.m = m
        self.X, self.F = backend.empty((n, m)), backend.empty((n, m))
        self.A = backend.empty((m, m))
        self.x_old, self.f_old = backend.empty(n), backend.empty(n)
        self.reset()

    def reset(self):
        self.k, self.have_old = 0, False

    def step(self, x, gx):
        f = gx - x
        m, k = self.m, self.k
        if self.have_old:
            j = k % m
            np.subtract(x, self.x_old, out=self.X[:, j])
            np.subtract(f, self.f_old, out=self.F[:, j])
            self.k = k = k + 1
            cols = min(k, m)
            row = self.F[:, :cols].T @ self.F[:, j]
            self.A[j, :cols] = row
            self.A[:cols, j] = row
        np.copyto(self.x_old, x)
        np.copyto(self.f_old, f)
        self.have_old = True
        cols = min(k, m)
        if cols == 0:
            return
        A = self.A[:cols, :cols]
        F = self.F[:, :cols]
        gamma = mixing_coefficients(A, F.T @ f)
        np.add(x, f, out=gx)
        gx -= self.X[:, :cols] @ gamma
        gx -= F @ gamma


def zone_inner(conv, h, zone, p, contact, tol: float, max_iter: int, monitor=None, precond=None,
            anderson: int = 0, stall: int = 100) -> ZoneResult:
    """The cohesive zone in the contact's loop (module doc), displacement control, from the total
    pressure ``p`` and ``contact`` mask (both the solve's own: overwritten).  ``h``: the gap above the wall at
    p = 0 (flat, ε); ``zone``: a plateau's hard-wall limit (tengsim.laws.cohesive; sharp or with a ramp);
    ``anderson``: the memory of the iterates' mixing (0: none); ``stall``: iterations without a new lowest
    residual after which it stops unconverged (a set update cycling, a mixing stagnating)."""
    n = h.size
    s0 = zone.tension
    Kp, u, r = backend.empty(n), backend.empty(n), backend.empty(n)
    work, target, p_old = backend.empty(n), backend.empty(n), backend.empty(n)
    t = backend.empty(n) if precond is not None else work
    beyond = backend.empty(n, bool)
    res, changes, best, it_best, it = math.inf, 0, math.inf, 0, 0
    mix = _Mix(n, anderson) if anderson else None
    for it in range(max_iter + 1):
        conv(p, Kp)
        np.add(h, Kp, out=u)
        res = zone_residual(zone, u, p, contact, work)
        if monitor is not None:
            monitor(it, res)
        if res <= tol or it == max_iter:
            break
        if res < best:
            best, it_best = res, it
        elif it - it_best > stall:                               # no new lowest residual
            break
        np.copyto(p_old, p)
        changed = False
        if contact.any():
            np.multiply(u, contact, out=work)                    # the gradient on the contact
            if precond is not None:                              # the direction: P_S M⁻¹ P_S u
                precond(work, t)
                t *= contact
            if precond is not None:
                p -= STEP * t                                    # t is 0 off the contact
            else:                                                # the exact step along u (one convolution)
                conv(t, r)
                rt = float(np.dot(r, t))
                p -= (float(np.dot(work, t)) / rt if rt > 0 else 0.0) * t
            left = contact & (p < -s0)
            if left.any():                                       # pulled below the zone's tension: leave
                p[left] = -s0
                contact &= ~left
                changes += int(np.count_nonzero(left))
                changed = True
        off = ~contact
        enter = off & (u < 0.0)                                  # overlaps enter (their tension: −σ0)
        if enter.any():
            contact |= enter
            off &= ~enter
            p[enter] = -s0
            changes += int(np.count_nonzero(enter))
            changed = True
        # every other pixel off the contact: to its law's tension at its gap
        np.greater(p, -0.5 * s0, out=beyond)                     # which side of the zone's end it was on
        np.maximum(u, 0.0, out=work)
        target[...] = zone.traction(work, np)
        target -= p
        target *= off
        p += target
        flips = int(np.count_nonzero(((p > -0.5 * s0) != beyond) & off))
        if flips:                                                # a pixel crossed the zone's middle
            changes += flips
            changed = True
        if mix is not None:
            if changed:
                mix.reset()
            mix.step(p_old, p)                                   # p <- the mixed iterate, within the bounds
            np.maximum(p, -s0, out=p)
            np.minimum(p, 0.0, out=p, where=~contact)
    return ZoneResult(p, Kp, u, contact, it, res, bool(res <= tol), changes)
