"""Paschen's law for air: the breakdown voltage of a uniform-field gap, V_b(p d).

    V_b = B p d / (ln(A p d) - ln(ln(1 + 1/gamma)))

Constants (the set the TENG breakdown literature uses, Zi et al., Adv. Funct. Mater. 27, 1700049, 2017;
from Raizer, *Gas Discharge Physics*, 1991, Table 4.1, valid for E/p = 100-800 V/(cm Torr)):
A = 112.50 /(kPa cm) (15 /(cm Torr)), B = 2737.50 V/(kPa cm) (365 V/(cm Torr)), gamma = 0.01.

These give the minimum V_min = e (B/A) ln(1 + 1/gamma) = 305.0 V at (p d)_min = e ln(1 + 1/gamma)/A
= 0.1115 kPa cm, i.e. d = 11.0 um at 1 atm; the measured minimum of air is about 327 V at 7.5 um
(0.567 Torr cm, Dakin et al., Electra 32, 1974). Left of the minimum the formula has a pole at
A p d = ln(1 + 1/gamma); there (and below it) no Townsend breakdown occurs: V_b = inf.
SI in, SI out; vectorises over numpy arrays.
"""
from __future__ import annotations

import math

import numpy as np

from tengsim.errors import positive

ATM_PA = 101325.0
A_PER_PA_M = 112.50 / (1e3 * 1e-2)   # 112.50 /(kPa cm) in 1/(Pa m)
B_V_PER_PA_M = 2737.50 / (1e3 * 1e-2)  # 2737.50 V/(kPa cm) in V/(Pa m)
GAMMA = 0.01
SOURCE = ("Paschen, air: A = 112.50 /(kPa cm), B = 2737.50 V/(kPa cm), gamma = 0.01 "
          "(Raizer 1991; Zi et al., Adv. Funct. Mater. 27, 1700049, 2017)")


def breakdown_voltage(gap_m, pressure_Pa: float = ATM_PA, gamma: float = GAMMA):
    """Breakdown voltage V_b (V) of an air gap ``gap_m`` (m) at ``pressure_Pa``; inf where none occurs."""
    p = positive("pressure", pressure_Pa)
    g = positive("gamma", gamma)
    pd = p * np.asarray(gap_m, dtype=float)
    c = math.log(math.log(1.0 + 1.0 / g))
    with np.errstate(divide="ignore", invalid="ignore"):
        den = np.log(A_PER_PA_M * pd) - c
        vb = np.where(den > 0, B_V_PER_PA_M * pd / np.where(den > 0, den, 1.0), np.inf)
    return vb if vb.ndim else float(vb)


def paschen_minimum(pressure_Pa: float = ATM_PA, gamma: float = GAMMA) -> tuple[float, float]:
    """(V_min in V, gap at the minimum in m), closed form: ln(A p d) - ln ln(1 + 1/gamma) = 1."""
    p = positive("pressure", pressure_Pa)
    lg = math.log(1.0 + 1.0 / positive("gamma", gamma))
    pd = math.e * lg / A_PER_PA_M
    return B_V_PER_PA_M * pd, pd / p
