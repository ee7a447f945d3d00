"""A pressure sensor's numbers from its V_OC(P) curve, defined once: used by ``tengsim design`` (report,
design.nc, comparison), the studies' observables and ``tengsim optimize``.

The curve is the open-circuit voltage on the approach (V) against the nominal pressure (Pa), piecewise linear
between the states given, read over a pressure range [p_lo, p_hi] (the part of it the curve reaches).  It is
resampled at :data:`SAMPLES` even pressures, so the numbers depend on the curve, not on where it was sampled.

* **Saturation pressure** P_sat: the lowest pressure from which V_OC stays within :data:`SATURATION_BAND`
  (2 %) of its full-scale change (max − min over the range) of its value at p_hi, when that flat tail covers at
  least :data:`SATURATION_MIN_WIDTH` (a tenth) of the range; n/a (with the reason) otherwise.
* **Regions**: the part below P_sat (the whole range without one) is one region when a least-squares line fits
  it with R² >= :data:`R2_LINEAR` (0.99); otherwise it is split at the **knee**, the pressure where two
  lines, one on each side, leave the least squared error: "below the knee" and "above the knee".  Above P_sat
  the region "saturated".  Each region has its sensitivity dV_OC/dP (V/Pa, the least-squares slope), its
  relative sensitivity (dV_OC/dP)/V₀ (1/Pa; V₀ = V_OC at p_lo, the unloaded baseline; n/a when V₀ = 0) and
  the R² of its line.  The sensor's **sensitivity** is that of its lowest region, stated with the region's top.
  A **snap** (the contact jumping in: between two states of the curve V_OC rises by at least
  :data:`SNAP_FRACTION` of its full-scale change at a slope at least :data:`SNAP_STEEPNESS` times the range's
  mean) is a knee of its own: the curve is split at its first snap below P_sat into "below the snap", "the snap"
  (the jump's two states) and "above the snap", each with its own line, and the knee is the pressure before it.
* **Linear range**: from p_lo up to the highest pressure p, at most the top of the lowest region, such that the
  least-squares line over [p_lo, p] fits with R² >= :data:`R2_LINEAR`; its R² is stated.
* **Hysteresis**: the largest |V_OC(retraction) − V_OC(approach)| at a pressure both branches reach in the
  range (V), and that over the full-scale change (the sensor's hysteresis, a fraction).

Every number that cannot be had is NaN with its reason in :attr:`SensorNumbers.reasons`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

R2_LINEAR = 0.99
"""R² at or above which a least-squares line is taken to fit (a region, the linear range)."""
SATURATION_BAND = 0.02
"""V_OC within this fraction of its full-scale change of its top value counts as saturated."""
SATURATION_MIN_WIDTH = 0.1
"""The flat tail must cover at least this fraction of the pressure range to be a saturation."""
SNAP_FRACTION = 0.2
"""A rise of V_OC between two states of at least this fraction of its full-scale change may be a snap ..."""
SNAP_STEEPNESS = 3.0
"""... when its slope is at least this many times the range's mean slope (full-scale change over the range)."""
SAMPLES = 401
"""Even pressures the piecewise-linear curve is read at over the range."""

NUMBERS = {
    # flat name: (unit, meaning); the names design.nc, compare.csv and a study's scalars carry
    "sensitivity_V_per_Pa": ("V/Pa", "sensitivity dV_OC/dP of the lowest pressure region (least-squares slope)"),
    "sensitivity_rel_per_Pa": ("1/Pa", "relative sensitivity (dV_OC/dP)/V0 of the lowest region, V0 = V_OC at "
                                       "the lowest pressure"),
    "sensitivity_to_Pa": ("Pa", "top of the lowest region (the knee, the saturation pressure or the range's top)"),
    "knee_Pa": ("Pa", "knee: where V_OC(P) changes slope (two lines fit better than one), or the pressure "
                       "just before a snap"),
    "sensitivity_above_knee_V_per_Pa": ("V/Pa", "sensitivity dV_OC/dP above the knee"),
    "saturation_Pa": ("Pa", f"saturation pressure: V_OC within {100 * SATURATION_BAND:g} % of its full-scale "
                            "change of its top value from there on"),
    "linear_range_Pa": ("Pa", f"top of the linear range from the lowest pressure (R² >= {R2_LINEAR:g}, within the "
                              "lowest region)"),
    "linear_r2": ("1", "R² of the line over the linear range"),
    "voc_hysteresis_V": ("V", "largest |V_OC(retraction) - V_OC(approach)| at a pressure"),
    "voc_hysteresis_fraction": ("1", "that over the full-scale change of V_OC (the sensor's hysteresis)"),
}


