"""The charged pattern's near field of a design (issue 51): the field and gap voltage of the charge its contact map
leaves, in the first micrometres of separation, against the uniform sheet σ A/S the device model uses.

The charge: the approach map at the largest pressure a design kept (the charged area at the pressure released),
each pixel 1 where its gap g = H + 1 is at most the law's peak-tension separation g_c (the charged-area
definition, :func:`tengsim.analysis.charged_area`), else 0; its mean is the map's A/S (it differs from the design's
sub-pixel A/S by the edge pixels, said beside it). The cell is one period of the array (pitches n_x dx × n_y dy);
a ``free`` design's cell is taken as one cell of a periodic array of the cell's size (its charge's images).
The field is :class:`tengsim.device.nearfield.PatternField`'s (exact Fourier modes in the layered gap, open
circuit, the moving electrode at the sheet's mean potential); at each gap x of :data:`GAPS_M` and the pitch:

* ``peak_over_uniform``: max over the cell of |E_u + E_p(z = 0)| / E_u at the charged surface, E_u = σ (A/S)/ε0;
* ``voltage_spread_over_uniform``: (max − min) of the surface potential over the sheet's gap voltage σ (A/S) x/ε0;

and ``decay_height_m``: in an open gap (x = max(d0, 10 × the pitch)), the height above which the pattern's field
is within :data:`LEVEL` of E_u everywhere in the cell (it scales with the pitch: exp(−2π z/p) of the first mode).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

GAPS_M = (0.1e-6, 1e-6, 10e-6)
"""The gaps (m) the near field is given at, besides the pitch."""
GAP_NAMES = ("100nm", "1um", "10um", "pitch")
"""Their names in design.nc's attributes (``nearfield_peak_over_uniform_at_1um``)."""
LEVEL = 0.01
"""The decay height's level: the pattern's field at most this × the uniform field."""
NO_MAPS = "no maps kept (maps = false): no contact map to take the charge from"


@dataclass(frozen=True)
class NearField:
    """The near field of one charged pattern (SI; module doc). Tuples run over ``gaps_m`` (:data:`GAPS_M` and the
    pitch)."""

    pressure_Pa: float
    """The nominal pressure of the map the charge is taken from (NaN where given a map directly)."""
    area_fraction: float
    """A/S of the charged map (its mean)."""
    pitch_x_m: float
    pitch_y_m: float
    pixels: tuple
    uniform_field_V_m: float
    """σ (A/S)/ε0: the uniform sheet's gap field, open circuit."""
    gaps_m: tuple
    peak_field_V_m: tuple
    """max over the cell of |E_u + E_p| at the charged surface, at each gap."""
    peak_over_uniform: tuple
    voltage_spread_V: tuple
    """max − min over the cell of the surface potential (the local gap voltage's spread), at each gap."""
    voltage_spread_over_uniform: tuple
    decay_gap_m: float
    """The open gap the decay height is measured in: max(d0, 10 × the pitch)."""
    decay_height_m: float
    boundary: str = "periodic"


def charged_fraction(H, g_c: float) -> np.ndarray:
    """The charged map of a kept gap map ``H`` (ε; g = H + 1): 1 where g <= ``g_c``, else 0."""
    return (np.asarray(H, float) + 1.0 <= float(g_c)).astype(float)


def decay_height(pf, gap_m: float, level: float = LEVEL) -> float:
    """The height (m) above which max |E_p| over the cell stays at most ``level`` × the uniform field, in the gap
    ``gap_m`` (0 for a uniform map; NaN where the field exceeds it up to the top electrode). Bracketed on a
    geometric ladder of heights and bisected to 1e-3 of the height (each mode's field falls monotonically in z)."""
    lim = level * pf.uniform_field()

    def above(z):
        return float(np.max(np.abs(pf.field_z(gap_m, z)))) > lim

    if not above(0.0):
        return 0.0
    pixel = min(pf.pitch_m / pf.fraction.shape[0], pf.pitch_y_m / pf.fraction.shape[1])
    zs = np.geomspace(pixel / 100, gap_m, 25)
    flags = [above(z) for z in zs]
    if flags[-1]:
        return math.nan
    last = max(i for i, f in enumerate(flags) if f) if any(flags) else -1
    lo, hi = (0.0 if last < 0 else zs[last]), zs[last + 1]
    while hi - lo > 1e-3 * hi:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if above(mid) else (lo, mid)
    return float(hi)


