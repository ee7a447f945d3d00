"""One descent of the fast solver (:class:`tengsim.solvers.fast.FastSolver`): the iterate, its residual and the
L-BFGS memory, and the fused sweeps that update them."""
from __future__ import annotations

import functools
import math
from typing import NamedTuple

import numpy as np

from tengsim import backend
from tengsim.laws.safe import safe
from tengsim.solvers import _algebra
from tengsim.solvers._algebra import HOST
from tengsim.solvers._kernelcall import takes_out
from tengsim.solvers._linesearch import Ray, Trial, WolfeLineSearch, _energy_at
from tengsim.solvers._reduce import for_kernel
from tengsim.solvers.types import Equilibrium, Problem, State, finish


class _Due(NamedTuple):
    """A residual whose numbers have not come to the host yet (they ride on the next sweep's sync):
    max r and min r, and the new pair's d·K y and y·K y (None at the start: no pair) with the step α,
    ΔA α² |d·K d| and whether the step re-anchored (the curvature test, :meth:`_Descent._settle`)."""

    hi: object
    lo: object
    dky: object = None
    yky: object = None
    alpha: float = 0.0
    sks: float = 0.0
    resync: bool = False

    def values(self) -> list:
        return [self.hi, self.lo] if self.dky is None else [self.hi, self.lo, self.dky, self.yky]


