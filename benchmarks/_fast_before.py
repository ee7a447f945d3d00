"""The fast solver as it was before the refactor of issue 13 (commit b76decc): a frozen benchmark
reference for ``refactor_ab.py`` and ``refactor_check.py``, not package code.

``FastSolver.solve`` here is the one long function with closures and ``_wolfe`` the 17-parameter line
search; the package's ``tengsim.solvers.FastSolver`` is the same arithmetic in named pieces.  It shares
``Problem``/``State``/``Equilibrium``, ``KMetricLBFGS`` and ``Sweeper`` with the package (unchanged in
behaviour by the refactor), so an A/B run compares only the solver's own code.
"""
from __future__ import annotations

import inspect
import math
import time
from dataclasses import dataclass

import numpy as np

from tengsim.solvers._lbfgs import KMetricLBFGS
from tengsim.solvers._sweep import Sweeper
from tengsim.errors import TengsimError
from tengsim.solvers import Equilibrium, Problem, State


def _finish(problem, state, P, r, energy, converged, it, n_conv, t0, msg):
    H = problem.g0 + state.w - 1.0
    res = float(np.max(np.abs(r)))
    return Equilibrium(state, H, P, res, converged, it, n_conv, float(energy), time.perf_counter() - t0, msg)


@dataclass(frozen=True)
class FastSolver:
    """L-BFGS on E(q) in the metric of the elastic kernel (K-preconditioned), Wolfe line search.

    Each iteration spends one convolution, K P(g) at the new state (plus one every ``resync``
    iterations to re-anchor w = K q): the direction's image K d is assembled from stored images
    (K s = Δw, K y = Δr, K G = r) by the compact L-BFGS form (tengsim.solvers._lbfgs), and the line search
    along d needs only element-wise work, since g(α) = g + α K d.  Converged when max|r| <= ``tol``.
    ``monitor(iteration, max|r|, energy)``, if given, is called every ``monitor_every`` iterations
    (progress on long solves).
    """

    tol: float = 1e-6
    max_iter: int = 3000
    memory: int = 10
    resync: int = 25
    name: str = "fast-before"
    monitor: object = None
    monitor_every: int = 100

    def __post_init__(self):
        if not self.tol > 0:
            raise TengsimError(f"tol must be > 0, got {self.tol!r}")
        if int(self.memory) < 1:
            raise TengsimError(f"memory must be >= 1, got {self.memory!r}")
        if int(self.monitor_every) < 1:
            raise TengsimError(f"monitor_every must be >= 1, got {self.monitor_every!r}")

    def solve(self, problem: Problem, start: State) -> Equilibrium:
        t0 = time.perf_counter()
        K, law, dA = problem.kernel, problem.law, problem.dA
        shape = problem.g0.shape
        g0 = np.ascontiguousarray(problem.g0, dtype=float).ravel()
        n = g0.size
        q = np.array(start.q, dtype=float).ravel()
        w = np.array(start.w, dtype=float).ravel()
        # every per-iteration array is preallocated, and the element-wise work runs in fused,
        # cache-blocked (on large grids threaded) sweeps: the loop is memory-bound, not FFT-bound
        g, gt, P, Pt, d, Kd, r, rn, G, Gn, y, ky = (np.empty(n) for _ in range(12))
        sw = Sweeper(n)
        buf = sw.buf
        mem = KMetricLBFGS(self.memory, n, dA)
        B, KB = mem.B, mem.KB

        cP = np.empty(n)
        takes_out = _takes_out(K.apply)

        def conv(x, out=cP):
            if takes_out:
                K.apply(x.reshape(shape), out=out.reshape(shape))
            else:  # a kernel of the caller's own without ``out=``
                out[:] = K.apply(x.reshape(shape)).ravel()
            return out

        # A periodic kernel has K(0) = 0: the mean of q is a gauge (E and w do not see it), and the
        # K metric cannot control it.  Left alone, a near-flat line search (near round-off) can push a
        # huge mean into q, which then spoils q·w and G in floating point and throws the iterate
        # away from the minimum it had reached.  So the mean of q is held fixed and G = q − P is used
        # without its mean (the K-metric gradient is the same); ΣP comes with the law's sweeps and
        # Σd with the direction's, so this costs no extra pass.
        proj = bool(getattr(K, "periodic", False))

        def law_sweep(gg, PP):
            """ΣΦ(gg) and ΣP (periodic kernels only, else 0), with P(gg) written into PP."""
            def fn(sl, m, sc, acc):
                acc[0] += law.energy_pressure(gg[sl], PP[sl], (buf(sc, "a", m), buf(sc, "b", m)))
                if proj:
                    acc[1] += float(PP[sl].sum())
            return sw.sum(fn, [0.0, 0.0])

        np.add(g0, w, out=g)
        phis, sum_p = law_sweep(g, P)
        np.subtract(w, conv(P), out=r)
        n_conv = 1
        mean_q = float(q.mean())
        np.subtract(q, P, out=G)
        if proj:
            G -= mean_q - sum_p / n
        qw = float(np.vdot(q, w))
        E = dA * (0.5 * qw + phis)
        rmax = max(float(r.max()), -float(r.min()))
        E_best = E

        def done(ok, it, msg):
            st = State(q.reshape(shape), w.reshape(shape))
            return _finish(problem, st, P.reshape(shape).copy(), r, E, ok, it, n_conv, t0, msg)

        def direction(gamma, c):
            """d = −H G, K d = −K H G, and the products d·w, d·K d, d·r (and Σd), in one sweep.

            The slope E'(0) = ΔA (d·w − P·K d) is taken as ΔA d·r (equal, since r = w − K P and K is
            symmetric): near convergence d·w and P·K d nearly cancel, and their difference is noise."""
            k2 = 0 if c is None else c.size

            def fn(sl, m, sc, acc):
                ds, kds = d[sl], Kd[sl]
                np.multiply(G[sl], -gamma, out=ds)
                np.multiply(r[sl], -gamma, out=kds)
                if k2:
                    h = buf(sc, "h", m)
                    np.matmul(c, B[:k2, sl], out=h)
                    ds -= h
                    np.matmul(c, KB[:k2, sl], out=h)
                    kds -= h
                acc[0] += float(np.vdot(ds, w[sl]))
                acc[1] += float(np.vdot(ds, kds))
                acc[2] += float(np.vdot(ds, r[sl]))
                if proj:
                    acc[3] += float(ds.sum())
            return sw.sum(fn, [0.0, 0.0, 0.0, 0.0])

        for it in range(self.max_iter + 1):
            if not math.isfinite(rmax):
                return done(False, it, "non-finite residual")
            if rmax <= self.tol:
                return done(True, it, "converged")
            if it == self.max_iter:
                break
            if self.monitor is not None and it % self.monitor_every == 0:
                self.monitor(it, rmax, E)
            a0, a1, dr, sum_d = direction(*mem.coefficients())
            if not dr < 0:  # not a descent direction: restart from the preconditioned gradient
                mem.reset()
                a0, a1, dr, sum_d = direction(*mem.coefficients())
            slope = dA * dr
            # E may rise by round-off in an accepted step (approximate Wolfe); measured from the
            # lowest E so far, such rises cannot add up over many steps near convergence
            E_best = min(E_best, E)
            alpha, E_new, phis_t, sum_pt = _wolfe(law, g, P, Kd, gt, Pt, sw, qw, a0, a1, E, slope, dA,
                                                  first=mem.empty, sum_p=proj, E_ref=E_best)
            if alpha is None:
                return done(False, it, "line search failed")
            resynced = (it + 1) % self.resync == 0
            if resynced:
                # the images K d are assembled, not convolved: round-off lets w drift from K q;
                # re-anchor w = K q (one extra convolution) so the metric stays exact
                _axpy(d, q, alpha, gt)
                w_exact = conv(q)
                n_conv += 1
                # the correction (w = K q exactly, minus the assembled step α K d) goes to w and r
                # only: the stored pair keeps the assembled images K s = α K d, K y = K s − Δ(K P),
                # as every other pair does, so the drift is not fed back into later directions
                corr = np.subtract(w_exact, w, out=gt)
                _axpy(Kd, corr, -alpha, Pt)
                w[:] = w_exact
                np.add(g0, w, out=g)
                phis, sum_p = law_sweep(g, P)
                qw = float(np.vdot(q, w))
                E_best = math.inf  # E is recomputed exactly: the bookkeeping restarts from it
            else:
                g, gt = gt, g
                P, Pt = Pt, P
                phis, sum_p = phis_t, sum_pt
                qw += alpha * (2.0 * a0 + alpha * a1)
            E = dA * (0.5 * qw + phis)
            mean_q += alpha * sum_d / n
            mu = mean_q - sum_p / n if proj else 0.0
            conv(P)
            n_conv += 1
            k2 = 2 * len(mem.order)
            step = not resynced

            def fn(sl, m, sc, acc):
                # q ← q + α d, w ← w + α K d; r_new = w − K P; K y = Δr; G_new = q − P; y = ΔG
                ds = d[sl]
                if step:
                    tmp = buf(sc, "t", m)
                    qs, ws = q[sl], w[sl]
                    np.multiply(ds, alpha, out=tmp)
                    qs += tmp
                    np.multiply(Kd[sl], alpha, out=tmp)
                    ws += tmp
                rns, kys, Gns, ys = rn[sl], ky[sl], Gn[sl], y[sl]
                np.subtract(w[sl], cP[sl], out=rns)
                np.subtract(rns, r[sl], out=kys)
                if resynced:
                    kys -= corr[sl]
                np.subtract(q[sl], P[sl], out=Gns)
                if proj:
                    Gns -= mu
                np.subtract(Gns, G[sl], out=ys)
                acc[0] += float(np.vdot(ds, kys))
                acc[1] += float(np.vdot(ys, kys))
                acc[2] += float(np.vdot(ds, rns))
                acc[3] += float(np.vdot(ys, rns))
                acc[4] = max(acc[4], float(rns.max()), -float(rns.min()))
                if k2:
                    acc[5] = acc[5] + B[:k2, sl] @ kys
            accs = sw.run(fn, [0.0, 0.0, 0.0, 0.0, 0.0, 0.0])
            if len(accs) == 1:
                dky, yky, drn, yrn, rmax, x = accs[0]
            else:
                dky, yky, drn, yrn, _, x = (sum(a[j] for a in accs) for j in range(6))
                rmax = max(a[4] for a in accs)
            sy = dA * alpha * dky
            yy = dA * yky
            sks = dA * alpha * alpha * abs(a1)
            store = sy > 1e-14 * max(sks, 1e-300) and yy > 0
            slot = mem.update(alpha, dA * x if k2 else None, sy, yy, dA * drn, dA * yrn, store)
            if slot is not None:
                def put(sl, m, sc, acc):
                    np.multiply(d[sl], alpha, out=B[2 * slot, sl])
                    B[2 * slot + 1, sl] = y[sl]
                    np.multiply(Kd[sl], alpha, out=KB[2 * slot, sl])
                    KB[2 * slot + 1, sl] = ky[sl]
                sw.run(put, ())
            r, rn = rn, r
            G, Gn = Gn, G
            if resynced:
                mem.refresh(r)
        return done(False, self.max_iter, f"not converged in {self.max_iter} iterations")


