"""From a contact result to a design's numbers: per asked pressure on each branch, and per design.

**Load-controlled branches.**  A pressed device passes, on the approach, the states whose load is above every
earlier load (:func:`tengsim.run.area.load_control`, the zero-load state interpolated in first); on the
retraction, the states whose load is below every earlier one.  Each asked pressure takes the value linearly
interpolated in pressure between the two states around it on that branch; NaN outside the pressures a branch
reaches.  At a snap (the load drops while D grows) the branch keeps the first state reached at a pressure.

**Charged area A/S** (the area that makes the charge, Eq. 12), by the plan's definition
(:data:`tengsim.run.area.DEFINITIONS`): by default ``contact``, the 2-D area where the gap is below the law's
peak-tension separation, measured on each state's map (:func:`tengsim.analysis.charged_area`: the same for
every shape); or ``paper``, the paper's construction from Greenwood's contact length Λc along X through the
apex (:func:`tengsim.run.area.area_fraction`: Λc² for a square patch, π/4 Λc² for a disc, Λc × L for a ridge,
over the cell area).  The repulsive area (pixels with P > 0) is reported beside it.

**Per design** (:func:`summarize`): jump-in pressure (:func:`snap_in`: the nominal pressure of a pressed device
on the approach just before it first snaps into contact within [p_min, p_max], the load-controlled branch's first
fold; the start, an adhesive apex drawn in at zero load, is the branch's first state, not a snap), pull-off (the most tensile load of the retraction, in N per cell
and Pa; none where the retraction never pulls: no tension), full-contact pressure (the approach pressure at
which A/S reaches 95 % of its full-contact value, the footprint's, interpolated between the two states around
it; none beyond the asked range), the sensor's numbers of V_OC (Eq. 12) over [p_min, p_max]: sensitivity per
pressure region, knee, saturation pressure, linear range with its R², hysteresis of V_OC
(:mod:`tengsim.device.sensor`, the one definition), and the energy lost per cycle ∮F dD per unit nominal area
(J/m²) and the largest difference of A/S between retraction and approach at an asked pressure.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tengsim.run.area import FULL_CONTACT_AREA_FRACTION


DEFINITIONS = {
    "square": "the paper's definition, A/S = Λc²/S: the square patch of side Λc, Greenwood's contact length (the "
              "tensile-peak length along X through the apex), over the cell area S",
    "disc": "the paper's definition, A/S = (π/4)Λc²/S: the disc of diameter Λc, Greenwood's contact length (the "
            "tensile-peak length along X through the apex), over the cell area S",
    "line": "the paper's definition, A/S = Λc/L: the strip of width Λc, Greenwood's contact length (the "
            "tensile-peak length across the ridge), over the cell width L",
}


def _params(res, plan) -> dict:
    return {**res.params, "config": {"shape": plan.shape}}


def _shape(plan):
    """The plan's shape object (None for a plan without its contact plan): what A/S asks (:func:`tengsim.run.area.patch`)."""
    return getattr(getattr(plan, "contact_plan", None), "shape", None)


def area_definition(plan) -> str:
    """The plan's charged-area definition: 'contact' (default) or 'paper'."""
    return getattr(plan, "area", "contact") or "contact"


CONTACT_DEFINITION = ("the 2-D contact area, A/S = area where the gap is below the separation of the law's peak "
                      "tension ({law}; Greenwood's contact edge; a law without tension: its wall's gap), measured on "
                      "the contact map, over the cell area S")
"""The charged-area definition ``contact`` in words (the report's line), ``{law}`` the result's law."""


def states(res, plan) -> dict:
    """{'approach'|'retraction': {'P' (Pa, increasing), 'area' (A/S), 'repulsive' (fraction)}} of the
    load-controlled states (module doc, :func:`tengsim.run.area.branch_states`), A/S by the plan's definition."""
    from tengsim.run.area import branch_states

    return branch_states(res, area_definition(plan), _params(res, plan), _shape(plan))