def pattern_nearfield(fraction, pitch_x_m: float, pitch_y_m: float, sigma_C_m2: float, thickness_m: float,
                      eps_r: float, rest_gap_m: float, pressure_Pa: float = math.nan,
                      boundary: str = "periodic") -> NearField:
    """The :class:`NearField` of a charged ``fraction`` map (axis 0 along x) of a cell ``pitch_x_m`` ×
    ``pitch_y_m`` at :data:`GAPS_M` and the pitch (the longer side), its decay height in the gap max(``rest_gap_m``,
    10 × the pitch)."""
    from tengsim.device.nearfield import PatternField

    pf = PatternField(fraction, pitch_x_m, sigma_C_m2, thickness_m, eps_r, pitch_y_m=pitch_y_m)
    pitch = max(pf.pitch_m, pf.pitch_y_m)
    e_u = pf.uniform_field()
    gaps = (*GAPS_M, pitch)
    peak, spread = [], []
    for x in gaps:
        peak.append(float(np.max(np.abs(e_u + pf.field_z(x, 0.0)))))
        spread.append(float(np.ptp(pf.surface_potential(x))))
    v_u = [e_u * x for x in gaps]  # σ (A/S) x/ε0
    x_open = max(float(rest_gap_m), 10 * pitch)
    with np.errstate(divide="ignore", invalid="ignore"):
        return NearField(
            pressure_Pa=float(pressure_Pa), area_fraction=pf.area_fraction, pitch_x_m=pf.pitch_m,
            pitch_y_m=pf.pitch_y_m, pixels=tuple(pf.fraction.shape), uniform_field_V_m=e_u, gaps_m=gaps,
            peak_field_V_m=tuple(peak), peak_over_uniform=tuple(p / e_u if e_u > 0 else math.nan for p in peak),
            voltage_spread_V=tuple(spread),
            voltage_spread_over_uniform=tuple(s / v if v > 0 else math.nan for s, v in zip(spread, v_u)),
            decay_gap_m=x_open, decay_height_m=decay_height(pf, x_open) if e_u > 0 else math.nan,
            boundary=boundary)


def _released_map(res):
    """The approach map at the largest pressure ``res`` kept and that pressure (Pa); (None, NaN) if none."""
    maps = [m for m in (getattr(res, "maps", None) or []) if str(m["branch"]) == "approach" and m.get("H") is not None]
    if not maps:
        return None, math.nan
    m = max(maps, key=lambda m: float(m["D"]))
    a = res.branch("approach")
    D = np.asarray(a["D"], float)
    i = int(np.argmin(np.abs(D - float(m["D"]))))
    return m, float(np.asarray(a["pressure_Pa"], float)[i])


def design_nearfield(res, plan):
    """The :class:`NearField` of a design's run ``res`` (holding its kept maps) and ``plan``: the charge of the
    approach map at the largest pressure kept; None where no maps were kept (``plan.maps`` false)."""
    from tengsim.design.walk import peak_separation

    if res is None or not getattr(plan, "maps", True):
        return None
    m, p_pa = _released_map(res)
    g_c = peak_separation(plan)
    if m is None or g_c is None:
        return None
    f = charged_fraction(m["H"], g_c)
    lat = res.scaling.lateral
    nx, ny = f.shape
    return pattern_nearfield(f, nx * res.grid.dx * lat, ny * res.grid.dy * lat, plan.sigma, plan.T, plan.eps_r,
                             plan.gap, p_pa, str(getattr(plan, "boundary", "periodic")))


