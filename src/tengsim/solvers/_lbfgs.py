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
  touches them (float32 rows would halve the bytes, but cancellation in the compact form costs more
  iterations than that saves);
* the inner products with the current gradient G, <s_i, G> and <y_i, G>, are carried along by
  recurrence (G changes by y each step, so they change by <s_i, y>, <y_i, y>, which the new
  pair's column of [<s_i, y_j>] needs anyway) and recomputed exactly on ``refresh``;
* the new pair's row <s, y_j> follows from the direction's coefficients and the small matrices.

Everything here runs on backend arrays, the small matrices included: the fast solver updates the
memory before the host has seen the new pair's products, so a pair is stored speculatively
(:meth:`KMetricLBFGS.update`) and the solver confirms it (:meth:`~KMetricLBFGS.confirm`) or takes it back
exactly (:meth:`~KMetricLBFGS.rollback`) once the curvature test's numbers have come over.  The rows of
the pair a full memory evicts are kept in two spare rows until then.
"""
from __future__ import annotations

import numpy as np

from tengsim import backend
from tengsim.solvers import _algebra


class KMetricLBFGS:
    """Ring of m pairs (s, y) and images (K s, K y); slot j lives in rows 2j, 2j + 1, and rows 2m, 2m + 1
    (slot m, :attr:`spare`) hold an evicted pair's rows until its successor is confirmed."""

    def __init__(self, memory: int, n: int, dA: float):
        self.m, self.dA = int(memory), float(dA)
        m = self.m
        self.spare = m
        self.B = backend.empty((2 * m + 2, n))     # s_j, y_j
        self.KB = backend.empty((2 * m + 2, n))    # K s_j, K y_j
        self.SY = backend.zeros((m, m))  # SY[i, j] = <s_i, y_j>, by slot
        self.YY = backend.zeros((m, m))  # YY[i, j] = <y_i, y_j>
        self.pS = backend.zeros(m)       # <s_i, G> for the current gradient G
        self.pY = backend.zeros(m)       # <y_i, G>
        self.order: list[int] = []  # slots, oldest first; the active slots are always 0 .. k-1
        self._last = (1.0, backend.zeros(0), backend.zeros(0))
        self._perm = backend.zeros(0, int)   # active slots in age order (oldest first), as an index array
        self._undo = None  # how to take back the last, unconfirmed pair (:meth:`rollback`)
        self.lines = None  # a weighted problem's deficit pixels (tengsim.solvers._weights): m-weighted products
        self.red = None    # a distributed solve's sums over all ranks (tengsim.solvers._reduce)

    @property
    def empty(self) -> bool:
        return not self.order

    def reset(self) -> None:
        self.order = []
        self._perm = backend.zeros(0, int)
        self._last = (1.0, backend.zeros(0), backend.zeros(0))
        self._undo = None

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
        c is None while the memory is empty (H = identity).  Backend values: nothing comes to the host."""
        k = len(self.order)
        if not k:
            self._last = (1.0, backend.zeros(0), backend.zeros(0))
            return 1.0, None
        xp = backend.xp
        act = self._perm
        new = act[-1]
        gamma = _algebra.newest_gamma(xp, self.SY[new, new], self.YY[new, new])
        # the pairs in age order; the triangular solve reads only SYa's upper triangle (no triu copy needed)
        top, cy = _algebra.compact_coefficients(xp, backend.solve_upper, self.SY[act[:, None], act],
                                                self.YY[act[:, None], act], self.pS[act], self.pY[act], gamma)
        cS = backend.empty(k)
        cY = backend.empty(k)
        cS[act] = top
        cY[act] = cy
        c = backend.empty(2 * k)
        c[0::2], c[1::2] = cS, cY
        self._last = (gamma, cS, cY)
        return gamma, c

    def next_slot(self):
        """(slot, held): the slot the next pair goes to, and the slot whose rows must first be copied to
        the spare rows (the oldest pair, evicted from a full memory), else None."""
        k = len(self.order)
        if k < self.m:
            return k, None
        return self.order[0], self.order[0]

    def update(self, alpha, x, sy, yy, d_rn, y_rn) -> int:
        """After the step s = α d, G ← G + y.  ``x`` = ΔA·B[:2k] @ K y (the rows' products with the
        new y), ``d_rn`` = ΔA d·r_new, ``y_rn`` = ΔA y·r_new, ``sy`` = <s, y>, ``yy`` = <y, y>: backend
        values (host floats do as well).

        Keeps <s_i, G>, <y_i, G> current and stores the pair (s, y) in :meth:`next_slot`'s slot
        (evicting the oldest when full), whose rows B[2 slot] = s, B[2 slot + 1] = y, KB[...] = K s, K y
        the caller fills (and, for a held slot, copies to the spare rows first).  The pair is
        unconfirmed: the caller then calls :meth:`confirm` if the curvature test passes (sy > 0, yy > 0),
        else :meth:`rollback`, which leaves the memory as if the pair had never been stored.
        Returns the slot.
        """
        k = len(self.order)
        if k:
            xs, xy = x[0::2], x[1::2]          # <s_i, y>, <y_i, y>
            gamma, cS, cY = self._last
            # <d, y_j> from d = −(γ G + Σ cS_i s_i + Σ cY_i y_i), with G the old gradient
            dy = _algebra.new_pair_row(gamma, cS, cY, self.SY[:k, :k], self.YY[:k, :k], self.pY[:k]) \
                if cS.size else -self.pY[:k]
            self.pS[:k] += xs
            self.pY[:k] += xy
        slot, held = self.next_slot()
        # a full memory overwrites the evicted slot's entries: keep them (small arrays) to take the pair back
        saved = None if held is None else (self.SY.copy(), self.YY.copy(), self.pS.copy(), self.pY.copy())
        self._undo = (list(self.order), self._perm, saved, held)
        if held is not None:
            self.order.pop(0)
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

    def confirm(self) -> None:
        """The last pair passed the curvature test: it stays, the evicted pair's rows are free."""
        self._undo = None

    def rollback(self) -> None:
        """Take back the last, unconfirmed pair: the memory as :meth:`update` would have left it without
        storing (the products with the old pairs kept current), the evicted pair's rows back in place."""
        order, perm, saved, held = self._undo
        self._undo = None
        self.order, self._perm = order, perm
        if saved is not None:
            for a, b in zip((self.SY, self.YY, self.pS, self.pY), saved):
                a[...] = b
        if held is not None:
            sp = self.spare
            self.B[2 * held:2 * held + 2] = self.B[2 * sp:2 * sp + 2]
            self.KB[2 * held:2 * held + 2] = self.KB[2 * sp:2 * sp + 2]