def branch_curves(res, plan) -> dict:
    """Per branch, at the asked pressures: 'area' (A/S), 'repulsive', 'voc_eq12', 'voc_eq17' (V), 'dvoc_dp' (V/Pa)."""
    from tengsim.device.formulas import voc_apart, voc_polymer
    from tengsim.run.area import at_pressures

    ps = np.asarray(plan.pressures, float)
    out = {}
    for b, s in states(res, plan).items():
        A = np.clip(at_pressures(s["P"], s["area"], ps), 0.0, 1.0)
        R = at_pressures(s["P"], s["repulsive"], ps)
        V12 = voc_polymer(A, plan.sigma, plan.eps_r, plan.T)
        V17 = voc_apart(plan.sigma, A, plan.gap, 1.0)
        dV = np.full(len(ps), np.nan)
        ok = np.flatnonzero(np.isfinite(V12))
        if len(ok) >= 2:
            dV[ok] = np.gradient(V12[ok], ps[ok])
        out[b] = {"area": A, "repulsive": R, "voc_eq12": V12, "voc_eq17": V17,
                  "dvoc_dp": dV}
    return out


def _full_fraction(res, params, shape) -> float:
    """A/S in full contact (NaN where the shape has no known full-contact area)."""
    from tengsim.run.area import area_fraction, full_length

    full = full_length(params, shape)
    return float(area_fraction(res, [full], params, shape)[0]) if math.isfinite(full) else math.nan


@dataclass(frozen=True)
class Reading:
    """What a design reads of its refined result, asked of the layers below in one go (:func:`read`): ``curves``
    (:func:`branch_curves`), the load-controlled ``states`` (:func:`states`), ``full`` (A/S in full contact, NaN
    where the shape has no known full-contact area), ``definition`` (the charged-area definition in words) and
    ``sensor`` (:func:`tengsim.device.sensor.sensor_numbers` of V_OC (Eq. 12) on the approach states over
    [p_min, p_max], the retraction's for the hysteresis)."""

    curves: dict
    states: dict
    full: float
    definition: str
    sensor: object


def read(res, plan) -> Reading:
    """The :class:`Reading` of ``res``: the design's own settings first, then the run layer's A/S
    (:mod:`tengsim.run.area`) and the device model's sensor numbers (:mod:`tengsim.device.sensor`)."""
    import dataclasses

    from tengsim.device.formulas import voc_polymer
    from tengsim.device.sensor import sensor_numbers
    from tengsim.run.area import CHARGED_COLUMN, branch_states, patch

    params, shape, how, back = _params(res, plan), _shape(plan), area_definition(plan), solved_back(plan)
    curves = branch_curves(res, plan)
    st = branch_states(res, how, params, shape)
    full = _full_fraction(res, params, shape)
    if how == "contact" and CHARGED_COLUMN in res.table:
        words = CONTACT_DEFINITION.format(law=res.params.get("law") or "the law")
    else:
        words = DEFINITIONS[patch(shape, params)[1]]
    V = voc_polymer(np.clip(st["approach"]["area"], 0.0, 1.0), plan.sigma, plan.eps_r, plan.T)
    pulled = (st["retraction"]["P"], voc_polymer(np.clip(st["retraction"]["area"], 0.0, 1.0), plan.sigma, plan.eps_r,
                                                 plan.T)) if back else None
    numbers = sensor_numbers(st["approach"]["P"], V, pulled, (plan.pressures[0], plan.pressures[-1]))
    if not back:
        numbers = dataclasses.replace(numbers, reasons={**numbers.reasons, **{
            k: NOT_RETRACTED for k in ("voc_hysteresis_V", "voc_hysteresis_fraction")}})
    return Reading(curves, st, full, words, numbers)


NOT_RETRACTED = "not solved: retraction = false, the approach only"
"""Why a number of the retraction is n/a in a design that solved the approach only."""


def solved_back(plan) -> bool:
    """Whether the design solved the retraction (``retraction``, true by default)."""
    return bool(getattr(plan, "retraction", True))