def attributes(nf) -> dict:
    """design.nc's global attributes of a :class:`NearField` (names ending in their unit; 'n/a: why' without)."""
    keys = ["nearfield_pressure_Pa", "nearfield_area_fraction", "nearfield_cell_x_m", "nearfield_cell_y_m",
            "nearfield_uniform_field_V_m", "nearfield_decay_gap_m", "nearfield_decay_height_m"]
    keys += [f"nearfield_{q}_at_{g}" for q in ("peak_over_uniform", "voltage_spread_over_uniform") for g in GAP_NAMES]
    if nf is None:
        return {"nearfield_model": f"n/a: {NO_MAPS}", **{k: f"n/a: {NO_MAPS}" for k in keys}}
    vals = [nf.pressure_Pa, nf.area_fraction, nf.pitch_x_m, nf.pitch_y_m, nf.uniform_field_V_m, nf.decay_gap_m,
            nf.decay_height_m, *nf.peak_over_uniform, *nf.voltage_spread_over_uniform]
    out = {"nearfield_model": _model_text(nf)}
    for k, v in zip(keys, vals):
        out[k] = float(v) if math.isfinite(v) else "n/a"
    if not math.isfinite(nf.decay_height_m):
        out["nearfield_decay_height_m"] = (f"n/a: the pattern's field exceeds {100 * LEVEL:g} % of the uniform one "
                                           "up to the top electrode")
    return out


def _model_text(nf) -> str:
    cell = "one cell of the periodic array" if nf.boundary == "periodic" else \
        "the free cell taken as one cell of a periodic array of its size"
    return (f"charge: the approach map at the largest pressure kept, pixels with g <= g_c ({nf.pixels[0]}x"
            f"{nf.pixels[1]}), {cell}; exact Fourier modes in the layered gap, open circuit "
            "(tengsim.device.nearfield.PatternField); peak: max |E| at the charged surface over sigma (A/S)/eps0; "
            "spread: max - min of the surface potential over sigma (A/S) x/eps0; decay height: the pattern's field "
            f"within {100 * LEVEL:g} % of the uniform one above it, in the open gap")


def report_line(nf) -> str:
    """The report's line: the pattern's peak field and gap-voltage spread at each gap, its decay height."""
    if nf is None:
        return f"Near field of the charged pattern: n/a ({NO_MAPS})."
    from tengsim.units import length_text

    cell = "" if nf.boundary == "periodic" else "; the free cell taken as one cell of a periodic array of its size"
    rows = list(zip(nf.peak_over_uniform, nf.voltage_spread_over_uniform, nf.gaps_m))
    if any(math.isclose(rows[-1][2], g, rel_tol=1e-9) for g in GAPS_M):
        rows = rows[:-1]  # the pitch is one of the gaps already
    at = ", ".join(f"{p:.3g}× / {100 * s:.3g} % at {length_text(x)}" for p, s, x in rows)
    dh = (f"within {100 * LEVEL:g} % of the uniform field above {length_text(nf.decay_height_m)} of the surface"
          if math.isfinite(nf.decay_height_m) else f"not within {100 * LEVEL:g} % of the uniform field below the top "
                                                   "electrode")
    return (f"Near field of the charged pattern (the approach map at {nf.pressure_Pa / 1e3:.3g} kPa: A/S "
            f"{nf.area_fraction:.4g} on {nf.pixels[0]}×{nf.pixels[1]} pixels of a {length_text(nf.pitch_x_m)} × "
            f"{length_text(nf.pitch_y_m)} cell{cell}; uniform sheet σ A/S/ε0 = "
            f"{nf.uniform_field_V_m / 1e6:.3g} V/µm, open circuit): the largest local field at the charged surface "
            f"over the uniform one / the gap voltage's spread over the cell over σ A/S x/ε0: {at}; the pattern's "
            f"field is {dh} (gap {length_text(nf.decay_gap_m)}).")
