"""Closed-form reference formulas: Eq. (12), parallel plates apart (Eqs. 17-19), forces, FOM_S.

Two open-circuit-voltage models are kept apart on purpose:

* :func:`voc_polymer` (Eq. 12, Section 4): the tribo-charge sigma A over the polymer's own
  capacitance eps_r eps0 S / T. Independent of the gap; it is the static pressure-voltage model
  of Fig. 5.
* :func:`voc_apart` (Eq. 17, Section 5): the parallel-plate open-circuit voltage sigma A d / (S eps0)
  of plates a gap d apart; zero in contact.

All functions are plain SI and vectorise over numpy arrays.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.integrate import trapezoid

from tengsim.constants import EPS0


def eq12_volts_per_charge(eps_r, thickness):
    """Eq. (12)'s V_OC per unit σ per unit A/S, T/(ε_r ε0) (V m²/C): the polymer's own capacitance per area,
    inverted.  The one definition: :func:`voc_polymer`, calibration's V_OC model and a prediction's bands use it."""
    return thickness / (eps_r * EPS0)


def eq17_volts_per_charge(gap, plate_area=1.0):
    """Eq. (17)'s V_OC per unit σ per unit charged area A (per unit A/S for ``plate_area`` 1), d/(S ε0) (V m²/C)."""
    return np.asarray(gap, dtype=float) / (plate_area * EPS0)


def voc_polymer(area_fraction, sigma, eps_r, thickness):
    """Eq. (12): V_OC = sigma (A/S) T / (eps_r eps0) (V)."""
    return sigma * np.asarray(area_fraction, dtype=float) * eq12_volts_per_charge(eps_r, thickness)


def voc_from_contact_length(lambda_c, cell_length, sigma, eps_r, thickness):
    """Eq. (12) as printed: V_OC = (sigma / (eps_r eps0)) (T / L^2) lambda_c^2 (V)."""
    lam = np.asarray(lambda_c, dtype=float)
    return sigma / (eps_r * EPS0) * thickness / cell_length ** 2 * lam ** 2


def voc_apart(sigma, area, gap, plate_area):
    """Eq. (17): V_OC = sigma A d / (S eps0) (V)."""
    return sigma * area * eq17_volts_per_charge(gap, plate_area)


def qsc_apart(sigma, area, gap, thickness, eps_r):
    """Eq. (18): Q_SC = sigma A d / (T/eps_r + d) (C)."""
    d = np.asarray(gap, dtype=float)
    return sigma * area * d / (thickness / eps_r + d)


def isc_apart(sigma, area, gap, velocity, thickness, eps_r):
    """Eq. (19): I_SC = -sigma A ydot (T/eps_r) / (T/eps_r + d)^2 (A); ydot > 0 closes the gap."""
    d = np.asarray(gap, dtype=float)
    te = thickness / eps_r
    return -sigma * area * np.asarray(velocity, dtype=float) * te / (te + d) ** 2


def voltage(charge, sigma, area, gap, plate_area, thickness, eps_r):
    """Eq. (14): V = -Q (T/eps_r + d)/(S eps0) + sigma A d/(S eps0) (V)."""
    d = np.asarray(gap, dtype=float)
    return (-np.asarray(charge) * (thickness / eps_r + d) + sigma * area * d) / (plate_area * EPS0)


def field_force(charge, sigma, area, plate_area):
    """Field pressure on the plate times S: (sigma A - Q)^2 / (2 eps0 S) (N), toward the polymer."""
    return (sigma * area - np.asarray(charge, dtype=float)) ** 2 / (2 * EPS0 * plate_area)


def eq20_force(charge, sigma, area, gap, plate_area, thickness, eps_r, reg_gap=0.0):
    """Eq. (20) with its sign corrected so that it attracts in open circuit (N, toward the polymer).

    Eq. (20) as printed reduces to F = A/(2 S^2 eps0) [(Q T/(eps_r d))^2 - (sigma A - Q)^2]; this
    returns its negative, with d -> d + reg_gap in the 1/d term (reg_gap = 0 is the raw form).
    """
    q = np.asarray(charge, dtype=float)
    d = np.asarray(gap, dtype=float) + reg_gap
    return area / (2 * plate_area ** 2 * EPS0) * ((sigma * area - q) ** 2 - (q * thickness / (eps_r * d)) ** 2)


def electrostatic_energy(charge, sigma, area, gap, plate_area, thickness, eps_r):
    """Field energy U = (sigma A - Q)^2 d/(2 eps0 S) + Q^2 T/(2 eps_r eps0 S) (J); dU = -V dQ - F dy."""
    q = np.asarray(charge, dtype=float)
    d = np.asarray(gap, dtype=float)
    return ((sigma * area - q) ** 2 * d + q ** 2 * thickness / eps_r) / (2 * EPS0 * plate_area)


# --- Zi et al., Nat. Commun. 6, 8376 (2015): cycle for maximised energy output (CMEO) ---

def fom_structural(x_max, thickness, eps_r):
    """Structural figure of merit of the contact-separation mode, closed form.

    FOM_S = 2 eps0 E_m / (sigma^2 S x_max) = x (x + 2 d_e) / (x + d_e)^2 with d_e = T/eps_r.
    """
    x = np.asarray(x_max, dtype=float)
    de = thickness / eps_r
    return x * (x + 2 * de) / (x + de) ** 2


@dataclass(frozen=True)
class CMEOCycle:
    """V-Q loop of the cycle for maximised energy output (Zi et al. 2015) and its energy."""

    charge_C: np.ndarray
    voltage_V: np.ndarray
    energy_J: float
    qsc_max_C: float
    voc_max_V: float
    v_prime_max_V: float
    x_max_m: float


def cmeo_cycle(sigma, plate_area, thickness, eps_r, x_max, area=None, n: int = 200) -> CMEOCycle:
    """Trace the CMEO with Eq. (14) and integrate E_m = loop integral of V dQ (trapezoid in x, exact in Q).

    Legs: open circuit 0 -> x_max (Q = 0); discharge at x_max (Q 0 -> Q_SC,max); open circuit back
    to contact (Q = Q_SC,max); discharge in contact (Q -> 0).
    """
    a = plate_area if area is None else area
    xs = np.linspace(0.0, x_max, n)
    qm = float(qsc_apart(sigma, a, x_max, thickness, eps_r))
    qs = np.linspace(0.0, qm, n)
    v = lambda q, x: voltage(q, sigma, a, x, plate_area, thickness, eps_r)  # noqa: E731
    legs_q = [np.zeros(n), qs, np.full(n, qm), qs[::-1]]
    legs_v = [v(0.0, xs), v(qs, x_max), v(qm, xs[::-1]), v(qs[::-1], 0.0)]
    q = np.concatenate(legs_q)
    vv = np.concatenate(legs_v)
    energy = float(trapezoid(vv, q))  # only the two discharge legs move Q
    return CMEOCycle(q, vv, energy, qm, float(v(0.0, x_max)), float(-v(qm, 0.0)), float(x_max))