def design_status(res, p_max: float) -> str:
    """The status of the rows a design's numbers are read from: every row at a nominal pressure up to the first
    approach state at or past ``p_max`` (the walk may run a little deeper, where a periodic array in full
    contact presses the law's wall: rows no number reads), and the refinement's own status."""
    from tengsim import status as _status

    t = res.table
    s = np.asarray(t.get("status"), dtype=str) if t.get("status") is not None else None
    if s is None or "pressure_Pa" not in t:
        return str(res.status)
    P = np.asarray(t["pressure_Pa"], float)
    br = np.asarray(t["branch"]).astype(str)
    past = np.flatnonzero((br == "approach") & (P >= p_max))
    top = P[past[0]] if len(past) else np.inf
    keep = ~(P > top * (1 + 1e-12))
    refined = res.params.get("resolve_status")
    return str(_status.overall([*s[keep].tolist(), *([str(refined)] if refined else [])]))


def crossing(P, A, level) -> float:
    """The pressure at which A(P) first reaches ``level``, linear between the two states around it (the first
    state itself if it is there already); NaN if never."""
    P, A = np.asarray(P, float), np.asarray(A, float)
    hit = np.flatnonzero(A >= level)
    if not len(hit):
        return math.nan
    i = int(hit[0])
    if i == 0 or not A[i] > A[i - 1]:
        return float(P[i])
    return float(P[i - 1] + (level - A[i - 1]) * (P[i] - P[i - 1]) / (A[i] - A[i - 1]))



SNAP_DROP = 1e-3
"""A fold is a snap where the path's load falls, before it is regained, by more than this fraction of p_max (a
smaller dip is the solver's noise, and the area it skips is nothing a device shows)."""


def snap_in(P, area, p_range) -> float:
    """The nominal pressure just before a pressed device first snaps into contact within ``p_range`` = (p_min,
    p_max), Pa; NaN if it does not.  ``P`` and ``area`` are the approach's path states in order (D increasing).
    Under a load the device passes the states whose P is above every earlier one, from zero load on
    (:func:`tengsim.run.area.load_control`); a fold is a state after which P falls by more than
    :data:`SNAP_DROP` × p_max before a later state exceeds it: the device snaps from the fold to that state.  It
    is a snap into contact where the area grows across it.  A fold past p_max is never taken (beyond it the walk
    may press the law's wall: rows no number reads), nor a jump the D-controlled walk records that the load does
    not make."""
    P, area = np.asarray(P, float), np.asarray(area, float)
    lo, hi = float(p_range[0]), float(p_range[-1])
    drop = SNAP_DROP * abs(hi)
    best, i_best, low = 0.0, None, math.inf
    for k, p in enumerate(P):
        if not math.isfinite(p):
            continue
        if p > best:
            if i_best is not None and low < best - drop and area[k] > area[i_best] and lo <= best <= hi:
                return float(best)
            if best > hi:
                break
            best, i_best, low = float(p), k, math.inf
        else:
            low = min(low, float(p))
    return math.nan


def _grids_text(res) -> str:
    from tengsim.units import length_text

    lat = res.scaling.lateral
    tab = res.params.get("resolution") or {}
    if not tab:
        return f"{res.grid.nx}×{res.grid.ny} (dx {length_text(res.grid.dx * lat)})"
    return ", ".join(f"{nx}×{ny} (dx {length_text(dx * lat)})" for nx, ny, dx in zip(tab["nx"], tab["ny"], tab["dx"]))


