"""Stability of an equilibrium: is the energy Hessian positive definite?

With E(q) = ΔA[½ q·Kq + Σ Φ(g0 + Kq)] the Hessian is ΔA (K + K diag(Φ'') K).  Relative to the
elastic metric ΔA K its eigenvalues are those of I + K^{1/2} Φ'' K^{1/2}: all equal to 1 without
interaction, and the state is stable (a local energy minimum) exactly when the smallest is > 0.
Solved densely (generalised symmetric eigenproblem), so for small grids (spot checks, tests).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tengsim.errors import TengsimError

MAX_PIXELS = 3000


@dataclass(frozen=True)
class StabilityReport:
    min_eigenvalue: float   # smallest eigenvalue of I + K^{1/2} Φ'' K^{1/2}
    stable: bool


def kernel_matrix(kernel) -> np.ndarray:
    """Dense matrix of the kernel (column j = K e_j); n convolutions."""
    n = kernel.grid.nx * kernel.grid.ny
    if n > MAX_PIXELS:
        raise TengsimError(f"stability check is dense: {n} pixels is more than {MAX_PIXELS}")
    M = np.empty((n, n))
    e = np.zeros(kernel.grid.shape)
    for j in range(n):
        e.flat[j] = 1.0
        M[:, j] = kernel.apply(e).ravel()
        e.flat[j] = 0.0
    return 0.5 * (M + M.T)


def hessian_min_eigenvalue(problem, H: np.ndarray, Kmat: np.ndarray | None = None) -> StabilityReport:
    """Smallest eigenvalue of I + K^{1/2} Φ''(H + 1) K^{1/2} at the state with gap H."""
    from scipy.linalg import eigh

    K = kernel_matrix(problem.kernel) if Kmat is None else Kmat
    stiff = problem.law.stiffness(H + 1.0).ravel()
    A = K + K @ (stiff[:, None] * K)
    k = problem.kernel
    if getattr(k, "pinned_mean", k.periodic):  # drop the mean mode (K is singular there)
        n = K.shape[0]
        Q = np.linalg.qr(np.hstack([np.ones((n, 1)), np.eye(n)[:, : n - 1]]))[0][:, 1:]
        A, K = Q.T @ A @ Q, Q.T @ K @ Q
    lam = eigh(A, K, eigvals_only=True, subset_by_index=[0, 0])[0]
    return StabilityReport(float(lam), bool(lam > 0))
