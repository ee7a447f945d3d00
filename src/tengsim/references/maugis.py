"""Closed-form and semi-analytic reference solutions of contact mechanics.

Plain functions for checking numerical solvers. Units are consistent but
arbitrary (SI recommended): lengths [m], forces [N], moduli and pressures [Pa],
work of adhesion W [J/m^2 = N/m].

Conventions
-----------
* ``E_star`` is the contact modulus, 1/E* = (1-nu1^2)/E1 + (1-nu2^2)/E2
  (use :func:`effective_modulus`).  For a single half-space against a rigid
  body, E* = E/(1-nu^2).
* Indentation ``delta`` > 0 means approach (compression); force ``F`` > 0 is
  compressive; pressure ``p`` > 0 is compressive.
* Maugis-Dugdale quantities use the Maugis (1992) / Johnson & Greenwood (1997)
  scales with K = 4E*/3:  A = a (K/(pi W R^2))^(1/3),  P = F/(pi W R),
  D = delta (K^2/(pi^2 W^2 R))^(1/3),  lambda = 2 sigma0 (R/(pi W K^2))^(1/3).

Sources: K.L. Johnson, *Contact Mechanics* (CUP 1985); Johnson, Kendall &
Roberts, Proc. R. Soc. A 324 (1971) 301; Derjaguin, Muller & Toporov, JCIS 53
(1975) 314; D. Maugis, JCIS 150 (1992) 243; K.L. Johnson & J.A. Greenwood,
JCIS 192 (1997) 326; J.A. Greenwood, Proc. R. Soc. A 453 (1997) 1277;
I.N. Sneddon, Int. J. Eng. Sci. 3 (1965) 47; K.L. Johnson, Int. J. Solids
Struct. 32 (1995) 423; A.E.H. Love, Phil. Trans. A 228 (1929) 377.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .errors import TengsimError, positive

__all__ = [
    "effective_modulus",
    "hertz_contact_radius", "hertz_force", "hertz_indentation",
    "hertz_contact_radius_from_force", "hertz_peak_pressure", "hertz_pressure",
    "JKRPoint", "jkr_force", "jkr_indentation", "jkr_contact_radius",
    "jkr_pulloff", "jkr_pulloff_fixed_grips", "jkr_zero_load_radius",
    "dmt_force", "dmt_contact_radius", "dmt_pulloff_force",
    "MDScales", "MDCurve", "MDPoint", "md_scales", "md_lambda",
    "maugis_dugdale_m", "maugis_dugdale_curve", "maugis_dugdale_pulloff",
    "maugis_dugdale_pulloff_point", "tabor_parameter", "md_lambda_from_tabor",
    "maugis_dugdale_pulloff_from_tabor",
    "cone_theta_from_half_angle", "sneddon_cone_contact_radius",
    "sneddon_cone_indentation", "sneddon_cone_force", "sneddon_cone_pressure",
    "flat_punch_force", "flat_punch_pressure",
    "westergaard_complete_contact_pressure", "westergaard_contact_half_width",
    "westergaard_mean_pressure", "westergaard_pressure",
    "johnson_sinusoid_alpha", "johnson_sinusoid_mean_pressure",
    "rectangle_displacement",
]


def _nonneg(name: str, value) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise TengsimError(f"{name} must be a number, got {value!r}") from None
    if not (v >= 0 and v < float("inf")):
        raise TengsimError(f"{name} must be finite and >= 0, got {value!r}")
    return v


def effective_modulus(E1, nu1, E2=np.inf, nu2=0.0) -> float:
    """Contact modulus E* [Pa]: 1/E* = (1-nu1^2)/E1 + (1-nu2^2)/E2.

    E2 = inf (default) is a rigid counter-body. Johnson (1985) Eq. 4.22.
    """
    E1 = positive("E1", E1)
    inv = (1.0 - float(nu1) ** 2) / E1
    if np.isfinite(E2):
        inv += (1.0 - float(nu2) ** 2) / positive("E2", E2)
    if not inv > 0:
        raise TengsimError("Poisson ratios must satisfy |nu| < 1")
    return 1.0 / inv


# ----------------------------------------------------------------------------
# Hertz (sphere of radius R on a flat; Johnson 1985 Sec. 4.2, Eqs. 4.22-4.23)
# ----------------------------------------------------------------------------

def hertz_contact_radius(delta, R):
    """Hertz contact radius a = sqrt(R delta) [m]; delta [m], R [m]. Johnson (1985) Eq. 4.22."""
    R = positive("R", R)
    return np.sqrt(R * np.maximum(np.asarray(delta, float), 0.0))


def hertz_force(delta, R, E_star):
    """Hertz force F = (4/3) E* R^(1/2) delta^(3/2) [N] (0 for delta <= 0). Johnson (1985) Eq. 4.23."""
    R, E_star = positive("R", R), positive("E_star", E_star)
    d = np.maximum(np.asarray(delta, float), 0.0)
    return 4.0 / 3.0 * E_star * np.sqrt(R) * d ** 1.5


def hertz_indentation(F, R, E_star):
    """Hertz indentation delta = (3F/(4 E* R^(1/2)))^(2/3) [m]; F [N] >= 0. Johnson (1985) Eq. 4.23."""
    R, E_star = positive("R", R), positive("E_star", E_star)
    F = np.maximum(np.asarray(F, float), 0.0)
    return (3.0 * F / (4.0 * E_star * np.sqrt(R))) ** (2.0 / 3.0)


def hertz_contact_radius_from_force(F, R, E_star):
    """Hertz contact radius a = (3FR/(4E*))^(1/3) [m]; F [N] >= 0. Johnson (1985) Eq. 4.22."""
    R, E_star = positive("R", R), positive("E_star", E_star)
    F = np.maximum(np.asarray(F, float), 0.0)
    return np.cbrt(3.0 * F * R / (4.0 * E_star))


def hertz_peak_pressure(a, R, E_star):
    """Hertz maximum pressure p0 = 2E*a/(pi R) [Pa] (= 3F/(2 pi a^2)). Johnson (1985) Eq. 4.22."""
    R, E_star = positive("R", R), positive("E_star", E_star)
    return 2.0 * E_star * np.asarray(a, float) / (np.pi * R)


def hertz_pressure(r, a, R, E_star):
    """Hertz pressure p(r) = p0 sqrt(1 - r^2/a^2) for r < a, else 0 [Pa]; r, a [m]. Johnson (1985) Eq. 4.22."""
    a = positive("a", a)
    p0 = hertz_peak_pressure(a, R, E_star)
    r = np.abs(np.asarray(r, float))
    return p0 * np.sqrt(np.clip(1.0 - (r / a) ** 2, 0.0, None))


# ----------------------------------------------------------------------------
# JKR (Johnson, Kendall & Roberts 1971; Johnson 1985 Sec. 5.5, Eqs. 5.60-5.63)
# ----------------------------------------------------------------------------

@dataclass(frozen=True)
class JKRPoint:
    """A point of the JKR curve: force [N], contact radius [m], indentation [m]."""

    force: float
    contact_radius: float
    indentation: float


def jkr_force(a, R, E_star, W):
    """JKR force F(a) = 4E*a^3/(3R) - sqrt(8 pi W E* a^3) [N]; a [m], W [J/m^2]. Johnson (1985) Eq. 5.60."""
    R, E_star, W = positive("R", R), positive("E_star", E_star), _nonneg("W", W)
    a = np.asarray(a, float)
    return 4.0 * E_star * a ** 3 / (3.0 * R) - np.sqrt(8.0 * np.pi * W * E_star * a ** 3)


def jkr_indentation(a, R, E_star, W):
    """JKR indentation delta(a) = a^2/R - sqrt(2 pi W a/E*) [m]. Johnson (1985) Eq. 5.61 / Maugis (2000)."""
    R, E_star, W = positive("R", R), positive("E_star", E_star), _nonneg("W", W)
    a = np.asarray(a, float)
    return a ** 2 / R - np.sqrt(2.0 * np.pi * W * a / E_star)


def jkr_contact_radius(F, R, E_star, W, branch="stable"):
    """JKR contact radius a(F) [m], exact inverse of :func:`jkr_force`.

    With x = a^(3/2): (4E*/(3R)) x^2 - sqrt(8 pi W E*) x - F = 0, so
    a^3 = (R/K)[F + 3 pi W R +/- sqrt(6 pi W R F + (3 pi W R)^2)], K = 4E*/3
    (Johnson 1985 Eq. 5.62). ``branch='stable'`` takes '+', ``'unstable'``
    takes '-' (only for -1.5 pi W R <= F <= 0). NaN where no solution exists
    (F < -1.5 pi W R).
    """
    R, E_star, W = positive("R", R), positive("E_star", E_star), _nonneg("W", W)
    F = np.asarray(F, float)
    k = 4.0 * E_star / (3.0 * R)
    b = np.sqrt(8.0 * np.pi * W * E_star)
    disc = b * b + 4.0 * k * F
    with np.errstate(invalid="ignore"):
        root = np.sqrt(disc)
        if branch == "stable":
            x = (b + root) / (2.0 * k)
        elif branch == "unstable":
            x = (b - root) / (2.0 * k)
            x = np.where(x >= 0.0, x, np.nan)
        else:
            raise TengsimError(f"branch must be 'stable' or 'unstable', got {branch!r}")
    return np.where(disc >= 0.0, x, np.nan) ** (2.0 / 3.0)


def jkr_pulloff(R, E_star, W) -> JKRPoint:
    """JKR load-controlled pull-off: F = -1.5 pi W R, a = (9 pi W R^2/(8E*))^(1/3). Johnson (1985) Eq. 5.63."""
    R, E_star, W = positive("R", R), positive("E_star", E_star), positive("W", W)
    a = np.cbrt(9.0 * np.pi * W * R ** 2 / (8.0 * E_star))
    return JKRPoint(float(-1.5 * np.pi * W * R), float(a), float(jkr_indentation(a, R, E_star, W)))


def jkr_pulloff_fixed_grips(R, E_star, W) -> JKRPoint:
    """JKR displacement-controlled pull-off: F = -(5/6) pi W R, a = (pi W R^2/(8E*))^(1/3) (d delta/da = 0)."""
    R, E_star, W = positive("R", R), positive("E_star", E_star), positive("W", W)
    a = np.cbrt(np.pi * W * R ** 2 / (8.0 * E_star))
    return JKRPoint(float(jkr_force(a, R, E_star, W)), float(a), float(jkr_indentation(a, R, E_star, W)))


def jkr_zero_load_radius(R, E_star, W) -> float:
    """JKR contact radius at zero load a0 = (9 pi W R^2/(2E*))^(1/3) [m]. Johnson (1985) Eq. 5.62 at F = 0."""
    R, E_star, W = positive("R", R), positive("E_star", E_star), _nonneg("W", W)
    return float(np.cbrt(9.0 * np.pi * W * R ** 2 / (2.0 * E_star)))


# ----------------------------------------------------------------------------
# DMT (Derjaguin, Muller & Toporov 1975)
# ----------------------------------------------------------------------------

def dmt_force(delta, R, E_star, W):
    """DMT force F = (4/3)E* R^(1/2) delta^(3/2) - 2 pi R W [N] for delta >= 0 (Hertz profile). DMT (1975)."""
    W = _nonneg("W", W)
    return hertz_force(delta, R, E_star) - 2.0 * np.pi * positive("R", R) * W


def dmt_contact_radius(F, R, E_star, W):
    """DMT contact radius a = (3R(F + 2 pi R W)/(4E*))^(1/3) [m]; 0 below F = -2 pi R W. DMT (1975)."""
    R, W = positive("R", R), _nonneg("W", W)
    return hertz_contact_radius_from_force(np.asarray(F, float) + 2.0 * np.pi * R * W, R, E_star)


def dmt_pulloff_force(R, W) -> float:
    """DMT pull-off force -2 pi R W [N]. Derjaguin, Muller & Toporov (1975)."""
    return float(-2.0 * np.pi * positive("R", R) * positive("W", W))


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


# ----------------------------------------------------------------------------
# Sneddon rigid cone (Sneddon 1965; Johnson 1985 Sec. 5.6)
# ----------------------------------------------------------------------------

def cone_theta_from_half_angle(alpha) -> float:
    """Surface inclination theta = pi/2 - alpha [rad] of a cone with semi-angle alpha (from its axis) [rad]."""
    alpha = float(alpha)
    if not 0.0 < alpha < 0.5 * np.pi:
        raise TengsimError(f"alpha must be in (0, pi/2), got {alpha!r}")
    return 0.5 * np.pi - alpha


def _theta(theta):
    theta = float(theta)
    if not 0.0 < theta < 0.5 * np.pi:
        raise TengsimError(f"theta (inclination from the surface) must be in (0, pi/2), got {theta!r}")
    return theta


def sneddon_cone_contact_radius(delta, theta):
    """Cone contact radius a = 2 delta/(pi tan theta) [m]; theta = flank inclination to the surface [rad]. Sneddon (1965)."""
    t = np.tan(_theta(theta))
    return 2.0 * np.maximum(np.asarray(delta, float), 0.0) / (np.pi * t)


def sneddon_cone_indentation(a, theta):
    """Cone indentation delta = (pi/2) a tan theta [m]; theta from the surface [rad]. Johnson (1985) Eq. 5.40."""
    return 0.5 * np.pi * np.asarray(a, float) * np.tan(_theta(theta))


def sneddon_cone_force(delta, E_star, theta):
    """Cone force F = (2/pi) E* delta^2/tan theta = (pi/2) E* a^2 tan theta [N]; theta from the surface. Sneddon (1965)."""
    E_star, t = positive("E_star", E_star), np.tan(_theta(theta))
    d = np.maximum(np.asarray(delta, float), 0.0)
    return 2.0 / np.pi * E_star * d ** 2 / t


def sneddon_cone_pressure(r, a, E_star, theta):
    """Cone pressure p(r) = (E* tan theta/2) arccosh(a/r) for 0 < r < a, else 0 [Pa]. Johnson (1985) Eq. 5.42."""
    a, E_star, t = positive("a", a), positive("E_star", E_star), np.tan(_theta(theta))
    r = np.abs(np.asarray(r, float))
    with np.errstate(divide="ignore"):
        x = np.where(r < a, a / np.where(r > 0, r, 1.0), 1.0)
        x = np.where(r > 0, x, np.inf)
    return 0.5 * E_star * t * np.arccosh(x)


# ----------------------------------------------------------------------------
# Rigid flat circular punch (Boussinesq; Johnson 1985 Sec. 3.8)
# ----------------------------------------------------------------------------

def flat_punch_force(delta, a, E_star):
    """Flat-punch force F = 2 a E* delta [N]; a [m] punch radius. Johnson (1985) Eq. 3.35."""
    return 2.0 * positive("a", a) * positive("E_star", E_star) * np.asarray(delta, float)


def flat_punch_pressure(r, a, F):
    """Flat-punch pressure p(r) = F/(2 pi a sqrt(a^2 - r^2)) for r < a, else 0 [Pa]. Johnson (1985) Eq. 3.34."""
    a = positive("a", a)
    r = np.abs(np.asarray(r, float))
    inside = r < a
    q = np.where(inside, a * a - r * r, 1.0)
    return np.where(inside, float(F) / (2.0 * np.pi * a * np.sqrt(q)), 0.0)


# ----------------------------------------------------------------------------
# Westergaard 1-D sinusoid, non-adhesive (Johnson 1985 Sec. 13.2; Johnson 1995)
# Surface h(x) = Delta (1 - cos(2 pi x / wavelength)): amplitude Delta,
# peak-to-valley 2 Delta; x measured from the crest.
# ----------------------------------------------------------------------------

def westergaard_complete_contact_pressure(wavelength, amplitude, E_star) -> float:
    """Mean pressure for complete contact p* = pi E* Delta/wavelength [Pa]. Johnson (1985) Eq. 13.6."""
    return float(np.pi * positive("E_star", E_star) * positive("amplitude", amplitude)
                 / positive("wavelength", wavelength))


def westergaard_mean_pressure(a, wavelength, amplitude, E_star):
    """Mean pressure p = p* sin^2(pi a/wavelength) [Pa] at contact half-width a [m]. Johnson (1985) Eq. 13.12."""
    p_star = westergaard_complete_contact_pressure(wavelength, amplitude, E_star)
    a = np.clip(np.asarray(a, float), 0.0, 0.5 * wavelength)
    return p_star * np.sin(np.pi * a / wavelength) ** 2


def westergaard_contact_half_width(p_mean, wavelength, amplitude, E_star):
    """Contact half-width a = (wavelength/pi) arcsin sqrt(p/p*) [m]; wavelength/2 for p >= p*. Johnson (1985) Eq. 13.12."""
    p_star = westergaard_complete_contact_pressure(wavelength, amplitude, E_star)
    q = np.clip(np.asarray(p_mean, float) / p_star, 0.0, 1.0)
    return wavelength / np.pi * np.arcsin(np.sqrt(q))


def westergaard_pressure(x, p_mean, wavelength, amplitude, E_star):
    """Westergaard pressure [Pa] at x [m] (periodic; x = 0 at a crest).

    p < p*: p(x) = (2p/sin^2 psi_a) cos(pi x/wavelength) sqrt(sin^2 psi_a - sin^2(pi x/wavelength))
    for |x| < a (psi_a = pi a/wavelength), 0 elsewhere; p >= p*:
    p(x) = p + p* cos(2 pi x/wavelength). Johnson (1985) Eqs. 13.9-13.11.
    """
    wavelength = positive("wavelength", wavelength)
    p_star = westergaard_complete_contact_pressure(wavelength, amplitude, E_star)
    p_mean = positive("p_mean", p_mean)
    x = np.asarray(x, float)
    xr = x - wavelength * np.round(x / wavelength)       # reduce to [-wl/2, wl/2]
    if p_mean >= p_star:
        return p_mean + p_star * np.cos(2.0 * np.pi * xr / wavelength)
    S2 = p_mean / p_star                                   # sin^2(psi_a)
    sx = np.sin(np.pi * xr / wavelength)
    q = S2 - sx * sx
    return np.where(q > 0, 2.0 * p_mean / S2 * np.cos(np.pi * xr / wavelength)
                    * np.sqrt(np.clip(q, 0.0, None)), 0.0)


def johnson_sinusoid_alpha(wavelength, amplitude, E_star, W) -> float:
    """Johnson (1995) adhesion parameter alpha = sqrt(2 W wavelength/(pi^2 E* Delta^2)) (dimensionless)."""
    wavelength, amplitude = positive("wavelength", wavelength), positive("amplitude", amplitude)
    E_star, W = positive("E_star", E_star), _nonneg("W", W)
    return float(np.sqrt(2.0 * W * wavelength / (np.pi ** 2 * E_star * amplitude ** 2)))


def johnson_sinusoid_mean_pressure(a, wavelength, amplitude, E_star, W):
    """JKR-type adhesive 1-D sinusoid: p/p* = sin^2 psi - alpha sqrt(tan psi), psi = pi a/wavelength.

    Westergaard pressure plus the periodic strip-punch term
    p1 cos(pi x/wl)/sqrt(sin^2 psi - sin^2(pi x/wl)) whose edge stress
    intensity satisfies K^2/(2E*) = W, giving p1 = -sqrt(2 E* W tan(psi)/wl).
    Returns p [Pa] for contact half-width a in (0, wavelength/2). Johnson (1995).
    """
    p_star = westergaard_complete_contact_pressure(wavelength, amplitude, E_star)
    al = johnson_sinusoid_alpha(wavelength, amplitude, E_star, W)
    psi = np.pi * np.asarray(a, float) / wavelength
    return p_star * (np.sin(psi) ** 2 - al * np.sqrt(np.tan(psi)))


# ----------------------------------------------------------------------------
# Uniformly loaded rectangle on a half-space (Love 1929; Johnson 1985 Sec. 3.3)
# ----------------------------------------------------------------------------

def _corner(x, y):
    """Antiderivative of 1/sqrt(x^2+y^2), odd in x and in y: x asinh(y/|x|) + y asinh(x/|y|) (0 on the axes)."""
    ax, ay = np.abs(x), np.abs(y)
    with np.errstate(divide="ignore", invalid="ignore"):
        t1 = np.where(ax > 0, x * np.arcsinh(y / np.where(ax > 0, ax, 1.0)), 0.0)
        t2 = np.where(ay > 0, y * np.arcsinh(x / np.where(ay > 0, ay, 1.0)), 0.0)
    return t1 + t2


def rectangle_displacement(x, y, a, b, p=1.0, E_star=1.0):
    """Normal surface displacement [m] from uniform pressure p [Pa] on [-a,a]x[-b,b] [m].

    u(x,y) = p/(pi E*) [G(x+a,y+b) - G(x+a,y-b) - G(x-a,y+b) + G(x-a,y-b)],
    G(s,t) = s asinh(t/|s|) + t asinh(s/|t|) (the odd-odd antiderivative of
    1/sqrt(s^2+t^2); the form s asinh(t/s) is wrong when the point is inside
    the strip). Centre of a square (a = b): u = (8 p a/(pi E*)) ln(1+sqrt 2)
    ~= 2.244 p a/E*. E* = E/(1-nu^2) for one half-space. Love (1929);
    Johnson (1985) Eq. 3.25.
    """
    a, b = positive("a", a), positive("b", b)
    E_star = positive("E_star", E_star)
    x = np.asarray(x, float)
    y = np.asarray(y, float)
    s = (_corner(x + a, y + b) - _corner(x + a, y - b)
         - _corner(x - a, y + b) + _corner(x - a, y - b))
    return float(p) / (np.pi * E_star) * s
