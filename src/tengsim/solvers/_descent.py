"""One descent of the fast solver (:class:`tengsim.solvers.fast.FastSolver`): the iterate, its residual and the
L-BFGS memory, and the fused sweeps that update them."""
from __future__ import annotations

import functools
import inspect
import math

import numpy as np

from tengsim import backend
from tengsim.laws.safe import safe
from tengsim.solvers._linesearch import Ray, Trial, WolfeLineSearch
from tengsim.solvers._reduce import for_kernel
from tengsim.solvers.types import Equilibrium, Problem, State, finish


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
        self._apply, self._takes_out = K.apply, _takes_out(K.apply)
        # the start: g, P, ΣΦ, r (one convolution), G, E
        np.add(self.g0, self.w, out=self.g)
        self.phis, self.sum_p = self.law_sweep()
        np.subtract(self.w, self.convolve(self.P), out=self.r)
        self.n_conv = 1
        if red is not None:
            self.mean_q = red.sum([backend.to_host(self.q.sum())])[0] / self.nw
        elif lines is None:
            self.mean_q = backend.to_host(self.q.mean())
        else:
            self.mean_q = backend.to_host(self.q.sum() - lines.sum(self.q)) / self.nw
        np.subtract(self.q, self.P, out=self.G)
        if self.proj:
            self.G -= self.mean_q - self.sum_p / self.nw
        self.qw = self._dot(self.q, self.w)
        self.E = self.dA * (0.5 * self.qw + self.phis)
        hi, lo = backend.sync((self.r.max(), self.r.min()))
        self.rmax = max(float(hi), -float(lo))
        if red is not None:
            self.rmax = red.max(self.rmax)
        self.E_best = self.E
        self.sum_d = 0.0
        self.corr = None
        self.first = None  # the first trial's sums, swept with the direction (:meth:`_direction`)

    # ---- the pieces ---------------------------------------------------------------------------
    def _dot(self, a, b) -> float:
        """a·b, m-weighted (in units of the interior weight) for a weighted problem."""
        v = np.vdot(a, b)
        if self.red is not None:
            return self.red.sum([backend.to_host(v)])[0]
        return backend.to_host(v if self.lines is None else v - self.lines.dot(a, b))

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

    def law_sweep(self):
        """ΣΦ(g) and ΣP (periodic kernels only, else 0), with P(g) written into P: one host sync (the
        law's unchecked hot path, checked by the smallest gap, as in the line search)."""
        phis, sum_p, g_min = self._law_sums(self.unchecked)
        if self.lines is None:
            phis, sum_p, g_min = backend.sync((phis, sum_p, g_min)).tolist()
            if self.unchecked and not self.law.covers(g_min):
                phis, sum_p, _ = backend.sync(self._law_sums(False)).tolist()
            acc = [phis, sum_p]
        else:  # weighted: the deficit pixels' share needs P right first
            if self.unchecked and not self.law.covers(backend.to_host(g_min)):
                phis, sum_p, _ = self._law_sums(False)
            acc = backend.sync(_weigh_law(self.lines, self.law, self.g, self.P, [phis, sum_p], self.proj)).tolist()
        if self.red is not None:
            acc = self.red.sum(acc)
        return acc

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
        """[d·w, d·K d, d·r, Σd] (host floats, one sync); with a memory the line search's first trial α = 1
        is swept along (:attr:`first`: its [ΣΦ, Σ(P(1) − P)·K d, ΣP], or None)."""
        gamma, c = self.mem.coefficients()
        k2 = 0 if c is None else c.size
        # fused in the serial, unweighted solve with a SafeLaw (its check rides on this sweep's sync)
        fuse = k2 > 0 and self.unchecked and self.lines is None and self.red is None
        init = [0.0, 0.0, 0.0, 0.0] + ([0.0, 0.0, 0.0, np.inf] if fuse else [])
        accs = self.sw.run(self._direction_block, init, gamma, c, k2, fuse)
        if len(accs) == 1:
            acc = accs[0]
        else:
            acc = [sum(a[j] for a in accs) for j in range(min(len(init), 7))]
            if fuse:
                acc.append(functools.reduce(np.minimum, (a[7] for a in accs)))
        self.first = None
        if fuse:
            h = backend.sync(acc).tolist()  # the sweep's one host sync: the direction and the trial
            if self.law.covers(h[7]):
                self.first = h[4:7]
            return h[:4]
        L = self.lines
        if L is not None:  # the sweep wrote d and K d whole: correct its sums on the deficit pixels
            cw, cKd, cr = L.dots(self.d, self.w, self.Kd, self.r)
            acc = [acc[0] - cw, acc[1] - cKd, acc[2] - cr, acc[3] - (L.sum(self.d) if self.proj else 0.0)]
        acc = backend.sync(acc).tolist()  # the sweep's one host sync
        if self.red is not None:
            acc = self.red.sum(acc)
        return acc

    def direction(self) -> Ray:
        """d = −H G and K d = −K H G (one sweep), and E along d.

        The slope E'(0) = ΔA (d·w − P·K d) is taken as ΔA d·r (equal, since r = w − K P and K is
        symmetric): near convergence d·w and P·K d nearly cancel, and their difference is noise.
        Not a descent direction (d·r >= 0): the memory is dropped, d = −G."""
        dw, dKd, dr, sum_d = self._direction()
        if not dr < 0:
            self.mem.reset()
            dw, dKd, dr, sum_d = self._direction()
        self.sum_d = sum_d
        return Ray(self.g, self.P, self.Kd, self.qw, dw, dKd, self.E, self.dA * dr)

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
        self.phis, self.sum_p = self.law_sweep()
        self.qw = self._dot(q, w)
        return corr

    def _residual_block(self, sl, m, sc, acc, alpha, step, corr, mu, k2):
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
        if k2:
            acc[5] = acc[5] + self.mem.B[:k2, sl] @ kys

    def new_residual(self, alpha: float, resync: bool):
        """K P at the new point (one convolution) and, in one sweep, the step of q and w (unless
        re-anchored), the new residual and gradient, the pair y = ΔG, K y = Δr and their products.

        Returns (d·K y, y·K y, d·r_new, y·r_new, B K y): what the memory update needs; sets max|r|."""
        mu = self.mean_q - self.sum_p / self.nw if self.proj else 0.0
        self.convolve(self.P)
        self.n_conv += 1
        k2 = 2 * len(self.mem.order)
        accs = self.sw.run(self._residual_block, [0.0, 0.0, 0.0, 0.0, None, 0.0, None],
                           alpha, not resync, self.corr, mu, k2)
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
            if k2:
                x = x - L.rows(self.mem.B[:k2], ky)
        h = backend.sync((dky, yky, drn, yrn, hi, lo), x if k2 else None)  # the sweep's one host sync
        dky, yky, drn, yrn, hi, lo = h[:6].tolist()
        self.rmax = max(hi, -lo) if hi == hi and lo == lo else math.nan   # max|r_new|
        x = h[6:]
        if self.red is not None:  # every rank's partial products and max|r|
            dky, yky, drn, yrn = self.red.sum([dky, yky, drn, yrn])
            self.rmax = self.red.max(self.rmax)
            if k2:
                x = self.red.sum(np.asarray(x, dtype=float))
        return dky, yky, drn, yrn, (x if k2 else None)

    def _store_block(self, sl, m, sc, acc, alpha, slot):
        B, KB = self.mem.B, self.mem.KB
        np.multiply(self.d[sl], alpha, out=B[2 * slot, sl])
        B[2 * slot + 1, sl] = self.y[sl]
        np.multiply(self.Kd[sl], alpha, out=KB[2 * slot, sl])
        KB[2 * slot + 1, sl] = self.ky[sl]

    def remember(self, alpha: float, ray: Ray, pair, resync: bool) -> None:
        """Update the L-BFGS memory with the pair (s = α d, y) if ⟨s, y⟩ > 0 (curvature), then make
        the new residual and gradient current (on a re-anchored step, the memory's products anew)."""
        dky, yky, drn, yrn, x = pair
        dA = self.dA
        sy = dA * alpha * dky
        yy = dA * yky
        sks = dA * alpha * alpha * abs(ray.dKd)
        store = sy > 1e-14 * max(sks, 1e-300) and yy > 0
        slot = self.mem.update(alpha, None if x is None else dA * x, sy, yy, dA * drn, dA * yrn, store)
        if slot is not None:
            self.sw.run(self._store_block, (), alpha, slot)
        self.r, self.rn = self.rn, self.r
        self.G, self.Gn = self.Gn, self.G
        if resync:
            self.mem.refresh(self.r)

    def finish(self, ok: bool, it: int, msg: str, t0: float) -> Equilibrium:
        st = State(self.q.reshape(self.shape), self.w.reshape(self.shape))
        return finish(self.problem, st, self.P.reshape(self.shape).copy(), self.r, self.E, ok, it,
                       self.n_conv, t0, msg)


def _weigh_law(lines, law, g, P, acc, sum_p):
    """[ΣΦ, ΣP] of a sweep, m-weighted: less the deficit pixels' share (Φ there evaluated anew)."""
    i = lines.idx
    phis = acc[0] - np.dot(lines.c, law.energy(g[i]))
    return [phis, acc[1] - lines.sum(P) if sum_p else acc[1]]


def _takes_out(fn) -> bool:
    """Does ``fn`` accept an ``out=`` keyword (the package's kernels do)?  Asked once per function:
    ``inspect.signature`` costs ~20 µs, a tenth of a warm equilibrium on group A's grid."""
    func = getattr(fn, "__func__", fn)  # a bound method's function: the same answer for every instance
    try:
        return _signature_takes_out(func)
    except TypeError:  # an unhashable callable: not cached
        return _signature_takes_out.__wrapped__(func)


@functools.lru_cache(maxsize=64)
def _signature_takes_out(fn) -> bool:
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
