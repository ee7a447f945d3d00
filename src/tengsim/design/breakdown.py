"""The breakdown-limited σ of a design's device (issue 51): the largest σ A/S its air gap holds in open circuit.

The design's device: σ, ε_r, T and the rest gap d0 of the design; the electrode of :data:`tengsim.design.device.
DEFAULTS` (4 cm²). The cap is :func:`tengsim.device.breakdown.sigma_breakdown`'s on gaps up to d0 with the finite
field, evaluated here on a disk of the electrode's area (axisymmetric, fast; a square of the same area differs by
< 1.5 %, docs/validation.md) on 8 gaps from d0/100 to d0.
"""
from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

AREA_M2 = 4.0e-4  # tengsim.design.device.DEFAULTS["area_m2"]: the device design's default electrode
FINITE_FIELD = "finite: a 4 cm² square electrode (tengsim device design's default), rest gap d0"
"""The finite field model a design's V_OC is also given with (``voc_finite_at_p_max_V``)."""


@lru_cache(maxsize=64)
def finite_voc_ratio(eps_r: float, thickness_m: float, gap_m: float) -> float:
    """V_OC at the rest gap d0 with the finite field of the design's device (a square of :data:`AREA_M2`, the
    electrode ``tengsim device design`` defaults to) over Eq. 17's parallel plates: σ A v(d0) / (σ (A/S) d0/ε0)."""
    from tengsim.device.field import electrode_size, gap_coefficients
    from tengsim.device.formulas import eq17_volts_per_charge

    v = gap_coefficients("square", electrode_size("square", AREA_M2), thickness_m, eps_r, np.array([gap_m]))[1]
    return float(v[0] * AREA_M2 / eq17_volts_per_charge(gap_m))


@lru_cache(maxsize=64)
def breakdown_cap(eps_r: float, thickness_m: float, gap_m: float) -> float:
    """The open-circuit cap on σ A/S (C/m²) of the design's device (module doc)."""
    from tengsim.device.field import electrode_size, gap_coefficients
    from tengsim.device.paschen import breakdown_voltage

    size = electrode_size("disk", AREA_M2)
    x = np.geomspace(gap_m / 100, gap_m, 8)
    _, v, _, _, ws = gap_coefficients("disk", size, thickness_m, eps_r, x)
    per_sigma = (v - ws) * AREA_M2  # air-gap voltage per unit σ A/S, Q = 0
    return float(np.min(breakdown_voltage(x) / per_sigma))


def design_breakdown(sigma: float, eps_r: float, thickness_m: float, gap_m: float, area_fraction_max: float) -> dict:
    """{sigma_breakdown_C_m2, sigma_area_fraction_C_m2 (σ × the largest A/S), breakdown_exceeded, paschen}."""
    from tengsim.device.paschen import SOURCE

    cap = breakdown_cap(float(eps_r), float(thickness_m), float(gap_m))
    eff = float(sigma * area_fraction_max) if math.isfinite(area_fraction_max) else math.nan
    return {"sigma_breakdown_C_m2": cap, "sigma_area_fraction_C_m2": eff, "breakdown_exceeded": bool(eff > cap),
            "breakdown_paschen": SOURCE}


def report_line(b: dict) -> str:
    over = ("**exceeds it: the gap discharges, the device cannot hold that charge**" if b["breakdown_exceeded"]
            else "below it")
    return (f"Air breakdown (Paschen, open circuit, 4 cm² electrode, gaps up to d0): the device holds σ A/S up to "
            f"{b['sigma_breakdown_C_m2'] * 1e6:.3g} µC/m²; this design's σ × largest A/S = "
            f"{b['sigma_area_fraction_C_m2'] * 1e6:.3g} µC/m², {over}.")
