"""Paschen's law for air: the breakdown voltage of a uniform-field gap, V_b(p d), on both branches.

No two-constant formula fits air both at its minimum and at the millimetre gaps where a TENG's
open-circuit cap binds, so V_b is built from two published fits, each where it holds:

* the minimum and the left branch (p d <= (p d)_min): V_b = a p d / (ln(p d) + b), p d in atm m,
  a = 4.36e7 V/(atm m), b = 12.8 (dry air; the fit of the TENG breakdown analyses, Zi et al.,
  Nat. Commun. 6, 8376, 2015). Its minimum, ln(p d) + b = 1: 327.2 V at 7.50 um and 1 atm, the
  measured minimum of air (about 327 V at 0.567 Torr cm, Dakin et al., Electra 32, 1974). Its pole,
  ln(p d) = -b (2.8 um at 1 atm): below it no Townsend breakdown occurs, V_b = inf;
* the right branch (p d > (p d)_min): the Townsend form V_b = B p d / (ln(A p d) - ln ln(1 + 1/gamma)),
  A = 112.50 /(kPa cm), B = 2737.50 V/(kPa cm), gamma = 0.01 (Raizer, *Gas Discharge Physics*, 1991,
  valid for E/p = 100-800 V/(cm Torr)) past its own minimum, floored at the measured minimum (it dips
  to 305 V at 11 um, below what air shows): V_b = 327.2 V from 7.5 to 17 um at 1 atm. The a-b fit alone overestimates this branch: 753 V against about 551 V at
  50 um, 7.4 kV against about 4.5 kV at 1 mm.

SI in (m, Pa), SI out (V); vectorises over numpy arrays. Measured against the uniform-field formula
for air in docs/validation.md.
"""
from __future__ import annotations

import math

import numpy as np

from tengsim.errors import positive

ATM_PA = 101325.0
A_MIN_V_PER_ATM_M = 4.36e7   # a, V/(atm m): the minimum and left branch
B_MIN_LOG = 12.8             # b (p d in atm m)
A_PER_PA_M = 112.50 / (1e3 * 1e-2)    # Townsend A: 112.50 /(kPa cm) in 1/(Pa m)
B_V_PER_PA_M = 2737.50 / (1e3 * 1e-2)  # Townsend B: 2737.50 V/(kPa cm) in V/(Pa m)
GAMMA = 0.01
PD_MIN_ATM_M = math.exp(1.0 - B_MIN_LOG)     # (p d) at the minimum, atm m
V_MIN = A_MIN_V_PER_ATM_M * PD_MIN_ATM_M     # 327.2 V
PD_TOWNSEND_MIN_PA_M = math.e * math.log(1.0 + 1.0 / GAMMA) / A_PER_PA_M  # the Townsend form's own minimum
SOURCE = ("Paschen, air: minimum and left branch V_b = a pd/(ln pd + b), a = 4.36e7 V/(atm m), b = 12.8 "
          "(Zi et al., Nat. Commun. 6, 8376, 2015); right branch Townsend A = 112.50 /(kPa cm), "
          "B = 2737.50 V/(kPa cm), gamma = 0.01 (Raizer 1991), floored at the 327 V minimum")


def _townsend(pd_pa_m):
    c = math.log(math.log(1.0 + 1.0 / GAMMA))
    den = np.log(A_PER_PA_M * pd_pa_m) - c
    return np.where(den > 0, B_V_PER_PA_M * pd_pa_m / np.where(den > 0, den, 1.0), np.inf)


def breakdown_voltage(gap_m, pressure_Pa: float = ATM_PA):
    """Breakdown voltage V_b (V) of an air gap ``gap_m`` (m) at ``pressure_Pa``; inf where none occurs."""
    p = positive("pressure", pressure_Pa)
    pd_atm = (p / ATM_PA) * np.asarray(gap_m, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        den = np.log(pd_atm) + B_MIN_LOG
        left = np.where(den > 0, A_MIN_V_PER_ATM_M * pd_atm / np.where(den > 0, den, 1.0), np.inf)
        pd_pa = pd_atm * ATM_PA  # the Townsend branch past its own minimum, floored at V_MIN
        right = np.where(pd_pa > PD_TOWNSEND_MIN_PA_M, np.maximum(V_MIN, _townsend(pd_pa)), V_MIN)
        vb = np.where(pd_atm <= PD_MIN_ATM_M, left, right)
    return vb if vb.ndim else float(vb)


def paschen_minimum(pressure_Pa: float = ATM_PA) -> tuple[float, float]:
    """(V_min in V, gap at the minimum in m): 327.2 V at 7.50 um / (p in atm)."""
    return V_MIN, PD_MIN_ATM_M / (positive("pressure", pressure_Pa) / ATM_PA)
