"""Compact limited-memory BFGS inverse Hessian in the elastic (K) inner product.

Byrd, Nocedal & Schnabel (1994), Eq. (3.1)-(3.2): with m pairs (s_i, y_i), γ = <s,y>/<y,y> of the
newest pair, R the upper triangle of [<s_i, y_j>] (pairs in age order), D its diagonal,

    H v = γ v + S top − γ Y u,   u = R⁻¹ (S^T v),   top = R^{-T}((D + γ Y^T Y) u − γ Y^T v),

where S^T v means the vector of <s_i, v> = ΔA s_i·K v.  Every stored vector is kept beside its image
K s_i, K y_i, so H v and K H v come from two matrix–vector products over the stored rows (BLAS, one
pass each) and no convolution.

Memory traffic is the cost here, not arithmetic, so:

* the 2m stored rows are read in two BLAS products for H v and K H v and one for the update, and
  nothing else touches them (``dtype=float32`` halves the bytes, but measured on rough surfaces it
  cost up to 20–30 % more iterations, from cancellation in the compact form, and no time overall);
* the inner products with the current gradient G, <s_i, G> and <y_i, G>, are carried along by
  recurrence (G changes by y each step, so they change by <s_i, y>, <y_i, y>, which the new
  pair's column of [<s_i, y_j>] needs anyway) and recomputed exactly on ``refresh``;
* the new pair's row <s, y_j> follows from the direction's coefficients and the small matrices.

Per iteration: two passes over the 2k stored rows for H G and K H G, one for the update.
"""
from __future__ import annotations

import numpy as np
from scipy.linalg.lapack import dtrtrs


class KMetricLBFGS:
    """Ring of m pairs (s, y) and images (K s, K y); slot j lives in rows 2j, 2j + 1."""

    def __init__(self, memory: int, n: int, dA: float, dtype=np.float64):
        self.m, self.dA = int(memory), float(dA)
        m = self.m
        self.B = np.empty((2 * m, n), dtype)     # s_j, y_j
        self.KB = np.empty((2 * m, n), dtype)    # K s_j, K y_j
        self.SY = np.zeros((m, m))  # SY[i, j] = <s_i, y_j>, by slot
        self.YY = np.zeros((m, m))  # YY[i, j] = <y_i, y_j>
        self.pS = np.zeros(m)       # <s_i, G> for the current gradient G
        self.pY = np.zeros(m)       # <y_i, G>
        self.order: list[int] = []  # slots, oldest first; the active slots are always 0 .. k-1
        self._v = np.empty(n, dtype)
        self._h = np.empty(n, dtype)
        self._last = (1.0, np.zeros(0), np.zeros(0))
        self._perm = np.zeros(0, int)   # active slots in age order (oldest first), as an index array

    @property
    def empty(self) -> bool:
        return not self.order

    def reset(self) -> None:
        self.order = []
        self._perm = np.zeros(0, int)
        self._last = (1.0, np.zeros(0), np.zeros(0))

    def refresh(self, r) -> None:
        """Recompute <s_i, G>, <y_i, G> exactly from r = K G (one pass over the rows)."""
        k = len(self.order)
        if k:
            self._v[:] = r
            p = self.dA * (self.B[: 2 * k] @ self._v)
            self.pS[:k], self.pY[:k] = p[0::2], p[1::2]

    def direction(self, G, r, d, Kd) -> None:
        """Write d = −H G and Kd = K d (flat float64 buffers); r = K G."""
        k = len(self.order)
        if not k:
            np.negative(G, out=d)
            np.negative(r, out=Kd)
            self._last = (1.0, np.zeros(0), np.zeros(0))
            return
        act = self._perm
        new = act[-1]
        yy = self.YY[new, new]
        gamma = self.SY[new, new] / yy if yy > 0 else 1.0
        SYa = self.SY[act[:, None], act]
        R = np.triu(SYa)
        # R is upper triangular with a positive diagonal (<s_i, y_i> > 0 for every stored pair);
        # LAPACK's trtrs directly: scipy's solve_triangular costs ~10× more on these tiny systems
        u = dtrtrs(R, self.pS[act], lower=0)[0]
        top = dtrtrs(R, np.diag(SYa) * u + gamma * (self.YY[act[:, None], act] @ u) - gamma * self.pY[act],
                     lower=0, trans=1)[0]
        cS = np.empty(k)
        cY = np.empty(k)
        cS[act] = top
        cY[act] = -gamma * u
        c = np.empty(2 * k, self.B.dtype)
        c[0::2], c[1::2] = cS, cY
        np.matmul(c, self.B[: 2 * k], out=self._h)
        np.multiply(G, -gamma, out=d)
        d -= self._h
        np.matmul(c, self.KB[: 2 * k], out=self._h)
        np.multiply(r, -gamma, out=Kd)
        Kd -= self._h
        self._last = (gamma, cS, cY)

    def update(self, alpha, d, ks_factor, ks_base, y, ky, r_new, sy, yy, store: bool) -> None:
        """After the step s = α d (image ks = ks_factor · ks_base), G ← G + y (image ky).

        Keeps <s_i, G>, <y_i, G> current and, if ``store``, adds the pair (s, y) with
        sy = <s, y> > 0 and yy = <y, y>, evicting the oldest when full.
        """
        k, dA, m = len(self.order), self.dA, self.m
        if k:
            self._v[:] = ky
            x = dA * (self.B[: 2 * k] @ self._v)
            xs, xy = x[0::2], x[1::2]          # <s_i, y>, <y_i, y>
            if store:
                gamma, cS, cY = self._last
                # <d, y_j> from d = −(γ G + Σ cS_i s_i + Σ cY_i y_i), with G the old gradient
                dy = -(gamma * self.pY[:k] + cS @ self.SY[:k, :k] + cY @ self.YY[:k, :k]) if cS.size \
                    else -self.pY[:k]
            self.pS[:k] += xs
            self.pY[:k] += xy
        if not store:
            return
        slot = k if k < m else self.order.pop(0)
        keep = [j for j in range(k) if j != slot]
        if keep:
            self.SY[keep, slot] = xs[keep]
            self.SY[slot, keep] = alpha * dy[keep]
            self.YY[keep, slot] = xy[keep]
            self.YY[slot, keep] = xy[keep]
        self.SY[slot, slot] = sy
        self.YY[slot, slot] = yy
        self.pS[slot] = alpha * dA * np.vdot(d, r_new)
        self.pY[slot] = dA * np.vdot(y, r_new)
        np.multiply(d, alpha, out=self.B[2 * slot], casting="same_kind")
        self.B[2 * slot + 1] = y
        np.multiply(ks_base, ks_factor, out=self.KB[2 * slot], casting="same_kind")
        self.KB[2 * slot + 1] = ky
        self.order.append(slot)
        self._perm = np.array(self.order)
