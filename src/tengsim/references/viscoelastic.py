"""A rigid sphere (paraboloid) on a linear viscoelastic half-space: Lee & Radok (1960) for a growing contact,
Ting (1966) for a contact that grows and then shrinks; the standard linear solid's closed forms.

Moduli are of E*(t) (plane strain), in any consistent units; times in any one unit.
"""
from __future__ import annotations

import numpy as np
from scipy.integrate import quad
from scipy.optimize import brentq

from tengsim.errors import positive


def sls_relaxation(t, E_inf: float, E1: float, tau: float):
    """E(t) = E∞ + E1 exp(−t/τ) of the standard linear solid."""
    return E_inf + E1 * np.exp(-np.asarray(t, float) / tau)


def sls_relaxation_integral(x, E_inf: float, E1: float, tau: float):
    """∫_0^x E(u) du = E∞ x + E1 τ (1 − e^{−x/τ})."""
    x = np.asarray(x, float)
    return E_inf * x + E1 * tau * -np.expm1(-x / tau)


def lee_radok_radius(P0: float, R: float, J_t):
    """Contact radius under a step load P0 held constant: a(t)³ = (3 R P0/4) J(t) (Lee & Radok 1960), J(t) the
    creep compliance of E* at the time wanted (the array ``J_t``)."""
    R = positive("R", R)
    return np.cbrt(0.75 * R * P0 * np.asarray(J_t, float))


def ting_triangle_force(t, R: float, v_up: float, t_m: float, v_down: float, E_inf: float, E1: float, tau: float):
    """Force on a paraboloid of radius R pressed at the rate v_up (δ = v_up s up to t_m), then withdrawn at the
    rate v_down, into a standard linear solid (Ting 1966).  Loading (t <= t_m, Lee–Radok):
    F = (4/3R) ∫_0^t E(t−s) d(a³)/ds ds with a² = R δ; unloading: the same integral up to t1(t) <= t_m, the
    time the contact radius had the same value, from ∫_{t1}^{t} E(t−s) δ'(s) ds = 0 (the maximum-history rule)."""
    E = lambda u: float(sls_relaxation(u, E_inf, E1, tau))
    I = lambda x: float(sls_relaxation_integral(x, E_inf, E1, tau))
    c = 1.5 * (R * v_up) ** 1.5

    def force(ti):
        if ti <= t_m:
            t1 = ti
        else:
            g = lambda s1: v_up * (I(ti - s1) - I(ti - t_m)) - v_down * I(ti - t_m)
            if g(0.0) <= 0:
                return 0.0  # the contact is gone
            t1 = brentq(g, 0.0, t_m, xtol=1e-14 * max(t_m, 1.0))
        val, _ = quad(lambda s: E(ti - s) * c * np.sqrt(s), 0.0, t1, limit=200)
        return 4.0 / (3.0 * R) * val

    return np.array([force(float(x)) for x in np.atleast_1d(t)])


def ting_triangle_t1(t, v_up: float, t_m: float, v_down: float, E_inf: float, E1: float, tau: float) -> float:
    """t1(t) of :func:`ting_triangle_force`: the loading time with the contact radius of the time t > t_m."""
    I = lambda x: float(sls_relaxation_integral(x, E_inf, E1, tau))
    return brentq(lambda s1: v_up * (I(t - s1) - I(t - t_m)) - v_down * I(t - t_m), 0.0, t_m)
