"""The constrained conjugate gradient of Polonsky & Keer (1999) on the contact pressures: the hard-wall
problem behind the ``pk`` solver (tengsim.solvers.pk).

Given the gap above the wall at zero contact pressure, ``h`` (ε; h = g0 − 1 plus the displacement of
any fixed traction), find the contact pressure p (W/ε) with

    u = h + K p (+ c),   p >= 0,   u >= 0,   p u = 0,

u the gap above the wall.  Under displacement control c = 0: this is the bound-constrained quadratic
program min ½ p·K p + h·p, p >= 0, whose gradient is u.  Under load control the mean of p is given
and c (the rigid approach's correction, a Lagrange multiplier) makes the mean of u over the contact
set zero (Polonsky & Keer's original form).

One iteration (Polonsky & Keer 1999, Eqs. 7–17; as in Tamaas and ASPHER): u = h + K p on the contact
set S = {p > 0} (one convolution), the conjugate direction t = u + δ (G/G_old) t_old on S, r = K t
(the second convolution), the exact step τ = u·t / r·t along −t, the projection p >= 0, and the
pixels out of contact that overlap the wall (u < 0, p = 0) entering with p = −τ u (then δ = 0: the
conjugacy restarts).  So two convolutions (FFT pairs) an iteration, plus one to start; with the |q|
preconditioner (:class:`Preconditioner`: the direction is z = P_S M⁻¹ P_S u, the overlap step scaled by M⁻¹'s
diagonal, the conjugacy restarted whenever the set shrinks) one FFT pair more.  Converged when
max |u| over S and the largest overlap max(−u, 0) off S are both <= ``tol`` (ε): the residual of the
hard-wall problem in the gap, the unit of Eq. (9)'s.

Every array goes through the backend seam (tengsim.backend); the only FFTs are the kernel's.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tengsim import backend
from tengsim.backend import fft as _bf
from tengsim.solvers._kernelcall import takes_out


#: iterations without a new lowest residual after which a preconditioned solve goes on without its
#: preconditioner (from its best pressure): the |q| preconditioner's steps can cycle on a contact set that
#: a displacement-controlled cold start has yet to find
STALL = 40
#: steps after which K p, carried by the CG's recurrence K p ← K p − τ K t while no pixel is clipped or enters,
#: is convolved afresh (as it is before any residual is judged)
RESYNC = 20


@dataclass
class CoreResult:
    """What :func:`constrained_cg` returns: the contact pressure ``p``, ``Kp`` = K p, the gap above the
    wall ``u`` (c included), the load-control correction ``c`` (ε; 0 under displacement control),
    iterations, convolutions, the residual (ε) and whether it met ``tol``."""

    p: np.ndarray
    Kp: np.ndarray
    u: np.ndarray
    c: float
    iterations: int
    n_conv: int
    residual: float
    converged: bool


class Convolution:
    """K x of a kernel into a buffer of its own (the solver's one convolution call)."""

    def __init__(self, kernel, shape):
        self.apply, self.shape = kernel.apply, tuple(shape)
        self.out = takes_out(kernel.apply)
        self.count = 0

    def __call__(self, x, out):
        self.count += 1
        if self.out:
            self.apply(x.reshape(self.shape), out=out.reshape(self.shape))
        else:
            out[:] = np.asarray(self.apply(x.reshape(self.shape))).ravel()
        return out


class Preconditioner:
    """z = M⁻¹ x with M⁻¹ the inverse of the half-space's periodic compliance on the cell grid,
    |q|/(2κ) (the mean mode: the smallest nonzero one, so M⁻¹ stays positive definite): one FFT pair.
    For any kernel with a ``coupling`` κ and a ``grid`` (the free cell and the films too: there it is
    an approximation, which a preconditioner may be)."""

    def __init__(self, kernel, shape):
        g = kernel.grid
        qx = 2 * np.pi * _bf.fftfreq(g.nx, d=g.dx)
        qy = 2 * np.pi * _bf.rfftfreq(g.ny, d=g.dy)
        q = np.hypot(*np.meshgrid(qx, qy, indexing="ij"))
        q[0, 0] = min(2 * np.pi / (g.nx * g.dx), 2 * np.pi / (g.ny * g.dy))
        self.mult = q / (2.0 * float(kernel.coupling))
        w = 2.0 + backend.zeros(self.mult.shape[1])  # the rfft layout's columns, each standing for two
        w[0] = 1.0
        if g.ny % 2 == 0:
            w[-1] = 1.0
        #: M⁻¹'s diagonal (its value at zero offset): the step a pixel's own gap takes through M⁻¹
        self.diag = float((self.mult * w).sum()) / (g.nx * g.ny)
        self.shape = tuple(shape)
        self.threads = _bf.threads(self.shape)
        self.direct = _bf.has_direct()
        self.cb = backend.empty(self.mult.shape, complex) if self.direct else None

    def __call__(self, x, out):
        x2, o2 = x.reshape(self.shape), out.reshape(self.shape)
        if not self.direct:
            o2[...] = _bf.irfft2(_bf.rfft2(x2) * self.mult, self.shape)
            return out
        cb, t = self.cb, self.threads
        _bf.r2c(x2, 1, cb, t)
        _bf.c2c(cb, 0, True, 0, cb, t)
        cb *= self.mult
        _bf.c2c(cb, 0, False, 2, cb, t)
        _bf.c2r(cb, 1, self.shape[1], 2, o2, t)
        return out


def preconditioner(kernel, shape):
    """The :class:`Preconditioner` of ``kernel``, or None for a kernel without ``coupling`` and ``grid``."""
    if getattr(kernel, "coupling", None) is None or getattr(kernel, "grid", None) is None:
        return None
    if tuple(kernel.grid.shape) != tuple(shape):
        return None
    return Preconditioner(kernel, shape)


def _residual(u, S, work):
    """max |u| on S and max(−u, 0) off S: the gap residual (ε)."""
    np.abs(u, out=work)
    np.negative(u, out=work, where=~S)
    return max(float(work.max()), 0.0) if work.size else 0.0


def _gap(h, Kp, p, u, load, c, work):
    """u = h + K p (+ c under load control) into ``u``; (the direction's set S, its size, c, the residual)."""
    np.add(h, Kp, out=u)
    S = p > 0
    nS = int(np.count_nonzero(S))
    if load is not None and nS:
        c = -float(np.sum(u, where=S)) / nS           # the rigid approach's correction
        u += c
    res = _residual(u, S, work)
    if nS == 0:
        S = u < 0                                     # nothing in contact yet: the overlap enters
        nS = int(np.count_nonzero(S))
    return S, nS, c, res


def constrained_cg(conv: Convolution, h, p, tol: float, max_iter: int, load: float | None = None,
                   monitor=None, precond=None, Kp0=None) -> CoreResult:
    """Polonsky–Keer's constrained CG (module doc) from the start pressure ``p`` (>= 0, a flat array; the
    solve's own: overwritten).  ``Kp0``: K p of that start if known (displacement control: saves the first
    convolution).  ``h``: the gap above the wall at p = 0 (flat, ε).  ``load``: the mean of
    p under load control (W/ε; None: displacement control).  ``monitor(it, residual)``: progress."""
    n = h.size
    n0 = conv.count
    Kp, u, t, r = backend.empty(n), backend.empty(n), backend.zeros(n), backend.empty(n)
    work = backend.empty(n)
    z = backend.empty(n) if precond is not None else work
    np.maximum(p, 0.0, out=p)
    if load is not None and not float(p.sum()) > 0:
        p[:] = load                                   # the cold start under load: a uniform pressure
    elif load is not None:
        p *= load / float(p.mean())
    delta, G_old, c = 0.0, 1.0, 0.0
    res = best = math.inf
    p_best, it_best, stalled = (backend.empty(n) if precond is not None else None), 0, False
    inc = 0                                           # steps since K p was last convolved (0: K p exact)
    for it in range(max_iter + 1):
        if it == 0 and Kp0 is not None and load is None:
            Kp[:] = Kp0
        elif inc == 0:
            conv(p, Kp)
        S, nS, c, res = _gap(h, Kp, p, u, load, c, work)
        if inc and (res <= tol or nS == 0 or it == max_iter or inc >= RESYNC):
            conv(p, Kp)                               # judged on an exact K p only
            inc = 0
            S, nS, c, res = _gap(h, Kp, p, u, load, c, work)
        if monitor is not None:
            monitor(it, res)
        if res <= tol or nS == 0 or it == max_iter:
            break
        if p_best is not None:                        # the preconditioned CG's safeguard (below)
            if res < best:
                best, it_best = res, it
                p_best[:] = p
            elif it - it_best > STALL:
                stalled = True
                break
        np.multiply(u, S, out=work)                   # the gradient on S
        if precond is not None:                       # z = P_S M⁻¹ P_S u (one FFT pair)
            precond(work, z)
            z *= S
            if load is not None:
                z -= float(np.sum(z, where=S)) / nS
                z *= S
        G = float(np.dot(work, z))
        t *= delta * G / G_old
        t *= S
        t += z
        G_old = G
        conv(t, r)
        if load is not None:
            r -= float(np.sum(r, where=S)) / nS
        rt = float(np.dot(r, t))
        if not rt > 0:
            break
        tau = float(np.dot(work, t)) / rt
        p -= tau * t
        exact = load is None and not bool((p < 0).any())   # no pixel clipped: K p moved by −τ K t exactly
        np.maximum(p, 0.0, out=p)
        left = nS - int(np.count_nonzero(p)) if precond is not None else 0   # pixels the step released
        np.less(u, 0.0, out=S)                        # overlaps out of contact enter (S reused)
        S &= p == 0
        if S.any():
            np.multiply(u, S, out=work)
            p -= (tau if precond is None else tau * precond.diag) * work
            delta, exact = 0.0, False
        else:                                         # preconditioned: restart where the set shrank too
            delta = 0.0 if left > 0 else 1.0
        if load is not None:
            m = float(p.mean())
            if not m > 0:
                break
            p *= load / m
        if exact:                                     # K p by the CG's own recurrence: no convolution
            Kp -= tau * r
            inc += 1
        else:
            inc = 0
    if stalled:  # no progress in STALL iterations: on from the best pressure without the preconditioner
        p[:] = p_best
        rest = constrained_cg(conv, h, p, tol, max_iter - it, load, monitor, None)
        rest.iterations += it
        rest.n_conv = conv.count - n0
        return rest
    return CoreResult(p, Kp, u, c, it, conv.count - n0, res, bool(res <= tol))
