"""Pixel weights of a weighted problem (a symmetry-reduced block: each pixel stands for m of the full grid).

With multiplicities m the solvers' sums become Σ m_i a_i b_i.  On a mirror block m is the same
interior value W (2 or 4) everywhere except on the mirror lines (1 or 2): O(√n) pixels.  So a weighted
sum is taken as W × (the plain sum, which the solvers' sweeps already compute) minus W × Σ c_i a_i b_i
over those few pixels only, with c = 1 − m/W: no extra pass over the grid.  The corrections are backend
scalars: the solver brings them to the host with the sweep's own sums.  The factor W goes into
the pixel area (ΔA W), the rest of the algebra is unchanged.
"""
from __future__ import annotations

import numpy as np

from tengsim.errors import TengsimError


class Weights:
    """Multiplicities ``m`` (shape ``shape``) as a scale W = max m and the deficits c = 1 − m/W on the
    pixels where m < W (``idx``, flat indices)."""

    def __init__(self, m, shape):
        m = np.asarray(m, dtype=float)
        if m.shape != tuple(shape):
            raise TengsimError(f"weights of shape {m.shape} do not match the problem's {tuple(shape)}")
        if not (np.all(np.isfinite(m)) and float(m.min()) > 0):
            raise TengsimError("weights must be finite and > 0")
        self.scale = float(m.max())
        s = m.ravel() / self.scale
        self.idx = np.flatnonzero(s != 1.0)
        self.c = 1.0 - s[self.idx]
        self.total = float(s.sum())  # Σ m / W: the weighted pixel count, in units of W

    def dot(self, a, b):
        """Σ c a b over the deficit pixels (subtract from the plain a·b)."""
        i = self.idx
        return np.dot(self.c * a[i], b[i])

    def dots(self, a, *bs) -> list:
        """[Σ c a b for b in bs]: several deficits with one vector (c a on the deficit pixels)."""
        i = self.idx
        ca = self.c * a[i]
        return [np.dot(ca, b[i]) for b in bs]

    def sum(self, a):
        """Σ c a over the deficit pixels (subtract from the plain Σ a)."""
        return np.dot(self.c, a[self.idx])

    def rows(self, B, a, moved=None):
        """B[:, idx] @ (c a[idx]): the deficit of the row products B @ a.  ``moved`` = (j, R): rows
        j, j + 1, ... of B are read from the rows of R instead (rows kept aside while B's are overwritten)."""
        i = self.idx
        Bi = B[:, i]
        if moved is not None:
            j, R = moved
            Bi[j:j + len(R)] = R[:, i]
        return Bi @ (self.c * a[i])
