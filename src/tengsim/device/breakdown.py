"""Air breakdown along the device's cycle: the air gap's voltage against Paschen's V_b at that gap.

The air gap lies between the tribo-charged dielectric surface and the moving electrode. Its (mean)
voltage is linear in the charges, V_gap = sigma A g(x) - Q h(x) (device/field.py's coefficients):
parallel plates V_gap = (sigma A - Q) x/(eps0 S). Breakdown starts where V_gap(x) > V_b(x):

* open circuit (Q = 0): the largest gap voltage at every x (Q >= 0 on a cycle only lowers it), so the
  open-circuit bound is the cap for any load: ``sigma_breakdown_C_m2`` = min_x V_b(x)/V_gap,1(x),
  the largest sigma A/S (charge per electrode area) the device holds anywhere on its cycle;
* short circuit (Q = Q_SC(x)): the bound with the transferred charge screening the gap;
* on the load: along a computed trajectory, sigma A/S times min_t V_b(x(t))/|V_gap(t)| (the run's
  trajectory held; the force's dependence on sigma neglected).

The finite field uses the sheet-averaged gap voltage (the centre's is a little higher at x ~ L).
"""
from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from tengsim.constants import EPS0
from tengsim.device.field import bar_field
from tengsim.device.paschen import ATM_PA, SOURCE, breakdown_voltage
from tengsim.device.params import DeviceParams
from tengsim.errors import positive, require


def gap_voltage_per_sigma(params: DeviceParams, gap_m, condition: str = "open"):
    """Air-gap voltage (V) per unit sigma A/S (C/m2) at gaps ``gap_m``, open or short circuit."""
    require(condition in ("open", "short"), f"condition must be open or short, got {condition!r}")
    f = bar_field(params, xb_max=max(3.0, float(np.max(gap_m)) / params.gap_m))
    xb = np.asarray(gap_m, float) / params.gap_m
    k = params.gap_m / EPS0  # V per (sigma, bar unit) with Q in units of sigma S
    g = f.voc(xb) - f.ws(xb)  # per unit g1 (sigma A = sigma S g1)
    if condition == "short":
        g = g - (f.cinv(xb) + f.wq(xb)) * f.voc(xb) / f.cinv(xb)
    return k * g


@dataclass(frozen=True)
class Breakdown:
    """Breakdown-limited charge density (on sigma A/S, C/m2) and where on the gap it binds."""

    sigma_breakdown_C_m2: float
    gap_at_limit_m: float
    sigma_short_C_m2: float
    gap_short_m: float
    x_max_m: float
    pressure_Pa: float
    field: str
    paschen: str = SOURCE

    def to_dict(self) -> dict:
        return asdict(self)


def sigma_breakdown(params: DeviceParams, x_max_m: float | None = None, pressure_Pa: float = ATM_PA,
                    n: int = 400) -> Breakdown:
    """The largest sigma A/S without breakdown for gaps up to ``x_max_m`` (default the rest gap d0)."""
    x_max = positive("x_max", params.gap_m if x_max_m is None else x_max_m)
    p = positive("pressure", pressure_Pa)
    x = np.geomspace(1e-7, x_max, n)
    vb = breakdown_voltage(x, p)
    out = []
    for cond in ("open", "short"):
        ratio = vb / np.maximum(gap_voltage_per_sigma(params, x, cond), 1e-300)
        i = int(np.argmin(ratio))
        out += [float(ratio[i]), float(x[i])]
    return Breakdown(out[0], out[1], out[2], out[3], float(x_max), p, params.field)


def sigma_breakdown_run(result, pressure_Pa: float = ATM_PA, skip_cycles: int = 1) -> float:
    """The largest sigma A/S the run's load holds on its settled flight (C/m2; inf if no gap opens)."""
    p, s = result.params, result.series
    f = bar_field(p, xb_max=max(3.0, float(np.max(s["gap"])) / p.gap_m))
    m = result.settled(skip_cycles) & (s["contact"] == 0) & (s["gap"] > 0)
    if not np.any(m):
        return float("inf")
    xb = s["gap"][m] / p.gap_m
    q = s["Q"][m] / p.charge_scale
    g1 = s["area"][m] / p.area_m2
    vgap = p.voltage_scale * (g1 * (f.voc(xb) - f.ws(xb)) - q * (f.cinv(xb) + f.wq(xb)))
    ratio = breakdown_voltage(s["gap"][m], pressure_Pa) / np.maximum(np.abs(vgap), 1e-300)
    return float(p.sigma_C_per_m2 * np.max(g1) * np.min(ratio))


@dataclass(frozen=True, eq=False)
class BreakdownCycle:
    """The cycle for maximised energy output (Zi et al. 2015) with the air gap's breakdown, quasi-static.

    The first open-circuit stroke to x_max discharges the gap wherever V_gap would pass V_b, leaving the
    charge density ``sigma_held_C_m2`` = min(σ A/S, the open-circuit cap on [0, x_max]); the cycle then runs with
    it (the later legs, with Q > 0 screening the gap, stay below). V–Q loop (legs: open 0 -> x_max, short at
    x_max, open back, short in contact), its energy E_m = ½ Q_SC,max (V_OC,max + V'_max) and FOM_S =
    2 eps0 E_m / (σ_held² S x_max); ``energy_unlimited_J`` is the same cycle without breakdown."""

    charge_C: np.ndarray
    voltage_V: np.ndarray
    energy_J: float
    energy_unlimited_J: float
    sigma_held_C_m2: float
    fom_structural: float
    x_max_m: float


def breakdown_cycle(params: DeviceParams, x_max_m: float, pressure_Pa: float = ATM_PA, n: int = 100,
                    sigma_area_C_m2: float | None = None) -> BreakdownCycle:
    """The CMEO of ``params`` (its field model) to a gap ``x_max_m``, limited by breakdown, for the charge density
    ``sigma_area_C_m2`` = σ A/S (default σ times the initial A/S, or σ for a flat device)."""
    x_max = positive("x_max", x_max_m)
    p = params
    sig = (p.sigma_C_per_m2 * (p.area.initial_fraction or 1.0) if sigma_area_C_m2 is None
           else positive("sigma A/S", sigma_area_C_m2))
    cap = sigma_breakdown(p, x_max_m=x_max, pressure_Pa=pressure_Pa).sigma_breakdown_C_m2
    f = bar_field(p, xb_max=max(3.0, x_max / p.gap_m))
    k = p.gap_m / (EPS0 * p.area_m2)
    xm, xs = x_max / p.gap_m, np.linspace(0.0, x_max / p.gap_m, n)

    def loop(s):
        sa = s * p.area_m2
        qm = sa * float(f.voc(xm)) / float(f.cinv(xm))
        qs = np.linspace(0.0, qm, n)
        legs_q = [np.zeros(n), qs, np.full(n, qm), qs[::-1]]
        legs_v = [k * sa * f.voc(xs), k * (-qs * f.cinv(xm) + sa * f.voc(xm)),
                  k * (-qm * f.cinv(xs[::-1]) + sa * f.voc(xs[::-1])), -k * qs[::-1] * f.cinv(0.0)]
        e = 0.5 * qm * k * (sa * float(f.voc(xm)) + qm * float(f.cinv(0.0)))
        return np.concatenate(legs_q), np.concatenate(legs_v), float(e)

    held = min(sig, cap)
    q, v, e = loop(held)
    fom = 2 * EPS0 * e / (held ** 2 * p.area_m2 * x_max)
    return BreakdownCycle(q, v, e, loop(sig)[2], float(held), float(fom), float(x_max))