def summarize(res, plan) -> tuple[dict, dict, list]:
    """(summary {name: value}, convergence {number: relative change between the last two grids}, notes)."""
    from tengsim.units import pressure_text

    from tengsim.run.area import CHARGED_COLUMN

    sc = res.scaling
    k_p = sc.pressure(1.0)
    a = res.branch("approach")
    col = CHARGED_COLUMN if area_definition(plan) == "contact" and CHARGED_COLUMN in a else "contact_length"
    back = solved_back(plan)
    jump_in = snap_in(k_p * np.asarray(a["F"], float), a[col], (plan.pressures[0], plan.pressures[-1]))
    status_now = design_status(res, plan.pressures[-1])
    r = read(res, plan)  # the layers below asked once
    app, ret = r.curves["approach"], r.curves["retraction"]
    st, full, numbers = r.states["approach"], r.full, r.sensor
    notes = [physical_message(str(res.params["resolve_message"]), sc.lateral)] if res.params.get("resolve_message") \
        else []
    full_P = math.nan
    if math.isfinite(full):
        full_P = crossing(st["P"], st["area"], FULL_CONTACT_AREA_FRACTION * full)
        if not full_P <= plan.pressures[-1] * (1 + 1e-9):
            full_P = math.nan
            notes.append(f"full contact (A/S >= {FULL_CONTACT_AREA_FRACTION:g} × {full:.3g}) is not reached by "
                         f"{pressure_text(plan.pressures[-1])}")
    diff = ret["area"] - app["area"]
    loop = res.loop_energy  # 0 where within its uncertainty, never a negative energy of quadrature error
    pull = float(res.pull_off_force)
    if pull >= 0:  # the retraction never pulls (a law without tension): no pull-off, not the least push
        notes.append("no pull-off: the retraction carries no tensile load")
    summary = {
        "status": status_now,
        "tabor": sc.mu,
        "jump_in_Pa": jump_in,
        "pull_off_N": sc.force(pull) if pull < 0 else math.nan,
        "pull_off_Pa": k_p * pull if pull < 0 else math.nan,
        "full_contact_Pa": full_P,
        **numbers.flat(),
        "sensor": numbers,
        "hysteresis_J_m2": sc.work(loop.value) / sc.cell_area if back else math.nan,
        "hysteresis_bound_J_m2": sc.work(loop.bound) / sc.cell_area if back else math.nan,
        "area_hysteresis": float(np.nanmax(np.abs(diff))) if np.any(np.isfinite(diff)) else math.nan,
        "area_at_p_max": float(app["area"][-1]),
        "voc_eq12_at_p_max_V": float(app["voc_eq12"][-1]),
        "voc_eq17_at_p_max_V": float(app["voc_eq17"][-1]),
        "voc_finite_at_p_max_V": _finite_voc(plan, float(app["voc_eq17"][-1])),
        "grids": _grids_text(res),
        "tolerance": plan.rel_tol,
        "charged_area_definition": r.definition,
        "seconds": float(res.params.get("resolve_seconds", res.seconds)),
    }
    summary["reasons"] = na_reasons(summary, numbers, plan, full, drawn_in=bool(len(a["F"]) and a["F"][0] < 0))
    if not back:
        summary["reasons"].update({k: NOT_RETRACTED for k in ("pull_off_N", "pull_off_Pa", "hysteresis_J_m2",
                                                              "hysteresis_bound_J_m2", "area_hysteresis")})
    conv = convergence(res)
    return summary, conv, notes


def _finite_voc(plan, voc_eq17: float) -> float:
    """Eq. 17's V_OC at p_max with the finite field of the design's device (tengsim.design.breakdown)."""
    if not math.isfinite(voc_eq17):
        return math.nan
    from tengsim.design.breakdown import finite_voc_ratio

    return voc_eq17 * finite_voc_ratio(float(plan.eps_r), float(plan.T), float(plan.gap))


