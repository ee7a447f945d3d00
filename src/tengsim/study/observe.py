"""Per-point observables of a design study (definitions in docs/design.md).

From one contact result (approach–retraction, dimensionless, Eq. 7/10) and the Eq. (12) device inputs
σ, ε_r, T.  Observables in the contact's own units (pull-off F, jump D, transition D, hysteresis,
charged-area fraction at zero load) exist for every run; those in pressure (V_OC at named pressures,
sensitivity, linear range, saturation, V_OC(P) curves) need a physical scaling and are NaN otherwise.
"""
from __future__ import annotations

import math

import numpy as np

from tengsim.errors import TengsimError
from tengsim.results.result import TRANSITION_LENGTH_FRACTION
from tengsim.run.area import (ADHESIVE_FULL_CONTACT_LENGTH_FRACTION, cell_side, full_length, loaded_area,
                               physical_scale)

OBSERVABLE_DEFAULTS = {
    "pressures": ("1kPa", "10kPa", "100kPa"),
    "fit_range": None,
    "grid_max": "150kPa",
    "grid_num": 61,
    "transition_fraction": TRANSITION_LENGTH_FRACTION,
    "full_contact_fraction": ADHESIVE_FULL_CONTACT_LENGTH_FRACTION,
}

SCALARS = {
    # name: (units, long name)
    "pull_off_F": ("3π W ε m²/n² (Eq. 10)", "most tensile force on retraction (negative: tensile)"),
    "pull_off_Pa": ("Pa", "pull-off force per cell area (negative: tensile)"),
    "jump_in_D": ("ε", "D at which the approach first lands on the jumped-in state"),
    "jump_out_D": ("ε", "D at which the retraction first lands on the jumped-out state"),
    "transition_D": ("ε", "approach D where Λc reaches transition_fraction of full contact"),
    "area_fraction_0": ("1", "charged-area fraction A/S at zero load (approach)"),
    "adhesive_full_contact": ("1", "1 if Λc at zero load >= full_contact_fraction × full contact (2N)"),
    # the sensor's numbers over fit_range (tengsim.device.sensor, the one definition the design uses too)
    "S_V_per_kPa": ("V/kPa", "sensitivity dV_OC/dP of the lowest pressure region (least-squares slope)"),
    "S_rel_per_kPa": ("kPa-1", "relative sensitivity (dV_OC/dP)/V0 of that region, V0 = V_OC at fit_range[0]"),
    "S_to_Pa": ("Pa", "top of that region (the knee, the saturation pressure or the top of the range)"),
    "knee_Pa": ("Pa", "knee of V_OC(P): where two lines fit better than one (NaN: one line fits, R2 >= 0.99)"),
    "S_above_knee_V_per_kPa": ("V/kPa", "sensitivity dV_OC/dP above the knee"),
    "linear_range_Pa": ("Pa", "top of the linear range from fit_range[0] (R2 >= 0.99 of the line over it)"),
    "linear_R2": ("1", "R2 of the line over the linear range"),
    "V_sat": ("V", "largest V_OC of the run"),
    "P_sat_Pa": ("Pa", "saturation pressure: V_OC within 2 % of its full-scale change of its top value from "
                 "there on (NaN: V_OC does not level off)"),
    "hysteresis": ("3π W ε² m²/n² per cell (∮F dD)", "approach minus retraction ∮ F dD"),
    "hysteresis_J_m2": ("J/m²", "energy lost per cycle per unit nominal area"),
}


def parse_observables(table: dict, where: str = "study") -> dict:
    """Typed [observables] settings with defaults (pressures in Pa)."""
    from tengsim.schema import Field, Table

    t = Table("observables", [
        Field("pressures", "floats", OBSERVABLE_DEFAULTS["pressures"], dim="pressure",
              help="pressures at which V_OC is reported"),
        Field("fit_range", "floats", None, dim="pressure",
              help="pressure range [lo, hi] the sensor's numbers (regions, sensitivity, linear range, "
                   "saturation) are read over (default: 0 to the top of each run)"),
        Field("grid_max", "float", OBSERVABLE_DEFAULTS["grid_max"], dim="pressure",
              help="top of the common pressure grid (from 0)"),
        Field("grid_num", "int", 61, help="points of the common pressure grid"),
        Field("transition_fraction", "float", OBSERVABLE_DEFAULTS["transition_fraction"], help="Λc fraction of full contact for transition_D"),
        Field("full_contact_fraction", "float", OBSERVABLE_DEFAULTS["full_contact_fraction"], help="Λc fraction of full contact at zero load flagged"),
    ])
    raw = dict(table)
    labels = raw.get("pressures", OBSERVABLE_DEFAULTS["pressures"])
    if isinstance(labels, str):
        labels = [s.strip() for s in labels.split(",") if s.strip()]
    elif not isinstance(labels, (list, tuple)):
        labels = [labels]
    out = t.parse(raw, where=f"{where}: [observables] ")
    defaults = {k: out[k] for k in out}
    for k in ("pressures", "grid_max"):
        if defaults[k] == OBSERVABLE_DEFAULTS[k]:
            defaults[k] = t.fields[k].parse(OBSERVABLE_DEFAULTS[k])
    fr = defaults["fit_range"] if defaults["fit_range"] is not None else [0.0, math.inf]
    if len(fr) != 2 or not fr[1] > fr[0] >= 0:
        raise TengsimError(f"{where}: [observables] fit_range must be [lo, hi] with 0 <= lo < hi, got {fr!r}")
    if not defaults["grid_max"] > 0 or defaults["grid_num"] < 2:
        raise TengsimError(f"{where}: [observables] grid_max must be > 0 and grid_num >= 2")
    defaults["pressure_labels"] = [str(s).replace(" ", "") for s in labels]
    defaults["pressures"] = list(defaults["pressures"])
    defaults["fit_range"] = list(fr)
    return defaults