@dataclass(frozen=True)
class Region:
    """One pressure region of a V_OC(P) curve and the line fitted to it."""

    name: str
    p_lo_Pa: float
    p_hi_Pa: float
    sensitivity_V_per_Pa: float
    relative_per_Pa: float
    r2: float


@dataclass(frozen=True)
class SensorNumbers:
    """The numbers of the module doc; NaN where there is none, with the reason in ``reasons`` (by the names
    of :data:`NUMBERS`)."""

    p_lo_Pa: float
    p_hi_Pa: float
    v0_V: float
    regions: tuple
    knee_Pa: float
    saturation_Pa: float
    linear_range_Pa: float
    linear_r2: float
    voc_hysteresis_V: float
    voc_hysteresis_fraction: float
    reasons: dict = field(default_factory=dict)

    def flat(self) -> dict:
        """{name of :data:`NUMBERS`: value (SI)}."""
        nan = math.nan
        low = self.regions[0] if self.regions else None
        above = next((r for r in self.regions if r.name in ("above the knee", "above the snap")), None)
        return {"sensitivity_V_per_Pa": low.sensitivity_V_per_Pa if low else nan,
                "sensitivity_rel_per_Pa": low.relative_per_Pa if low else nan,
                "sensitivity_to_Pa": low.p_hi_Pa if low else nan,
                "knee_Pa": self.knee_Pa,
                "sensitivity_above_knee_V_per_Pa": above.sensitivity_V_per_Pa if above else nan,
                "saturation_Pa": self.saturation_Pa, "linear_range_Pa": self.linear_range_Pa,
                "linear_r2": self.linear_r2, "voc_hysteresis_V": self.voc_hysteresis_V,
                "voc_hysteresis_fraction": self.voc_hysteresis_fraction}

    def reason(self, name: str) -> str:
        return self.reasons.get(name, "")


def _kpa(p: float) -> str:
    return f"{p / 1e3:.4g} kPa"


def _curve(P, V):
    """Finite (P, V) with P increasing; at a pressure given twice (a snap: the state before it and the state the
    device lands on at the same load, :func:`tengsim.run.area.load_control`) the landing state is kept, so the
    jump lies between the fold and the state before it, not spread over the pressures after it; a pressure
    lower than one kept is dropped."""
    P, V = np.asarray(P, float).ravel(), np.asarray(V, float).ravel()
    ok = np.isfinite(P) & np.isfinite(V)
    P, V = P[ok], V[ok]
    if P.size == 0:
        return P, V
    keep = [0]
    for i in range(1, P.size):
        if P[i] > P[keep[-1]]:
            keep.append(i)
        elif P[i] == P[keep[-1]]:
            keep[-1] = i
    return P[keep], V[keep]


def _fit(x, y):
    """(slope, intercept, R², sum of squared residuals) of the least-squares line; R² NaN for constant y."""
    slope, icpt = np.polyfit(x, y, 1)
    res = float(np.sum((y - (icpt + slope * x)) ** 2))
    tot = float(np.sum((y - np.mean(y)) ** 2))
    scale = max(float(np.max(np.abs(y))), 1e-300)
    r2 = 1.0 - res / tot if tot > (1e-12 * scale) ** 2 * len(y) else math.nan
    return float(slope), float(icpt), r2, res