def na_reasons(summary: dict, numbers, plan, full: float, drawn_in: bool = False) -> dict:
    """{number: why it is n/a} for the per-design numbers that are NaN (the sensor's from its own reasons);
    ``drawn_in``: the approach starts attracted (an adhesive apex drawn into contact at zero load)."""
    from tengsim.units import pressure_text

    top = pressure_text(plan.pressures[-1])
    start = "the apex is drawn in at zero load, then " if drawn_in else ""
    why = {"jump_in_Pa": f"no jump into contact on the approach between {pressure_text(plan.pressures[0])} and "
                         f"{top}: {start}the contact grows under the load without a snap",
           "full_contact_Pa": (f"A/S does not reach {FULL_CONTACT_AREA_FRACTION:g} of the footprint's by {top}"
                               if math.isfinite(full) else "the shape has no known full-contact area"),
           "pull_off_N": "no tensile load on the retraction", "pull_off_Pa": "no tensile load on the retraction",
           "area_hysteresis": "the retraction reaches none of the asked pressures",
           "area_at_p_max": f"the approach does not reach {top}", "voc_eq12_at_p_max_V": f"the approach does not "
           f"reach {top}", "voc_eq17_at_p_max_V": f"the approach does not reach {top}",
           "voc_finite_at_p_max_V": f"the approach does not reach {top}",
           **numbers.reasons}
    out = {}
    for k, text in why.items():
        v = summary.get(k)
        if isinstance(v, (int, float)) and not math.isfinite(float(v)):
            out[k] = text
    return out


def physical_message(text: str, lateral: float) -> str:
    """The refinement's message in the user's units: dx values (X units) as lengths, A/S observables named."""
    import re

    from tengsim.units import length_text

    def dx(m):
        return f"dx {m.group(1)} {length_text(float(m.group(2)) * lateral)}"

    # a number in X units only: the refinement writes a physical run's lengths with their unit already
    text = re.sub(r"dx (=|≈|below) ([0-9.]+(?:e[-+]?[0-9]+)?)(?![0-9.e]|\s*[pnµumk]?m\b)", dx, text)
    return re.sub(r"A_S_(app|ret)_([0-9p.e+]+)Pa",
                  lambda m: f"A/S at {float(m.group(2).replace('p', '.')) / 1e3:g} kPa "
                            f"({'approach' if m.group(1) == 'app' else 'retraction'})", text)


RETRACTION_AREA = "charged area A/S on the retraction (largest over the pressures; recorded, not judged)"
HYSTERESIS = "hysteresis energy (recorded, not judged)"


def convergence(res) -> dict:
    """{number: relative change between the last two grids}: the judged numbers, A/S on the approach (the
    largest over the asked pressures), pull-off force, jump-in and jump-out D; then the retraction's numbers the
    refinement records but does not judge (:func:`tengsim.design.walk.observers`): A/S on the retraction (the
    largest over the pressures it reaches on both grids) and the hysteresis energy; NaN with one grid."""
    rich = res.params.get("richardson") or {}
    watched = res.params.get("watched") or {}
    out = {}

    def largest(table, prefix):
        vals = [r.get("change", math.nan) for n, r in table.items() if n.startswith(prefix)]
        vals = [a for a in vals if math.isfinite(a)]
        return max(vals) if vals else math.nan

    out["charged area A/S (largest over the pressures)"] = largest(rich, "A_S_app")
    for key, label in (("pull_off_F", "pull-off force"), ("jump_in_D", "jump-in D"), ("jump_out_D", "jump-out D")):
        out[label] = float(rich.get(key, {}).get("change", math.nan))
    out[RETRACTION_AREA] = largest(watched, "A_S_ret")
    h = [float(x) for x in (res.params.get("resolution") or {}).get("hysteresis_W", [])][-2:]
    # relative to the finest value itself (no floor: the energy's scale is its own); 0 on both grids (within
    # each grid's uncertainty, tengsim.results.hysteresis) is no change
    out[HYSTERESIS] = (abs(h[1] - h[0]) / abs(h[1]) if h[1] != 0 else 0.0 if h[0] == 0 else math.nan) \
        if len(h) == 2 else math.nan
    return out


def area_name(branch: str, p: float) -> str:
    """The refinement's observable name of A/S on ``branch`` at the pressure ``p`` (Pa)."""
    return f"A_S_{branch[:3]}_{p:.6g}Pa".replace("+", "").replace(".", "p")