def pressure_grid(settings: dict) -> np.ndarray:
    return np.linspace(0.0, settings["grid_max"], int(settings["grid_num"]))


def _first_jump(res, kind):
    for j in res.jumps:
        if j.kind == kind:
            return j.D_after
    return math.nan


def device_values(device: dict) -> tuple[float, float, float]:
    """(σ in C/m², ε_r, T in m) of a point's [device] table; a TengsimError naming a bad value."""
    from tengsim.schema import Field

    sigma = Field("sigma", dim="charge/area").parse(device["sigma"], "device.")
    eps_r = Field("eps_r").parse(device["eps_r"], "device.")
    T = Field("thickness", dim="length").parse(device["thickness"], "device.")
    for k, v in (("sigma", sigma), ("eps_r", eps_r), ("thickness", T)):
        if not v > 0:
            raise TengsimError(f"device.{k} must be > 0, got {device[k]!r}")
    return sigma, eps_r, T


def observe(res, device: dict, settings: dict) -> dict:
    """Scalars (dict name → float) and curves ('V_OC', 'area_fraction' on the common pressure grid,
    'V_OC_at' at the named pressures) of one contact result.

    A/S is :func:`tengsim.run.area.loaded_area`'s: the result's ``charged_fraction`` column (the 2-D
    charged area), or, for a run with the ``array_area`` observer, its ``area_fraction_greenwood`` column
    (Σ over the array's cells).  A value that cannot be had is NaN:
    every pressure observable of a dimensionless run (no scaling); transition_D and
    adhesive_full_contact of a shape without a known full-contact length (:func:`full_length`); the
    V_OC observables of a run with fewer than two loaded states or no known cell (:func:`cell_side`).
    'notes' lists the reasons that apply to a physical run (V_OC missing; an array's A/S from one cell),
    for the study's message column."""
    from tengsim.device.formulas import voc_polymer

    sigma, eps_r, T = device_values(device)
    nan = math.nan
    out = {k: nan for k in SCALARS}
    out["pull_off_F"] = res.pull_off_force
    out["jump_in_D"] = _first_jump(res, "jump-in")
    retr = [j for j in res.jumps if j.kind == "jump-out"]
    out["jump_out_D"] = retr[0].D_after if retr else nan
    full = full_length(res.params)
    if math.isfinite(full):
        out["transition_D"] = res.transition_D(full, settings["transition_fraction"])
    out["hysteresis"] = res.hysteresis
    Fk, Lk, A, notes = loaded_area(res)
    grid = pressure_grid(settings)
    curves = {"V_OC": np.full(grid.shape, nan), "area_fraction": np.full(grid.shape, nan),
              "V_OC_at": np.full(len(settings["pressures"]), nan)}
    if len(Fk):
        out["area_fraction_0"] = float(A[0])
        if math.isfinite(full):
            out["adhesive_full_contact"] = float(Lk[0] >= settings["full_contact_fraction"] * full)
    scale = physical_scale(res)
    if scale is None:
        return {"scalars": out, "curves": curves, "notes": notes}
    k_p, k_D = scale
    out["pull_off_Pa"] = k_p * out["pull_off_F"]
    out["hysteresis_J_m2"] = k_p * k_D * out["hysteresis"]
    known = np.isfinite(A)
    if np.count_nonzero(known) < 2:
        why = ("no cell side known for A/S" if len(Fk) >= 2 and not math.isfinite(cell_side(res.params))
               else f"{len(Fk)} loaded state(s) (F > 0 rising) on the approach, 2 needed")
        return {"scalars": out, "curves": curves, "notes": [*notes, f"no V_OC: {why}"]}
    P = k_p * Fk[known]
    A = A[known]
    V = voc_polymer(A, sigma, eps_r, T)

    def at(x):
        x = np.asarray(x, float)
        y = np.interp(x, P, V)
        return np.where((x >= P[0]) & (x <= P[-1]), y, nan)

    curves["V_OC"] = at(grid)
    curves["area_fraction"] = np.where(np.isfinite(curves["V_OC"]), np.interp(grid, P, A), nan)
    curves["V_OC_at"] = at(settings["pressures"])
    from tengsim.device.sensor import sensor_numbers

    lo, hi = settings["fit_range"]  # hi: inf (the run's top), None once the settings went through JSON
    nums = sensor_numbers(P, V, p_range=(lo, math.inf if hi is None else hi))
    f = nums.flat()
    for name, key, k in (("S_V_per_kPa", "sensitivity_V_per_Pa", 1e3), ("S_rel_per_kPa", "sensitivity_rel_per_Pa", 1e3),
                         ("S_to_Pa", "sensitivity_to_Pa", 1.0), ("knee_Pa", "knee_Pa", 1.0),
                         ("S_above_knee_V_per_kPa", "sensitivity_above_knee_V_per_Pa", 1e3),
                         ("linear_range_Pa", "linear_range_Pa", 1.0), ("linear_R2", "linear_r2", 1.0),
                         ("P_sat_Pa", "saturation_Pa", 1.0)):
        out[name] = f[key] * k
    out["V_sat"] = float(np.max(V))
    why = [f"{name}: {nums.reason(key)}" for name, key in (("S_V_per_kPa", "sensitivity_V_per_Pa"),
                                                          ("linear_range_Pa", "linear_range_Pa"))
           if not math.isfinite(f[key]) and nums.reason(key)]
    notes = [*notes, *why]
    return {"scalars": out, "curves": curves, "notes": notes}
