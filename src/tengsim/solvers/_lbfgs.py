"""Compact limited-memory BFGS inverse Hessian in the elastic (K) inner product.

Byrd, Nocedal & Schnabel (1994), Eq. (3.1)-(3.2): with m pairs (s_i, y_i), γ = <s,y>/<y,y> of the
newest pair, R the upper triangle of [<s_i, y_j>] (pairs in age order), D its diagonal,

    H v = γ v + S top − γ Y u,   u = R⁻¹ (S^T v),   top = R^{-T}((D + γ Y^T Y) u − γ Y^T v),

where S^T v means the vector of <s_i, v> = ΔA s_i·K v.  Every stored vector is kept beside its image
K s_i, K y_i, so H v and K H v come from two matrix–vector products over the stored rows (BLAS, one
pass each) and no convolution.

Memory traffic is the cost here, not arithmetic, so this class keeps only the small matrices and
the rows; the solver reads the rows itself, block by block together with its other element-wise
work (tengsim.solvers._sweep):

* the 2m stored rows are read twice for H v and K H v and once for the update, and nothing else
  touches them (float32 rows halve the bytes, but measured on rough surfaces they cost up to
  20–30 % more iterations, from cancellation in the compact form, and no time overall);
* the inner products with the current gradient G, <s_i, G> and <y_i, G>, are carried along by
  recurrence (G changes by y each step, so they change by <s_i, y>, <y_i, y>, which the new
  pair's column of [<s_i, y_j>] needs anyway) and recomputed exactly on ``refresh``;
* the new pair's row <s, y_j> follows from the direction's coefficients and the small matrices.
"""
from __future__ import annotations

import numpy as np
from scipy.linalg.lapack import dtrtrs

from tengsim import backend


class KMetricLBFGS:
    """Ring of m pairs (s, y) and images (K s, K y); slot j lives in rows 2j, 2j + 1."""

    def __init__(self, memory: int, n: int, dA: float):
        self.m, self.dA = int(memory), float(dA)
        m = self.m
        self.B = backend.empty((2 * m, n))     # s_j, y_j
        self.KB = backend.empty((2 * m, n))    # K s_j, K y_j
        self.SY = backend.zeros((m, m))  # SY[i, j] = <s_i, y_j>, by slot
        self.YY = backend.zeros((m, m))  # YY[i, j] = <y_i, y_j>
        self.pS = backend.zeros(m)       # <s_i, G> for the current gradient G
        self.pY = backend.zeros(m)       # <y_i, G>
        self.order: list[int] = []  # slots, oldest first; the active slots are always 0 .. k-1
        self._last = (1.0, backend.zeros(0), backend.zeros(0))
        self._perm = backend.zeros(0, int)   # active slots in age order (oldest first), as an index array
        self.lines = None  # a weighted problem's deficit pixels (tengsim.solvers._weights): m-weighted products
        self.red = None    # a distributed solve's sums over all ranks (tengsim.solvers._reduce)

    @property
    def empty(self) -> bool:
        return not self.order

    def reset(self) -> None:
        self.order = []
        self._perm = backend.zeros(0, int)
        self._last = (1.0, backend.zeros(0), backend.zeros(0))

    def refresh(self, r) -> None:
        """Recompute <s_i, G>, <y_i, G> exactly from r = K G (one pass over the rows)."""
        k = len(self.order)
        if k:
            p = self.B[: 2 * k] @ r
            if self.lines is not None:
                p = p - self.lines.rows(self.B[: 2 * k], r)
            if self.red is not None:  # a distributed solve: the rows' products over all ranks
                p = self.red.sum(np.asarray(p, dtype=float))
            p = self.dA * p
            self.pS[:k], self.pY[:k] = p[0::2], p[1::2]

    def coefficients(self):
        """(γ, c) of  H G = γ G + Σ_rows c_i B_i  (and K H G = γ r + Σ c_i KB_i) over rows B[:2k];
        c is None while the memory is empty (H = identity)."""
        k = len(self.order)
        if not k:
            self._last = (1.0, backend.zeros(0), backend.zeros(0))
            return 1.0, None
        act = self._perm
        new = act[-1]
        yy = self.YY[new, new]
        gamma = self.SY[new, new] / yy if yy > 0 else 1.0
        SYa = self.SY[act[:, None], act]
        # R = upper triangle of SYa, positive diagonal (<s_i, y_i> > 0 for every stored pair);
        # LAPACK's trtrs reads only the upper triangle (no triu copy needed), and directly:
        # scipy's solve_triangular costs ~10× more on these tiny systems
        u = dtrtrs(SYa, self.pS[act], lower=0)[0]
        top = dtrtrs(SYa, np.diag(SYa) * u + gamma * (self.YY[act[:, None], act] @ u) - gamma * self.pY[act],
                     lower=0, trans=1)[0]
        cS = backend.empty(k)
        cY = backend.empty(k)
        cS[act] = top
        cY[act] = -gamma * u
        c = backend.empty(2 * k)
        c[0::2], c[1::2] = cS, cY
        self._last = (gamma, cS, cY)
        return gamma, c

    def update(self, alpha, x, sy, yy, d_rn, y_rn, store: bool):
        """After the step s = α d, G ← G + y.  ``x`` = ΔA·B[:2k] @ K y (the rows' products with the
        new y), ``d_rn`` = ΔA d·r_new, ``y_rn`` = ΔA y·r_new.

        Keeps <s_i, G>, <y_i, G> current and, if ``store`` (sy = <s, y> > 0, yy = <y, y>), makes room
        for the pair (s, y), evicting the oldest when full; returns the slot whose rows
        B[2 slot] = s, B[2 slot + 1] = y, KB[...] = K s, K y the caller must then fill, else None.
        """
        k, m = len(self.order), self.m
        if k:
            xs, xy = x[0::2], x[1::2]          # <s_i, y>, <y_i, y>
            if store:
                gamma, cS, cY = self._last
                # <d, y_j> from d = −(γ G + Σ cS_i s_i + Σ cY_i y_i), with G the old gradient
                dy = -(gamma * self.pY[:k] + cS @ self.SY[:k, :k] + cY @ self.YY[:k, :k]) if cS.size \
                    else -self.pY[:k]
            self.pS[:k] += xs
            self.pY[:k] += xy
        if not store:
            return None
        slot = k if k < m else self.order.pop(0)
        if k:  # the evicted slot's own entries are overwritten by the diagonal just below
            self.SY[:k, slot] = xs
            self.SY[slot, :k] = alpha * dy
            self.YY[:k, slot] = xy
            self.YY[slot, :k] = xy
        self.SY[slot, slot] = sy
        self.YY[slot, slot] = yy
        self.pS[slot] = alpha * d_rn
        self.pY[slot] = y_rn
        self.order.append(slot)
        self._perm = backend.xp.asarray(self.order)
        return slot