def _r2_prefix(x, y):
    """R² of the line over x[0..k] for every k (NaN for k < 2 and where y is constant so far)."""
    n = np.arange(1, len(x) + 1, dtype=float)
    sx, sy = np.cumsum(x), np.cumsum(y)
    sxx, syy, sxy = np.cumsum(x * x), np.cumsum(y * y), np.cumsum(x * y)
    vx = sxx - sx * sx / n
    vy = syy - sy * sy / n
    cxy = sxy - sx * sy / n
    scale = max(float(np.max(np.abs(y))), 1e-300)
    with np.errstate(invalid="ignore", divide="ignore"):
        r2 = np.where((vx > 0) & (vy > (1e-12 * scale) ** 2 * n), cxy * cxy / (vx * vy), np.nan)
    r2[:2] = np.nan
    return r2


def _saturation(x, y, span):
    """(P_sat or NaN, reason)."""
    band = SATURATION_BAND * span
    out = np.flatnonzero(np.abs(y - y[-1]) > band)
    j = int(out[-1])  # span > band: some value lies outside the band
    edge = y[-1] + math.copysign(band, y[j] - y[-1])
    t = (y[j] - edge) / (y[j] - y[j + 1]) if y[j] != y[j + 1] else 1.0
    p_sat = float(x[j] + min(max(t, 0.0), 1.0) * (x[j + 1] - x[j]))
    if x[-1] - p_sat >= SATURATION_MIN_WIDTH * (x[-1] - x[0]):
        return p_sat, ""
    return math.nan, (f"V_OC does not level off by {_kpa(x[-1])}: it stays within {100 * SATURATION_BAND:g} % of "
                      f"its full-scale change of its value there only from {_kpa(p_sat)}, less than the top "
                      f"{100 * SATURATION_MIN_WIDTH:g} % of the range")


def _region(name, x, y, v0, lo=None, hi=None):
    """The region ``name`` fitted on the samples (x, y), spanning [lo, hi] (default its first and last sample)."""
    if len(x) >= 2:
        slope, _, r2, _ = _fit(x, y)
    else:  # a region narrower than one sample
        slope, r2 = 0.0, math.nan
    rel = slope / v0 if v0 != 0 else math.nan
    return Region(name, float(x[0] if lo is None else lo), float(x[-1] if hi is None else hi), slope, rel, r2)


def _snap(P, V, lo, hi, span):
    """(P before, P after) of the first snap of the states (P, V) inside [lo, hi] (module doc), or None."""
    if not hi > lo:  # saturated from the lowest pressure on: no rise to snap in
        return None
    mean = span / (hi - lo)
    for i in range(P.size - 1):
        a, b = float(P[i]), float(P[i + 1])
        if a < lo or b > hi:
            continue
        dv = float(V[i + 1] - V[i])
        if dv >= SNAP_FRACTION * span and dv / (b - a) >= SNAP_STEEPNESS * mean:
            return a, b
    return None


