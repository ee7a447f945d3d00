"""Sphere on a flat: Hertz (no adhesion), JKR (short-range adhesion) and DMT (long-range adhesion);
Johnson (1985) Sec. 4.2, Johnson, Kendall & Roberts (1971), Derjaguin, Muller & Toporov (1975).

Units and conventions: :mod:`tengsim.references.common`.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tengsim.errors import TengsimError, positive
from tengsim.references.common import nonnegative


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
    R, E_star, W = positive("R", R), positive("E_star", E_star), nonnegative("W", W)
    a = np.asarray(a, float)
    return 4.0 * E_star * a ** 3 / (3.0 * R) - np.sqrt(8.0 * np.pi * W * E_star * a ** 3)


def jkr_indentation(a, R, E_star, W):
    """JKR indentation delta(a) = a^2/R - sqrt(2 pi W a/E*) [m]. Johnson (1985) Eq. 5.61 / Maugis (2000)."""
    R, E_star, W = positive("R", R), positive("E_star", E_star), nonnegative("W", W)
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
    R, E_star, W = positive("R", R), positive("E_star", E_star), nonnegative("W", W)
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
    R, E_star, W = positive("R", R), positive("E_star", E_star), nonnegative("W", W)
    return float(np.cbrt(9.0 * np.pi * W * R ** 2 / (2.0 * E_star)))


# ----------------------------------------------------------------------------
# DMT (Derjaguin, Muller & Toporov 1975)
# ----------------------------------------------------------------------------

def dmt_force(delta, R, E_star, W):
    """DMT force F = (4/3)E* R^(1/2) delta^(3/2) - 2 pi R W [N] for delta >= 0 (Hertz profile). DMT (1975)."""
    W = nonnegative("W", W)
    return hertz_force(delta, R, E_star) - 2.0 * np.pi * positive("R", R) * W


def dmt_contact_radius(F, R, E_star, W):
    """DMT contact radius a = (3R(F + 2 pi R W)/(4E*))^(1/3) [m]; 0 below F = -2 pi R W. DMT (1975)."""
    R, W = positive("R", R), nonnegative("W", W)
    return hertz_contact_radius_from_force(np.asarray(F, float) + 2.0 * np.pi * R * W, R, E_star)


def dmt_pulloff_force(R, W) -> float:
    """DMT pull-off force -2 pi R W [N]. Derjaguin, Muller & Toporov (1975)."""
    return float(-2.0 * np.pi * positive("R", R) * positive("W", W))
