"""Maugis–Dugdale sphere (Maugis 1992; Johnson & Greenwood 1997): the JKR–DMT transition with the
Tabor parameter, curves and pull-off.

Units and conventions: :mod:`tengsim.references.common`.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tengsim.errors import TengsimError, positive


# ----------------------------------------------------------------------------
# Maugis-Dugdale (Maugis 1992; Johnson & Greenwood 1997 Eqs. 3-5)
# ----------------------------------------------------------------------------

@dataclass(frozen=True)
class MDScales:
    """Maugis-Dugdale scales: A = a/length, P = F/force, D = delta/indentation (all [m] or [N])."""

    length: float
    force: float
    indentation: float


@dataclass(frozen=True)
class MDCurve:
    """Maugis-Dugdale curve (dimensionless), sorted by increasing A.

    A = contact radius, P = load, D = indentation, m = c/a (adhesive-zone
    radius over contact radius), lam = Maugis parameter.
    """

    lam: float
    A: np.ndarray
    P: np.ndarray
    D: np.ndarray
    m: np.ndarray


@dataclass(frozen=True)
class MDPoint:
    """One Maugis-Dugdale state (dimensionless A, P, D, m) at parameter lam."""

    lam: float
    A: float
    P: float
    D: float
    m: float


def md_scales(R, E_star, W) -> MDScales:
    """MD scales with K = 4E*/3: length (pi W R^2/K)^(1/3), force pi W R, indentation (pi^2 W^2 R/K^2)^(1/3). Maugis (1992)."""
    R, E_star, W = positive("R", R), positive("E_star", E_star), positive("W", W)
    K = 4.0 * E_star / 3.0
    return MDScales(float(np.cbrt(np.pi * W * R ** 2 / K)), float(np.pi * W * R),
                    float(np.cbrt(np.pi ** 2 * W ** 2 * R / K ** 2)))


def md_lambda(R, E_star, W, sigma0) -> float:
    """Maugis parameter lambda = 2 sigma0 (R/(pi W K^2))^(1/3) = sigma0 (9R/(2 pi W E*^2))^(1/3), K = 4E*/3.

    sigma0 [Pa] is the Dugdale cohesive stress (range h0 = W/sigma0).
    Maugis (1992) Eq. 6.17; Johnson & Greenwood (1997) Eq. 2.
    """
    R, E_star, W = positive("R", R), positive("E_star", E_star), positive("W", W)
    return float(positive("sigma0", sigma0) * np.cbrt(9.0 * R / (2.0 * np.pi * W * E_star ** 2)))


def _md_f(s):
    """f(s) = s + (m^2-2) arctan s with s = sqrt(m^2-1); series below s = 0.05 (leading (4/3)s^3)."""
    s = np.asarray(s, float)
    big = s + (s * s - 1.0) * np.arctan(s)
    s2 = s * s
    # series sum_{k>=1} (-1)^(k+1) 4k/(4k^2-1) s^(2k+1), used for s < 0.05
    small = s ** 3 * (4.0 / 3.0 - s2 * (8.0 / 15.0 - s2 * (12.0 / 35.0 - s2 * (16.0 / 63.0 - s2 * 20.0 / 99.0))))
    return np.where(s < 0.05, small, big)


def _md_g(s):
    """g(s) = s arctan s - (m - 1), m = sqrt(1+s^2); ~ s^2/2 for small s, no cancellation."""
    s = np.asarray(s, float)
    return s * np.arctan(s) - s * s / (1.0 + np.sqrt(1.0 + s * s))


def _md_A_of_s(lam, s):
    """Positive root A of (lam/2) f A^2 + (4 lam^2/3) g A - 1 = 0 (Johnson & Greenwood 1997 Eq. 3)."""
    al = 0.5 * lam * _md_f(s)
    be = 4.0 * lam ** 2 / 3.0 * _md_g(s)
    return 2.0 / (be + np.sqrt(be * be + 4.0 * al))


def _md_state(lam, s):
    s = np.asarray(s, float)
    A = _md_A_of_s(lam, s)
    m = np.sqrt(1.0 + s * s)
    P = A ** 3 - lam * A ** 2 * (s + m * m * np.arctan(s))
    D = A ** 2 - 4.0 / 3.0 * A * lam * s
    return A, P, D, m


def _md_s_of_A(lam, A, iters=200):
    """Invert the monotone decreasing A(s) by vectorised bisection in log s."""
    A = np.asarray(A, float)
    lo = np.full(A.shape, np.log(1e-16))
    hi = np.full(A.shape, np.log(1e16))
    for _ in range(iters):
        mid = 0.5 * (lo + hi)
        too_big = _md_A_of_s(lam, np.exp(mid)) > A   # A(s) too large -> s must grow
        lo = np.where(too_big, mid, lo)
        hi = np.where(too_big, hi, mid)
        if np.all(hi - lo < 1e-14):
            break
    return np.exp(0.5 * (lo + hi))


def maugis_dugdale_m(lam, A):
    """m = c/a of the Maugis-Dugdale model at parameter lam and contact radius A (solves J&G 1997 Eq. 3).

    The left side of Eq. 3 increases monotonically with m at fixed A, so the
    root is unique; found by bisection. Dimensionless.
    """
    lam = positive("lam", lam)
    A = np.asarray(A, float)
    if np.any(~(A > 0)):
        raise TengsimError("A must be > 0")
    return np.sqrt(1.0 + _md_s_of_A(lam, A) ** 2)


def maugis_dugdale_curve(lam, A_max=3.0, n=400, A_min=None) -> MDCurve:
    """Maugis-Dugdale load/indentation curve (dimensionless) for A in [A_min, A_max].

    Equations (Maugis 1992; Johnson & Greenwood 1997 Eqs. 3-5), s = sqrt(m^2-1)::

      (lam A^2/2)[s + (m^2-2) atan s] + (4 lam^2 A/3)[s atan s - m + 1] = 1,
      P = A^3 - lam A^2 [s + m^2 atan s],   D = A^2 - (4/3) A lam s.

    For each A (uniform grid, A_min default A_max/n) m is found by bisection,
    which is robust for all lam > 0. Dimensional values: multiply by
    :func:`md_scales`.
    """
    lam = positive("lam", lam)
    A_max = positive("A_max", A_max)
    A_min = A_max / n if A_min is None else positive("A_min", A_min)
    if not A_min < A_max or int(n) < 2:
        raise TengsimError("need A_min < A_max and n >= 2")
    A = np.linspace(A_min, A_max, int(n))
    s = _md_s_of_A(lam, A)
    A2, P, D, m = _md_state(lam, s)
    return MDCurve(lam, A2, P, D, m)


def _md_P_at_zero_area(lam):
    """lim P as A -> 0 (m -> inf, c finite): P = -(pi lam/2) C^2 with (pi lam/4)C^2 + (4lam^2/3)(pi/2-1)C = 1."""
    a2 = np.pi * lam / 4.0
    b1 = 4.0 * lam ** 2 / 3.0 * (np.pi / 2.0 - 1.0)
    C = 2.0 / (b1 + np.sqrt(b1 * b1 + 4.0 * a2))
    return -0.5 * np.pi * lam * C * C


def maugis_dugdale_pulloff_point(lam) -> MDPoint:
    """State at the load-controlled Maugis-Dugdale pull-off (minimum of P over the curve).

    The minimum is searched over the whole branch A in (0, inf); for small lam
    it lies at A -> 0 (m -> inf, adhesive zone of finite radius), where the
    limit is taken analytically (returned with A = 0, m = inf). Maugis (1992);
    Johnson & Greenwood (1997).
    """
    from scipy.optimize import minimize_scalar

    lam = positive("lam", lam)
    u = np.linspace(np.log(1e-7), np.log(1e9), 1601)       # u = log s
    A, P, D, m = _md_state(lam, np.exp(u))
    i = int(np.argmin(P))
    best = MDPoint(lam, 0.0, float(_md_P_at_zero_area(lam)), 0.0, float("inf"))
    if 0 < i < u.size - 1:
        res = minimize_scalar(lambda v: float(_md_state(lam, np.exp(v))[1]),
                              bounds=(u[i - 1], u[i + 1]), method="bounded",
                              options={"xatol": 1e-10})
        A1, P1, D1, m1 = (float(x) for x in _md_state(lam, np.exp(res.x)))
        if P1 < best.P:
            best = MDPoint(lam, A1, P1, D1, m1)
    elif i == 0:
        raise TengsimError(f"lam={lam} too large for the pull-off search (s range)")
    return best


def maugis_dugdale_pulloff(lam) -> float:
    """Load-controlled Maugis-Dugdale pull-off -min(P) = |F_po|/(pi W R): 2 (DMT, lam->0) to 1.5 (JKR, lam->inf).

    Dimensionless; multiply by pi W R for the force [N]. Maugis (1992);
    Johnson & Greenwood (1997) Fig. 2.
    """
    return -maugis_dugdale_pulloff_point(lam).P


def tabor_parameter(R, W, E_star, eps) -> float:
    """Tabor parameter mu = (R W^2/(E*^2 eps^3))^(1/3); eps [m] equilibrium spacing. Tabor (1977)."""
    R, W = positive("R", R), positive("W", W)
    E_star, eps = positive("E_star", E_star), positive("eps", eps)
    return float(np.cbrt(R * W ** 2 / (E_star ** 2 * eps ** 3)))


def md_lambda_from_tabor(mu) -> float:
    """Maugis lambda = 1.157 mu (Greenwood 1997; Johnson & Greenwood 1997).

    Obtained by setting the Dugdale stress sigma0 to the maximum stress
    16W/(9 sqrt(3) eps) of the Lennard-Jones 9-3 (Derjaguin) law, so
    h0 = W/sigma0 = 0.97 eps and 1.157 = (16/(9 sqrt 3)) (9/(2 pi))^(1/3).
    Note this holds for lambda defined with K = 4E*/3 as in :func:`md_lambda`.
    """
    return float(16.0 / (9.0 * np.sqrt(3.0)) * np.cbrt(9.0 / (2.0 * np.pi)) * positive("mu", mu))


def maugis_dugdale_pulloff_from_tabor(mu) -> float:
    """MD pull-off -min(P) (times pi W R) at lam = 1.157 mu (:func:`md_lambda_from_tabor`). Dimensionless."""
    return maugis_dugdale_pulloff(md_lambda_from_tabor(mu))