class _Descent:
    """One FastSolver solve: the iterate and what is carried with it, and its steps.

    Carried: q and w = K q (the solve's own arrays, returned in the State); g = g0 + w, P = P(g),
    the residual r = w − K P, the K-metric gradient G = q − P, its next values rn, Gn, and the
    scalars E, q·w, ΣΦ, ΣP, the mean of q, max|r| and the lowest E so far.  All other arrays are
    the workspace's.

    A periodic kernel has K(0) = 0: the mean of q is a gauge (E and w do not see it), and the K
    metric cannot control it.  Left alone, a near-flat line search (near round-off) can push a huge
    mean into q, which then spoils q·w and G in floating point and throws the iterate away from the
    minimum it had reached.  So the mean of q is held fixed and G = q − P is used without its mean
    (the K-metric gradient is the same); ΣP comes with the law's sweeps and Σd with the direction's,
    so this costs no extra pass.

    A weighted problem (``lines``, tengsim.solvers._weights): the sweeps' plain sums are corrected on
    the few pixels whose weight differs from the interior one, and ΔA carries the interior weight.

    The new residual's numbers are due (:class:`_Due`) until the next direction's sweep brings them
    over with its own (:meth:`_direction`): max|r| is known one sweep late, and the L-BFGS pair is
    stored unconfirmed and confirmed or taken back then (:meth:`_settle`).
    """

    def __init__(self, problem: Problem, start: State, ws, lines=None):
        K = problem.kernel
        self.problem, self.law, self.dA = problem, safe(problem.law), problem.dA  # the law, safe below g_safe
        self.lines = lines
        if lines is not None:
            self.dA = problem.dA * lines.scale
        self.shape = problem.g0.shape
        self.g0 = backend.xp.ascontiguousarray(problem.g0, dtype=float).ravel()
        self.n = self.g0.size
        self.nw = self.n if lines is None else lines.total  # the (weighted) pixel count
        self.red = red = for_kernel(K)  # None, or the sums and maxima over the ranks of a distributed solve
        if red is not None:
            self.nw = red.sum([float(self.n)])[0]
        self.q = backend.xp.array(start.q, dtype=float).ravel()
        self.w = backend.xp.array(start.w, dtype=float).ravel()
        self.sw, self.mem, self.cP = ws.sweeper, ws.memory, ws.cP
        self.g, self.P, self.d, self.Kd = ws.g, ws.P, ws.d, ws.Kd
        self.r, self.rn, self.G, self.Gn, self.y, self.ky = ws.r, ws.rn, ws.G, ws.Gn, ws.y, ws.ky
        # a film's periodic kernel has a finite mean compliance, K(0) > 0: it says pinned_mean = False
        self.proj = bool(getattr(K, "pinned_mean", getattr(K, "periodic", False)))
        self.unchecked = hasattr(self.law, "energy_pressure_unchecked")  # a SafeLaw (tengsim.laws.safe)
        self.search = WolfeLineSearch(self.law, ws.sweeper, self.dA, ws.gt, ws.Pt, sum_p=self.proj,
                                      lines=lines, red=red)
        self._apply, self._takes_out = K.apply, takes_out(K.apply)
        # the start: g, P, ΣΦ, r (one convolution), G, E
        np.add(self.g0, self.w, out=self.g)
        self.phis, self.sum_p = self.law_sweep()
        np.subtract(self.w, self.convolve(self.P), out=self.r)
        self.n_conv = 1
        if red is not None:
            sq = self.q.sum()
        elif lines is None:
            sq = self.q.mean()
        else:
            sq = self.q.sum() - lines.sum(self.q)
        sq, qw = backend.sync((sq, self._dot_dev(self.q, self.w))).tolist()  # one sync: mean q and q·w
        if red is not None:
            self.mean_q, self.qw = red.sum([sq])[0] / self.nw, red.sum([qw])[0]
        else:
            self.mean_q, self.qw = (sq if lines is None else sq / self.nw), qw
        np.subtract(self.q, self.P, out=self.G)
        if self.proj:
            self.G -= self.mean_q - self.sum_p / self.nw
        self.E = self.dA * (0.5 * self.qw + self.phis)
        self.rmax = math.inf
        self._due = _Due(self.r.max(), self.r.min())  # max|r|: with the first direction's sums
        if red is not None:  # a distributed solve reduces max|r| over the ranks at once
            self._settle(backend.sync(self._due.values()).tolist())
        self.E_best = self.E
        self.sum_d = 0.0
        self.corr = None
        self.first = None  # the first trial's sums, swept with the direction (:meth:`_direction`)

    # ---- the pieces ---------------------------------------------------------------------------
    def _dot_dev(self, a, b):
        """a·b, m-weighted (in units of the interior weight) for a weighted problem: a backend scalar
        (this process's share in a distributed solve)."""
        v = np.vdot(a, b)
        return v if self.lines is None else v - self.lines.dot(a, b)

    def convolve(self, x):
        """K x into the workspace's output array (one convolution; not counted here)."""
        out, shape = self.cP, self.shape
        if self._takes_out:
            self._apply(x.reshape(shape), out=out.reshape(shape))
        else:  # a kernel of the caller's own without ``out=``
            out[:] = self._apply(x.reshape(shape)).ravel()
        return out

    def _law_block(self, sl, m, sc, acc, unchecked):
        buf = self.sw.buf
        work = (buf(sc, "a", m), buf(sc, "b", m))
        if unchecked:
            e, g_min = self.law.energy_pressure_unchecked(self.g[sl], self.P[sl], work)
            acc[0] += e
            acc[2] = np.minimum(acc[2], g_min)
        else:
            acc[0] += self.law.energy_pressure(self.g[sl], self.P[sl], work)
        if self.proj:
            acc[1] += self.P[sl].sum()

    def _law_sums(self, unchecked):
        accs = self.sw.run(self._law_block, [0.0, 0.0, np.inf], unchecked)
        if len(accs) == 1:
            return accs[0]
        return [sum(a[0] for a in accs), sum(a[1] for a in accs), functools.reduce(np.minimum, (a[2] for a in accs))]

    def law_sweep(self, extra=()):
        """[ΣΦ(g), ΣP] (ΣP for periodic kernels only, else 0) with P(g) written into P, then the backend
        scalars ``extra`` as host floats: one host sync (the law's unchecked hot path, checked by the
        smallest gap, as in the line search; a weighted problem's share of the deficit pixels taken
        with it).  Distributed: ΣΦ and ΣP summed over the ranks (``extra`` as this process has it)."""
        phis, sum_p, g_min = self._law_sums(self.unchecked)
        L, extra = self.lines, list(extra)
        if L is not None:  # weighted: the deficit pixels' share, from the unchecked P first
            phis, sum_p = _weigh_law(L, self.law, self.g, self.P, [phis, sum_p], self.proj)
        h = backend.sync([phis, sum_p, g_min] + extra).tolist()
        if self.unchecked and not self.law.covers(h[2]):  # P was not right everywhere: checked anew
            phis, sum_p, _ = self._law_sums(False)
            if L is not None:
                phis, sum_p = _weigh_law(L, self.law, self.g, self.P, [phis, sum_p], self.proj)
            h[:2] = backend.sync((phis, sum_p)).tolist()
        acc = h[:2]
        if self.red is not None:
            acc = self.red.sum(acc)
        return acc + h[3:]

    def lowest_energy(self) -> float:
        """The lowest E so far: E may rise by round-off in an accepted step (approximate Wolfe);
        measured from it, such rises cannot add up over many steps near convergence."""
        self.E_best = min(self.E_best, self.E)
        return self.E_best

    # ---- the direction --------------------------------------------------------------------------
    def _direction_block(self, sl, m, sc, acc, gamma, c, k2, fuse):
        ds, kds = self.d[sl], self.Kd[sl]
        np.multiply(self.G[sl], -gamma, out=ds)
        np.multiply(self.r[sl], -gamma, out=kds)
        if k2:
            h = self.sw.buf(sc, "h", m)
            np.matmul(c, self.mem.B[:k2, sl], out=h)
            ds -= h
            np.matmul(c, self.mem.KB[:k2, sl], out=h)
            kds -= h
        acc[0] += np.vdot(ds, self.w[sl])
        acc[1] += np.vdot(ds, kds)
        acc[2] += np.vdot(ds, self.r[sl])
        if self.proj:
            acc[3] += ds.sum()
        if fuse:  # the line search's first trial, α = 1, on this block while it is in cache
            self.search.block(sl, m, sc, acc, 1.0, self.g, self.P, self.Kd, True, 4)

    def _direction(self):
        """One sweep and its one host sync: ([d·w, d·K d, d·r, Σd], α0, taken_back).

        Along come: with a memory, the line search's first trial α = 1 (:attr:`first`: its [ΣΦ,
        Σ(P(1) − P)·K d, ΣP], or None); without, max K d and min K d for α0 (else α0 = 1); and the due
        residual's numbers (:meth:`_settle`: ``taken_back`` says the memory lost the pair this direction
        was computed with, which is then void)."""
        gamma, c = self.mem.coefficients()
        k2 = 0 if c is None else c.size
        # the first trial fused with a SafeLaw (its check rides on this sweep's sync), not distributed
        fuse = k2 > 0 and self.unchecked and self.red is None
        init = [0.0, 0.0, 0.0, 0.0] + ([0.0, 0.0, 0.0, np.inf] if fuse else [])
        accs = self.sw.run(self._direction_block, init, gamma, c, k2, fuse)
        if len(accs) == 1:
            acc = accs[0]
        else:
            acc = [sum(a[j] for a in accs) for j in range(min(len(init), 7))]
            if fuse:
                acc.append(functools.reduce(np.minimum, (a[7] for a in accs)))
        L = self.lines
        if L is not None:  # the sweep wrote d and K d whole: correct its sums on the deficit pixels
            cw, cKd, cr = L.dots(self.d, self.w, self.Kd, self.r)
            acc[:4] = [acc[0] - cw, acc[1] - cKd, acc[2] - cr, acc[3] - (L.sum(self.d) if self.proj else 0.0)]
            if fuse:  # the trial's too, from its unchecked P(1) (void unless its smallest gap is covered)
                acc[4:7] = self.search.weigh(*acc[4:7], self.P, self.Kd)
        if not k2:
            acc += [self.Kd.max(), self.Kd.min()]
        due = [] if self._due is None else self._due.values()
        h = backend.sync(acc + due).tolist()  # the sweep's one host sync
        taken_back = self._settle(h[len(acc):]) if due else False
        self.first = None
        if fuse and self.law.covers(h[7]):
            self.first = h[4:7]
        alpha0 = 1.0 if k2 else self.search.first_step(h[4], h[5])
        sums = h[:4]
        if self.red is not None:
            sums = self.red.sum(sums)
        return sums, alpha0, taken_back

    def _settle(self, h) -> bool:
        """The due residual's numbers ``h`` (host floats, :meth:`_Due.values`): max|r| and, for a new pair,
        its curvature test: the memory holds the pair unconfirmed (:meth:`remember`) and keeps it, or
        takes it back (and, on a re-anchored step, its products with G anew).  Returns True when taken back."""
        due, self._due = self._due, None
        hi, lo = h[0], h[1]
        self.rmax = max(hi, -lo) if hi == hi and lo == lo else math.nan   # max|r_new|
        if self.red is not None:
            self.rmax = self.red.max(self.rmax)
        if due.dky is None:
            return False
        dA, alpha = self.dA, due.alpha
        sy = dA * alpha * h[2]
        yy = dA * h[3]
        if _algebra.stores_pair(HOST, sy, yy, due.sks):
            self.mem.confirm()
            return False
        self.mem.rollback()
        if due.resync:
            self.mem.refresh(self.r)
        return True

    def ended(self, tol: float) -> bool:
        """Is the current residual non-finite or max|r| <= ``tol``?"""
        return not math.isfinite(self.rmax) or self.rmax <= tol

    def settle(self) -> None:
        """Bring the due residual's numbers over on their own (the solve ends without another sweep)."""
        if self._due is not None:
            self._settle(backend.sync(self._due.values()).tolist())

    def direction(self, tol: float):
        """(Ray, α0): d = −H G and K d = −K H G (one sweep), E along d, and the line search's first α;
        or None when the residual that came over with the sweep ends the solve (:meth:`ended`: the
        sweep is then void; it wrote only d, K d and the trial buffers).

        The slope E'(0) = ΔA (d·w − P·K d) is taken as ΔA d·r (equal, since r = w − K P and K is
        symmetric): near convergence d·w and P·K d nearly cancel, and their difference is noise.
        A pair that failed the curvature test is taken back and d computed anew without it.
        Not a descent direction (d·r >= 0): the memory is dropped, d = −G."""
        if self._due is None and self.ended(tol):
            return None
        sums, alpha0, taken_back = self._direction()
        if self.ended(tol):
            return None
        if taken_back:
            sums, alpha0, _ = self._direction()
        dw, dKd, dr, sum_d = sums
        if not dr < 0:
            self.mem.reset()
            (dw, dKd, dr, sum_d), alpha0, _ = self._direction()
        self.sum_d = sum_d
        return Ray(self.g, self.P, self.Kd, self.qw, dw, dKd, self.E, self.dA * dr), alpha0

    # ---- the step -------------------------------------------------------------------------------
    def accept(self, trial: Trial, ray: Ray, resync: bool) -> None:
        """Move E, q·w, ΣΦ, ΣP, mean(q) to the accepted point (q and w themselves move in
        :meth:`new_residual`); on a ``resync`` step q moves here and w is re-anchored (:meth:`_reanchor`)."""
        alpha = trial.alpha
        if resync:
            self.corr = self._reanchor(alpha)
            self.E_best = math.inf  # E is recomputed exactly: the bookkeeping restarts from it
        else:
            self.g, self.P = self.search.swap(self.g, self.P)
            self.phis, self.sum_p = trial.phis, trial.sum_p
            self.qw += alpha * (2.0 * ray.dw + alpha * ray.dKd)
            self.corr = None
        self.E = self.dA * (0.5 * self.qw + self.phis)
        self.mean_q += alpha * self.sum_d / self.nw

    def _reanchor(self, alpha):
        """q ← q + α d and w = K q exactly (one convolution), then g, P, ΣΦ, q·w anew.

        The images K d are assembled, not convolved: round-off lets w drift from K q.  The
        correction (w = K q exactly, minus the assembled step α K d) goes to w and r only: the
        stored pair keeps the assembled images K s = α K d, K y = K s − Δ(K P), as every other
        pair does, so the drift is not fed back into later directions.  Returns the correction."""
        q, w, gt, Pt = self.q, self.w, self.search.g_trial, self.search.P_trial
        _axpy(self.d, q, alpha, gt)
        w_exact = self.convolve(q)
        self.n_conv += 1
        corr = np.subtract(w_exact, w, out=gt)
        _axpy(self.Kd, corr, -alpha, Pt)
        w[:] = w_exact
        np.add(self.g0, w, out=self.g)
        self.phis, self.sum_p, qw = self.law_sweep([self._dot_dev(q, w)])  # q·w in the law sweep's sync
        self.qw = qw if self.red is None else self.red.sum([qw])[0]
        return corr

    def _residual_block(self, sl, m, sc, acc, alpha, step, corr, mu, k2, slot, held):
        # q ← q + α d, w ← w + α K d; r_new = w − K P; K y = Δr; G_new = q − P; y = ΔG
        ds = self.d[sl]
        if step:
            tmp = self.sw.buf(sc, "t", m)
            qs, ws = self.q[sl], self.w[sl]
            np.multiply(ds, alpha, out=tmp)
            qs += tmp
            np.multiply(self.Kd[sl], alpha, out=tmp)
            ws += tmp
        rns, kys, Gns, ys = self.rn[sl], self.ky[sl], self.Gn[sl], self.y[sl]
        np.subtract(self.w[sl], self.cP[sl], out=rns)
        np.subtract(rns, self.r[sl], out=kys)
        if corr is not None:
            kys -= corr[sl]
        np.subtract(self.q[sl], self.P[sl], out=Gns)
        if self.proj:
            Gns -= mu
        np.subtract(Gns, self.G[sl], out=ys)
        acc[0] += np.vdot(ds, kys)
        acc[1] += np.vdot(ys, kys)
        acc[2] += np.vdot(ds, rns)
        acc[3] += np.vdot(ys, rns)
        hi, lo = rns.max(), rns.min()
        acc[4] = hi if acc[4] is None else np.maximum(acc[4], hi)
        acc[6] = lo if acc[6] is None else np.minimum(acc[6], lo)
        B, KB = self.mem.B, self.mem.KB
        if k2:
            acc[5] = acc[5] + B[:k2, sl] @ kys
        # the new pair's rows s = α d, y, K s, K y (unconfirmed); a full memory's oldest pair aside first
        if held is not None:
            sp = self.mem.spare
            B[2 * sp:2 * sp + 2, sl] = B[2 * held:2 * held + 2, sl]
            KB[2 * sp:2 * sp + 2, sl] = KB[2 * held:2 * held + 2, sl]
        np.multiply(ds, alpha, out=B[2 * slot, sl])
        B[2 * slot + 1, sl] = ys
        np.multiply(self.Kd[sl], alpha, out=KB[2 * slot, sl])
        KB[2 * slot + 1, sl] = kys

    def new_residual(self, alpha: float, resync: bool):
        """K P at the new point (one convolution) and, in one sweep, the step of q and w (unless
        re-anchored), the new residual and gradient, the pair y = ΔG, K y = Δr, their products, and the
        pair's rows in the memory (:meth:`KMetricLBFGS.next_slot <tengsim.solvers._lbfgs.KMetricLBFGS.next_slot>`).

        Returns (d·K y, y·K y, d·r_new, y·r_new, max r_new, min r_new, B K y): backend values, no host
        sync (a distributed solve's: synced and summed over the ranks)."""
        mu = self.mean_q - self.sum_p / self.nw if self.proj else 0.0
        self.convolve(self.P)
        self.n_conv += 1
        mem = self.mem
        k2 = 2 * len(mem.order)
        slot, held = mem.next_slot()
        accs = self.sw.run(self._residual_block, [0.0, 0.0, 0.0, 0.0, None, 0.0, None],
                           alpha, not resync, self.corr, mu, k2, slot, held)
        if len(accs) == 1:
            dky, yky, drn, yrn, hi, x, lo = accs[0]
        else:
            dky, yky, drn, yrn, x = (sum(a[j] for a in accs) for j in (0, 1, 2, 3, 5))
            hi = functools.reduce(np.maximum, (a[4] for a in accs))
            lo = functools.reduce(np.minimum, (a[6] for a in accs))
        L = self.lines
        if L is not None:  # max|r| stays a plain max; the products are weighted
            ky, rn = self.ky, self.rn
            c_dky, c_drn = L.dots(self.d, ky, rn)
            c_yky, c_yrn = L.dots(self.y, ky, rn)
            dky, yky, drn, yrn = dky - c_dky, yky - c_yky, drn - c_drn, yrn - c_yrn
            if k2:  # the rows as they were: the held pair's from the spare rows
                moved = None if held is None else (2 * held, mem.B[2 * mem.spare:2 * mem.spare + 2])
                x = x - L.rows(mem.B[:k2], ky, moved)
        if self.red is None:
            return dky, yky, drn, yrn, hi, lo, (x if k2 else None)
        h = backend.sync((dky, yky, drn, yrn, hi, lo), x if k2 else None)  # every rank's partial values
        dky, yky, drn, yrn = self.red.sum(h[:4].tolist())
        x = self.red.sum(np.asarray(h[6:], dtype=float)) if k2 else None
        return dky, yky, drn, yrn, float(h[4]), float(h[5]), x

    def remember(self, alpha: float, ray: Ray, pair, resync: bool) -> None:
        """Update the L-BFGS memory with the pair (s = α d, y), unconfirmed, and make the new residual
        and gradient current (on a re-anchored step, the memory's products anew).  The residual is
        due (:class:`_Due`): max|r| and the curvature test ⟨s, y⟩ > 0 come over with the next sweep's
        sync (a distributed solve's are here already: settled at once)."""
        dky, yky, drn, yrn, hi, lo, x = pair
        dA = self.dA
        self.mem.update(alpha, None if x is None else dA * x, dA * alpha * dky, dA * yky, dA * drn, dA * yrn)
        self.r, self.rn = self.rn, self.r
        self.G, self.Gn = self.Gn, self.G
        if resync:
            self.mem.refresh(self.r)
        self._due = _Due(hi, lo, dky, yky, alpha, dA * alpha * alpha * abs(ray.dKd), resync)
        if self.red is not None:
            self._settle([hi, lo, dky, yky])

    def finish(self, ok: bool, it: int, msg: str, t0: float, capped: bool = False) -> Equilibrium:
        st = State(self.q.reshape(self.shape), self.w.reshape(self.shape))
        return finish(self.problem, st, self.P.reshape(self.shape).copy(), self.r, self.E, ok, it,
                       self.n_conv, t0, msg, capped)


def _weigh_law(lines, law, g, P, acc, sum_p):
    """[ΣΦ, ΣP] of a sweep, m-weighted: less the deficit pixels' share (Φ there evaluated anew)."""
    i = lines.idx
    phis = acc[0] - np.dot(lines.c, _energy_at(law, g[i]))
    return [phis, acc[1] - lines.sum(P) if sum_p else acc[1]]


def _axpy(x, y, a, tmp):
    """y ← y + a x in place, through the scratch array ``tmp`` (no allocation).

    (Not BLAS daxpy: OpenBLAS threads it, and on a busy 2-core machine that cost ~1000× on small arrays.)
    """
    np.multiply(x, a, out=tmp)
    np.add(y, tmp, out=y)