def _takes_out(fn) -> bool:
    """Does ``fn`` accept an ``out=`` keyword (the package's kernels do)?"""
    try:
        params = inspect.signature(fn).parameters.values()
    except (TypeError, ValueError):
        return False
    return any(p.name == "out" or p.kind is p.VAR_KEYWORD for p in params)


def _axpy(x, y, a, tmp):
    """y ← y + a x in place, through the scratch array ``tmp`` (no allocation).

    (Not BLAS daxpy: OpenBLAS threads it, and on a busy 2-core machine that cost ~1000× on small arrays.)
    """
    np.multiply(x, a, out=tmp)
    np.add(y, tmp, out=y)


def _wolfe(law, g, P, Kd, gt, Pt, sw, qw, a0, a1, E0, slope0, dA, first, c1=1e-4, c2=0.9, max_eval=40,
           sum_p=False, E_ref=None):
    """Line search along d; element-wise only (no convolution).

    E(α) = dA[½ q·w + α d·w + ½ α² d·K d + Σ Φ(g + α K d)],
    E'(α) = E'(0) + dA[α d·K d − (P(g + α K d) − P(g))·K d]   (qw = q·w, a0 = d·w, a1 = d·K d;
    the pressure change is summed point by point, so E' keeps its precision near convergence).
    Accepts the strong Wolfe conditions, or near round-off the approximate Wolfe conditions of
    Hager & Zhang (2005): E(α) <= E_ref + 1e-11|E(0)| and 0.9 E'(0) <= E'(α) <= −0.8 E'(0), with
    E_ref = min(E(0), ``E_ref``) (the caller's lowest energy, so round-off rises cannot accumulate).
    The bracket is narrowed by safeguarded secant steps on E'.  On return the buffers gt, Pt hold
    the gap and pressure at the accepted α; returns (α, E(α), ΣΦ, ΣP) (ΣP only if ``sum_p``, else 0)
    or (None, None, None, None).
    """
    eps_E = 1e-11 * max(1.0, abs(E0))
    E_lo = E0 if E_ref is None else min(E0, E_ref)

    buf = sw.buf

    def f(a):
        def fn(sl, m, sc, acc):
            # block by block (a sweep): the gap, the law's scratch and the pressure stay in cache
            gb, pb, kb = gt[sl], Pt[sl], Kd[sl]
            np.multiply(kb, a, out=gb)
            np.add(gb, g[sl], out=gb)
            acc[0] += law.energy_pressure(gb, pb, (buf(sc, "a", m), buf(sc, "b", m)))
            dp = buf(sc, "c", m)
            np.subtract(pb, P[sl], out=dp)
            acc[1] += float(np.vdot(dp, kb))
            if sum_p:
                acc[2] += float(pb.sum())
        phis, dpk, sp = sw.sum(fn, [0.0, 0.0, 0.0])
        e = dA * (0.5 * qw + a * a0 + 0.5 * a * a * a1 + phis)
        de = slope0 + dA * (a * a1 - dpk)
        return e, de, phis, sp

    alpha = 1.0
    if first:  # scale the first trial step so that the gap moves by at most 0.25 ε
        m = max(float(Kd.max()), -float(Kd.min()))
        if m > 0.25:
            alpha = 0.25 / m
    lo, de_lo = 0.0, slope0
    hi, de_hi = None, None
    best = None
    for _ in range(max_eval):
        e, de, phis, sp = f(alpha)
        if not np.isfinite(e):
            hi, de_hi = alpha, None
        else:
            wolfe = e <= E0 + c1 * alpha * slope0 and abs(de) <= -c2 * slope0
            approx = e <= E_lo + eps_E and c2 * slope0 <= de <= -0.8 * slope0
            if wolfe or approx:
                return alpha, e, phis, sp
            if e <= E_lo + eps_E and (best is None or abs(de) < best[0]):
                best = (abs(de), alpha)
            if e > E0 + c1 * alpha * slope0 + eps_E or de > 0:
                hi, de_hi = alpha, (de if e <= E0 + eps_E or de > 0 else None)
            else:
                lo, de_lo = alpha, de
        if hi is None:
            alpha = 2.0 * alpha
            continue
        width = hi - lo
        if de_hi is not None and de_hi > de_lo:
            cand = lo - de_lo * width / (de_hi - de_lo)
        else:
            cand = lo + 0.5 * width
        alpha = min(max(cand, lo + 0.1 * width), hi - 0.1 * width)
    if best is not None:
        e, _, phis, sp = f(best[1])  # the buffers must hold the accepted point
        return best[1], e, phis, sp
    return None, None, None, None