def _split(x, y):
    """The knee index: two lines (one each side, sharing the knee) with the least total squared error."""
    n = len(x)
    m = max(3, n // 20)
    best, k_best = math.inf, None
    for k in range(m, n - m):
        e = _fit(x[:k + 1], y[:k + 1])[3] + _fit(x[k:], y[k:])[3]
        if e < best:
            best, k_best = e, k
    return k_best


def sensor_numbers(pressure_Pa, voc_V, retraction=None, p_range=None) -> SensorNumbers:
    """The sensor's numbers (module doc) of the approach curve V_OC(P) (``pressure_Pa`` increasing, ``voc_V``),
    with the retraction's (P, V_OC) arrays for the hysteresis, read over ``p_range`` = (lo, hi) in Pa
    (default: the whole curve) ∩ the pressures the curve reaches."""
    nan = math.nan
    P, V = _curve(pressure_Pa, voc_V)
    lo, hi = (-math.inf, math.inf) if p_range is None else (float(p_range[0]), float(p_range[1]))
    lo, hi = (max(lo, float(P[0])), min(hi, float(P[-1]))) if P.size else (lo, hi)
    reasons = {}
    if P.size < 2 or not hi > lo:
        why = (f"the approach reaches {P.size} pressure(s); 2 are needed" if P.size < 2 else
               f"the approach reaches no pressure range inside [{_kpa(float(p_range[0]))}, "
               f"{_kpa(float(p_range[1]))}]")
        return SensorNumbers(lo, hi, nan, (), nan, nan, nan, nan, nan, nan, {k: why for k in NUMBERS})
    x = np.linspace(lo, hi, SAMPLES)
    y = np.interp(x, P, V)
    v0 = float(y[0])
    span = float(np.max(y) - np.min(y))
    if not span > 1e-12 * max(float(np.max(np.abs(y))), 1e-300):
        flat = f"V_OC does not change from {_kpa(lo)} to {_kpa(hi)} (no response)"
        region = Region("no response", lo, hi, 0.0, 0.0 if v0 != 0 else nan, nan)
        reasons = {k: flat for k in ("knee_Pa", "sensitivity_above_knee_V_per_Pa", "saturation_Pa",
                                     "linear_range_Pa", "linear_r2", "voc_hysteresis_fraction")}
        if v0 == 0:
            reasons["sensitivity_rel_per_Pa"] = f"V_OC is 0 at {_kpa(lo)}: no baseline V0 to divide by"
        h, hf, why = _hysteresis(retraction, lo, hi, x, y, span)
        if why:
            reasons["voc_hysteresis_V"] = why
        return SensorNumbers(lo, hi, v0, (region,), nan, nan, nan, nan, h, nan, reasons)
    p_sat, why = _saturation(x, y, span)
    if why:
        reasons["saturation_Pa"] = why
    rising = x <= p_sat if math.isfinite(p_sat) else np.ones(x.size, bool)
    xr, yr = x[rising], y[rising]
    top = "up to saturation" if math.isfinite(p_sat) else "whole range"
    knee = nan
    single = _fit(xr, yr)[2] if xr.size >= 3 else 1.0
    snap = _snap(P, V, lo, float(xr[-1]), span)
    below = xr <= (snap[0] if snap else -math.inf)
    above = xr >= (snap[1] if snap else math.inf)
    if snap and np.count_nonzero(below) >= 2 and np.count_nonzero(above) >= 2:
        knee = snap[0]
        regions = [_region("below the snap", xr[below], yr[below], v0),
                   _region("the snap", np.array(snap), np.interp(snap, P, V), v0),
                   _region("above the snap", xr[above], yr[above], v0, hi=p_sat if math.isfinite(p_sat) else None)]
    elif not (single >= R2_LINEAR or math.isnan(single)) and xr.size >= 8:
        k = _split(xr, yr)
        knee = float(xr[k])
        regions = [_region("below the knee", xr[:k + 1], yr[:k + 1], v0),
                   _region("above the knee", xr[k:], yr[k:], v0, hi=p_sat if math.isfinite(p_sat) else None)]
    else:
        regions = [_region(top, xr, yr, v0, hi=p_sat if math.isfinite(p_sat) else None)]
        reasons["knee_Pa"] = (f"one line fits V_OC from {_kpa(lo)} to {_kpa(float(xr[-1]))} with R² = {single:.4g} "
                              f"≥ {R2_LINEAR:g}: no knee") if single >= R2_LINEAR else \
            f"V_OC is constant from {_kpa(lo)} to {_kpa(float(xr[-1]))}: no knee"
        reasons["sensitivity_above_knee_V_per_Pa"] = reasons["knee_Pa"]
    if math.isfinite(p_sat):
        regions.append(_region("saturated", x[x >= p_sat], y[x >= p_sat], v0, lo=p_sat))
    if v0 == 0:
        reasons["sensitivity_rel_per_Pa"] = f"V_OC is 0 at {_kpa(lo)}: no baseline V0 to divide by"
    lin, r2_lin = _linear_range(x[x <= regions[0].p_hi_Pa], y[x <= regions[0].p_hi_Pa], reasons)
    h, hf, why = _hysteresis(retraction, lo, hi, x, y, span)
    if why:
        reasons["voc_hysteresis_V"] = reasons["voc_hysteresis_fraction"] = why
    return SensorNumbers(lo, hi, v0, tuple(regions), knee, p_sat, lin, r2_lin, h, hf, reasons)


def _linear_range(x, y, reasons):
    if len(x) < 3:
        why = f"the lowest region ({_kpa(x[0])} to {_kpa(x[-1])}) is narrower than three samples"
        reasons["linear_range_Pa"] = reasons["linear_r2"] = why
        return math.nan, math.nan
    r2 = _r2_prefix(x, y)
    fits = np.flatnonzero(r2[2:] >= R2_LINEAR) + 2
    if fits.size:
        k = int(fits[-1])
        return float(x[k]), float(r2[k])
    why = (f"V_OC does not change from {_kpa(x[0])} to {_kpa(x[-1])}" if np.all(np.isnan(r2[2:])) else
           f"no line from {_kpa(x[0])} fits V_OC with R² >= {R2_LINEAR:g} (best {np.nanmax(r2[2:]):.4g})")
    reasons["linear_range_Pa"] = reasons["linear_r2"] = why
    return math.nan, math.nan


def _hysteresis(retraction, lo, hi, x, y, span):
    """(largest |ΔV| V, over the full-scale change, reason if n/a)."""
    nan = math.nan
    if retraction is None:
        return nan, nan, "no retraction branch given"
    Pr, Vr = _curve(*retraction)
    if Pr.size < 2:
        return nan, nan, f"the retraction reaches {Pr.size} pressure(s); 2 are needed"
    a, b = max(lo, float(Pr[0])), min(hi, float(Pr[-1]))
    if not b > a:
        return nan, nan, f"the retraction reaches no pressure between {_kpa(lo)} and {_kpa(hi)}"
    inside = (x >= a) & (x <= b)
    xs = np.r_[a, x[inside], b]
    dv = float(np.max(np.abs(np.interp(xs, Pr, Vr) - np.interp(xs, x, y))))
    return dv, (dv / span if span > 0 else nan), ""


def describe(numbers: SensorNumbers) -> list:
    """Markdown lines: the regions' table and the sensor's numbers, every n/a with its reason."""
    def v(x, scale, unit, name=None):
        if x is None or not math.isfinite(x):
            why = numbers.reason(name) if name else ""
            return f"n/a ({why})" if why else "n/a"
        return f"{x * scale:.4g} {unit}".strip()

    lines = ["| region | pressures | sensitivity | relative sensitivity | R² of its line |", "|---|---|---|---|---|"]
    for r in numbers.regions:
        rel = v(r.relative_per_Pa, 1e3, "kPa⁻¹", "sensitivity_rel_per_Pa")
        slope = v(r.sensitivity_V_per_Pa, 1e3, "V/kPa")
        lines.append(f"| {r.name} | {_kpa(r.p_lo_Pa)} to {_kpa(r.p_hi_Pa)} | {slope} | "
                     f"{rel} | {v(r.r2, 1, '') if math.isfinite(r.r2) else 'n/a (V_OC constant)'} |")
    if not numbers.regions:
        lines.append(f"| n/a ({numbers.reason('sensitivity_V_per_Pa')}) | | | | |")
    f = numbers.flat()
    lines += ["", "| number | value |", "|---|---|",
              f"| knee | {v(f['knee_Pa'], 1e-3, 'kPa', 'knee_Pa')} |",
              f"| saturation pressure | {v(f['saturation_Pa'], 1e-3, 'kPa', 'saturation_Pa')} |",
              f"| linear range (R² ≥ {R2_LINEAR:g}) | "
              + (f"{_kpa(numbers.p_lo_Pa)} to {_kpa(f['linear_range_Pa'])}, R² = {f['linear_r2']:.4g}"
                 if math.isfinite(f["linear_range_Pa"]) else v(math.nan, 1, "", "linear_range_Pa")) + " |",
              f"| hysteresis of V_OC | {v(f['voc_hysteresis_V'], 1, 'V', 'voc_hysteresis_V')}"
              + (f" ({100 * f['voc_hysteresis_fraction']:.3g} % of the full-scale change)"
                 if math.isfinite(f["voc_hysteresis_fraction"]) else "") + " |"]
    return lines


__all__ = ["NUMBERS", "R2_LINEAR", "SATURATION_BAND", "SATURATION_MIN_WIDTH", "SNAP_FRACTION", "SNAP_STEEPNESS",
           "Region", "SensorNumbers",
           "describe", "sensor_numbers"]
