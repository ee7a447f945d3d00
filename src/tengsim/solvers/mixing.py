"""Anderson mixing (type II) of a fixed point x = G(x): the one least-squares fit of the residual f = G(x) − x by the
stored differences of residuals, used by the ``pk`` solver's cohesive zone (its outer loop and its in-loop mixing,
:mod:`tengsim.solvers._pk_zone`) and by the periodic steady state of a viscoelastic press
(:mod:`tengsim.visco.periodic`)."""
from __future__ import annotations

import math

import numpy as np


def mixing_coefficients(A, Ftf):
    """γ minimising |f − ΔF γ| from its normal equations, ``A`` = ΔFᵀΔF (m × m) and ``Ftf`` = ΔFᵀf, scaled to a
    unit diagonal and solved by least squares (rcond 1e-10: a difference that repeats another is dropped)."""
    d = np.sqrt(np.maximum(np.diag(A), 1e-300))
    return np.linalg.lstsq(A / np.outer(d, d), Ftf / d, rcond=1e-10)[0] / d


class Anderson:
    """Anderson mixing (type II, memory ``m``) of a fixed point x = G(x) (a cohesive zone's tractions in the outer
    loop of tengsim.solvers.pk.PKSolver._cohesive; a period's start memory in tengsim.visco.periodic):
    ``step(x, gx)`` moves x in place to x + f − (ΔX + ΔF) γ, γ the least-squares fit of f = G(x) − x
    by the stored differences (m = 0: the plain update x = G(x)).  Memory is dropped when the residual
    grows tenfold (a jump: the old differences describe another branch)."""

    def __init__(self, n: int, m: int):
        self.m, self.X, self.F = int(m), [], []
        self.x_old = self.f_old = None
        self.f_norm = math.inf

    def step(self, x, gx):
        f = gx - x
        fn = float(np.dot(f, f))
        if fn > 100.0 * self.f_norm:
            self.X, self.F = [], []
        self.f_norm = fn
        if self.m and self.x_old is not None:
            self.X.append(x - self.x_old)
            self.F.append(f - self.f_old)
            if len(self.X) > self.m:
                self.X.pop(0)
                self.F.pop(0)
        self.x_old, self.f_old = x.copy(), f
        if not self.F:
            x += f
            return
        Fm = np.stack(self.F, axis=1)
        gamma = mixing_coefficients(Fm.T @ Fm, Fm.T @ f)
        x += f - (np.stack(self.X, axis=1) + Fm) @ gamma
