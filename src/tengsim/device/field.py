"""The device's field model: ``parallel`` (infinite plates, Eqs. 14-19, the paper's) or ``finite``
(electrodes of a given size and shape, solved by the boundary elements of device/field_bem.py).

Both write the field energy of the two electrodes and the tribo-charge sheet as one quadratic form,

    U(Q, x) = Q^2 / (2 C(x)) - Q sigma A v(x) + (sigma A)^2 u(x) / 2,

so that V = -dU/dQ = -Q/C + sigma A v (V_OC = sigma A v, Q_SC = C V_OC) and the force toward the
polymer F = dU/dx at fixed charge: the dynamics then conserve energy exactly, whatever C, v, u are.
Parallel plates: 1/C = (T/eps_r + x)/(eps0 S), v = u = x/(eps0 S). The finite model tabulates the
three on gaps 0..x_max (clustered at 0) and interpolates them with cubic splines (their derivatives
give F and I_SC); each table is cached per geometry.

In the dynamics' units (x = d0 xb; Eq. 23 scales) the coefficients enter as
cinv(xb) = eps0 S/(d0 C), voc(xb) = eps0 S v/d0, usig(xb) = eps0 S u/d0 (parallel: g3 + xb, xb, xb).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from scipy.interpolate import CubicSpline

from tengsim.constants import EPS0
from tengsim.device import field_bem
from tengsim.errors import require

FIELD_MODELS = ("parallel", "finite")
SHAPES = field_bem.SHAPES
PANELS = {"square": 16, "disk": 80}
"""Panels per half-size (the square: n^2 per quadrant). Disk: Kirchhoff within 0.3 % at a/d = 20, 50;
square: the fringe term within ~2 % of its n = 30 value (docs/validation.md)."""


def electrode_size(shape: str, area_m2: float) -> float:
    """The square's side or the disk's diameter (m) of an electrode of area S."""
    require(shape in SHAPES, f"electrode shape must be one of {list(SHAPES)}, got {shape!r}")
    return math.sqrt(area_m2) if shape == "square" else math.sqrt(4.0 * area_m2 / math.pi)


@dataclass(frozen=True)
class ParallelBar:
    """Parallel plates in the dynamics' units: cinv = g3 + xb, voc = usig = xb."""

    g3: float

    def cinv(self, xb, der=0):
        return (self.g3 + xb) if der == 0 else 1.0 + 0.0 * xb

    def voc(self, xb, der=0):
        return xb if der == 0 else 1.0 + 0.0 * xb

    def usig(self, xb, der=0):
        return self.voc(xb, der)

    def wq(self, xb):
        """The layer's voltage per unit q (sheet minus back electrode): -g3."""
        return -self.g3 + 0.0 * xb

    def ws(self, xb):
        return 0.0 * xb


@dataclass(frozen=True, eq=False)
class FiniteBar:
    """Splines of the finite model's coefficients over xb = x/d0 (dynamics' units)."""

    splines: tuple
    xb_max: float

    def cinv(self, xb, der=0):
        return self.splines[0](xb, der)

    def voc(self, xb, der=0):
        return self.splines[1](xb, der)

    def usig(self, xb, der=0):
        return self.splines[2](xb, der)

    def wq(self, xb):
        return self.splines[3](xb)

    def ws(self, xb):
        return self.splines[4](xb)


def gap_coefficients(shape: str, size_m: float, thickness_m: float, eps_r: float, gaps_m, n: int | None = None):
    """SI coefficients at each gap: 1/C (1/F), v (V/C), u (J/C^2), and the layer's voltage per unit Q and
    per unit sigma A (V/C; the air gap's mean voltage is V - Q wq - sigma A ws), arrays over ``gaps_m``."""
    n = PANELS[shape] if n is None else n
    te = thickness_m / eps_r / size_m
    out = np.array([[getattr(field_bem.solve(shape, g / size_m, te, n), k) for k in ("cinv", "voc", "usig", "wq", "ws")]
                    for g in np.atleast_1d(np.asarray(gaps_m, float))])
    return out.T / (4.0 * math.pi * EPS0 * size_m)


@lru_cache(maxsize=16)
def _finite_bar(shape, area_m2, thickness_m, eps_r, gap_m, xb_max, n_gaps, n):
    size = electrode_size(shape, area_m2)
    xb = xb_max * (np.arange(n_gaps) / (n_gaps - 1)) ** 2
    coef = gap_coefficients(shape, size, thickness_m, eps_r, xb * gap_m, n)
    bar = coef * EPS0 * area_m2 / gap_m
    bar[1:3, 0] = 0.0  # v(0) = u(0) = 0 exactly (the sheet lies on the moving electrode)
    return FiniteBar(tuple(CubicSpline(xb, b) for b in bar), float(xb_max))


def bar_field(params, xb_max: float = 3.0, n_gaps: int = 17):
    """The field coefficients of a DeviceParams in the dynamics' units (ParallelBar or FiniteBar)."""
    if getattr(params, "field", "parallel") == "parallel":
        return ParallelBar(params.gamma3)
    shape = params.electrode_shape
    return _finite_bar(shape, float(params.area_m2), float(params.thickness_m), float(params.eps_r),
                       float(params.gap_m), float(xb_max), int(n_gaps), PANELS[shape])


def si_series(params, charge_C, area_m2, gap_m, ydot):
    """V at this Q (Eq. 14's generalisation), V_OC, Q_SC, I_SC, F_e (toward the polymer) and U, SI."""
    f = bar_field(params)
    d0, S = params.gap_m, params.area_m2
    xb = np.asarray(gap_m, float) / d0
    q = np.asarray(charge_C, float)
    sa = params.sigma_C_per_m2 * np.asarray(area_m2, float)
    k = d0 / (EPS0 * S)  # bar -> SI: 1/C = k cinv, v = k voc, u = k usig
    ci, vo, us = f.cinv(xb), f.voc(xb), f.usig(xb)
    dci, dvo, dus = f.cinv(xb, 1), f.voc(xb, 1), f.usig(xb, 1)
    voc = k * sa * vo
    volt = -q * k * ci + voc
    qsc = sa * vo / ci
    isc = -sa * (dvo * ci - vo * dci) / ci ** 2 * np.asarray(ydot, float) / d0
    force = 0.5 * (k / d0) * (q * q * dci - 2.0 * q * sa * dvo + sa * sa * dus)
    energy = 0.5 * k * (q * q * ci - 2.0 * q * sa * vo + sa * sa * us)
    return {"V": volt, "V_oc": voc, "Q_sc": qsc, "I_sc": isc, "F_e": force, "U": energy}
