"""Compact limited-memory BFGS inverse Hessian in the elastic (K) inner product.

Byrd, Nocedal & Schnabel (1994), Eq. (3.1)-(3.2): with m pairs (s_i, y_i), γ = <s,y>/<y,y> of the
newest pair, R the upper triangle of [<s_i, y_j>], D its diagonal,

    H v = γ v + S top − γ Y u,   u = R⁻¹ (S^T v),   top = R^{-T}((D + γ Y^T Y) u − γ Y^T v),

where S^T v means the vector of <s_i, v> = ΔA s_i·K v.  Every stored vector is kept beside its image
K s_i, K y_i, so H v and K H v come from a few matrix–vector products over the m × n buffers (BLAS,
one pass each) and no convolution.  The m × m inner-product matrices are updated in O(m n) per pair.
"""
from __future__ import annotations

import numpy as np
from scipy.linalg import solve_triangular


class KMetricLBFGS:
    """Ring buffers of (s, K s, y, K y) and their inner products; ``direction`` returns (H v, K H v)."""

    def __init__(self, memory: int, n: int, dA: float):
        self.m, self.dA = int(memory), float(dA)
        self.S = np.empty((self.m, n))
        self.KS = np.empty((self.m, n))
        self.Y = np.empty((self.m, n))
        self.KY = np.empty((self.m, n))
        self.SY = np.zeros((self.m, self.m))  # SY[i, j] = <s_i, y_j>, by slot
        self.YY = np.zeros((self.m, self.m))  # YY[i, j] = <y_i, y_j>
        self.order: list[int] = []            # slots, oldest first

    @property
    def empty(self) -> bool:
        return not self.order

    def reset(self) -> None:
        self.order = []

    def push(self, s, ks, y, ky) -> None:
        """Store a pair (flat arrays); the caller has checked <s, y> > 0."""
        # not full: the active slots are 0 .. len-1 (reset empties all); full: reuse the oldest
        slot = len(self.order) if len(self.order) < self.m else self.order.pop(0)
        self.S[slot], self.KS[slot], self.Y[slot], self.KY[slot] = s, ks, y, ky
        self.order.append(slot)
        k = self._k()
        dA = self.dA
        # <s_i, y> = dA s_i·K y ; <s, y_j> = dA s·K y_j ; <y_i, y> = dA y_i·K y
        self.SY[:k, slot] = dA * (self.S[:k] @ ky)
        self.SY[slot, :k] = dA * (self.KY[:k] @ s)
        yy = dA * (self.Y[:k] @ ky)
        self.YY[:k, slot] = yy
        self.YY[slot, :k] = yy

    def _k(self) -> int:
        return len(self.order)

    def direction(self, v, Kv):
        """(H v, K H v) for flat v and its image K v."""
        if not self.order:
            return v.copy(), Kv.copy()
        k, dA, act = self._k(), self.dA, self.order
        new = act[-1]
        yy = self.YY[new, new]
        gamma = self.SY[new, new] / yy if yy > 0 else 1.0
        pS = dA * (self.S[:k] @ Kv)   # <s_i, v>, by slot
        pY = dA * (self.Y[:k] @ Kv)   # <y_i, v>
        ix = np.ix_(act, act)
        R = np.triu(self.SY[ix])
        Dg = np.diag(np.diag(self.SY[ix]))
        u = solve_triangular(R, pS[act], lower=False)
        top = solve_triangular(R, (Dg + gamma * self.YY[ix]) @ u - gamma * pY[act], trans="T", lower=False)
        cS = np.zeros(k)
        cY = np.zeros(k)
        cS[act] = top
        cY[act] = -gamma * u
        Hv = gamma * v + cS @ self.S[:k] + cY @ self.Y[:k]
        KHv = gamma * Kv + cS @ self.KS[:k] + cY @ self.KY[:k]
        return Hv, KHv
