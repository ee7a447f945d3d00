"""A 1-D sinusoidal surface: Westergaard's non-adhesive solution and Johnson's adhesive one
(Johnson 1985 Sec. 13.2; Johnson 1995).

Units and conventions: :mod:`tengsim.references.common`.
"""
from __future__ import annotations

import numpy as np

from tengsim.errors import positive
from tengsim.references.common import nonnegative


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
    E_star, W = positive("E_star", E_star), nonnegative("W", W)
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
