"""Non-adhesive axisymmetric indenters: Sneddon's rigid cone (Sneddon 1965) and the flat punch
(Johnson 1985 Sec. 3.8, 5.6).

Units and conventions: :mod:`tengsim.references.common`.
"""
from __future__ import annotations

import numpy as np

from tengsim.errors import TengsimError, positive


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
