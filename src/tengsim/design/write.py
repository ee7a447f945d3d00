"""A design's files: DIR/design.nc (the contract below), DIR/design.csv, the figures and DIR/report.md.

design.nc (CF-1.10, SI): coordinates ``pressure`` (Pa, the pressures asked for, increasing; along the dimension
``applied_pressure``, :data:`PRESSURE_DIM`) and ``branch`` (approach, retraction); ``charged_area_fraction``,
``repulsive_area_fraction`` (1), ``voc_eq12``, ``voc_eq17`` (V), ``dvoc_dp`` (V Pa-1) on (branch, pressure), NaN
where a branch does not reach a pressure; ``state_pressure`` (Pa) and ``state_charged_area_fraction`` (1) on
(branch, ``path_state``, :data:`STATE_DIM`): every state a pressed device passes on the finest grid, in increasing
load, NaN-padded (a snap is two states at one pressure: the fold and where it lands, so the jump's pressure is
exact, not one of the asked pressures); global attributes
Conventions, title, shape, shape_params (JSON), E_star_Pa, W_J_m2, eps_m, tabor, sigma_C_m2, eps_r, thickness_m,
gap_m, status, grids, tolerance, charged_area_definition, branches_solved (the retraction is all NaN where only
the approach was solved), the per-design numbers (:mod:`tengsim.design.curves`) and the charged pattern's near
field, ``nearfield_*`` (:func:`tengsim.design.nearfield.attributes`; 'n/a: ...' without maps).
``tengsim.device.area_table_from_design`` reads it.
"""
from __future__ import annotations

import json
import math
import re
from pathlib import Path

import numpy as np

from tengsim.device.sensor import NUMBERS

BRANCHES = ("approach", "retraction")
PRESSURE_DIM = "applied_pressure"
STATE_DIM = "path_state"
"""The dimension the coordinate ``pressure`` runs along: CF takes a dimension named 'pressure' for air pressure
(a vertical axis asking for standard_name air_pressure), so it is named as a study.nc names it; select with
``ds.swap_dims(applied_pressure="pressure").sel(pressure=...)`` or by position."""
VARIABLES = {
    "charged_area_fraction": ("1", "charged contact area over cell area (A/S)"),
    "repulsive_area_fraction": ("1", "repulsive contact area (P > 0) over cell area"),
    "voc_eq12": ("V", "open-circuit voltage of the polymer, Eq. 12: sigma (A/S) T / (eps_r eps0)"),
    "voc_eq17": ("V", "open-circuit voltage at the rest gap, Eq. 17: sigma (A/S) d0 / eps0"),
    "dvoc_dp": ("V Pa-1", "local slope dV_OC/dP of voc_eq12 (the sensitivity per region: sensor_region_*)"),
}
_CURVE = {"charged_area_fraction": "area", "repulsive_area_fraction": "repulsive", "voc_eq12": "voc_eq12",
          "voc_eq17": "voc_eq17", "dvoc_dp": "dvoc_dp"}
SUMMARY_UNITS = {"jump_in_Pa": "Pa", "pull_off_N": "N per cell", "pull_off_Pa": "Pa", "full_contact_Pa": "Pa",
                 "hysteresis_J_m2": "J/m2",
                 "hysteresis_bound_J_m2": "J/m2",
                 "area_hysteresis": "1", "area_at_p_max": "1", "voc_eq12_at_p_max_V": "V",
                 "voc_eq17_at_p_max_V": "V", "voc_finite_at_p_max_V": "V", "tabor": "1", "seconds": "s",
                 **{k: u for k, (u, _) in NUMBERS.items()}}


def to_dataset(res, plan, summary: dict):
    """The design.nc Dataset of a finished design (module doc)."""
    import xarray as xr

    from tengsim.design.curves import branch_curves, states
    from tengsim.io import cf_conventions

    curves = branch_curves(res, plan)
    passed = states(res, plan)
    P = np.asarray(plan.pressures, float)
    data = {}
    for name, (units, long) in VARIABLES.items():
        arr = np.vstack([curves[b][_CURVE[name]] for b in BRANCHES]).astype(float)
        data[name] = (("branch", PRESSURE_DIM), arr, {"units": units, "long_name": long})
    coords = {"pressure": (PRESSURE_DIM, P, {"units": "Pa", "long_name": "nominal pressure"}),
              "branch": ("branch", np.array(BRANCHES, dtype=object), {"long_name": "path branch"})}
    n = max([1] + [len(passed[b]["P"]) for b in BRANCHES])
    for name, key, units, long in (
            ("state_pressure", "P", "Pa", "nominal pressure of each state a pressed device passes (finest grid)"),
            ("state_charged_area_fraction", "area", "1", "charged area A/S of each state a pressed device passes")):
        arr = np.full((len(BRANCHES), n), np.nan)
        for i, b in enumerate(BRANCHES):
            v = np.asarray(passed[b][key], float)
            arr[i, :len(v)] = v
        data[name] = (("branch", STATE_DIM), arr, {"units": units, "long_name": long})
    ds = xr.Dataset(data, coords=coords)
    _by_grid(ds, res, plan)  # the refinement's record and its change_* attributes (kept after the others below)
    attrs = {
        "shape": plan.shape, "shape_params": json.dumps(plan.shape_params, sort_keys=True),
        "design_name": plan.name, "E_star_Pa": plan.E_star, "W_J_m2": plan.W, "eps_m": plan.eps,
        "tabor": float(summary["tabor"]), "sigma_C_m2": plan.sigma, "eps_r": plan.eps_r, "thickness_m": plan.T,
        "gap_m": plan.gap, "status": str(summary["status"]), "grids": str(summary["grids"]),
        "tolerance": float(plan.rel_tol), "solver_tolerance_eps": float(res.params.get("tol", math.nan)),
        "charged_area_definition": str(summary["charged_area_definition"]),
        "area_definition": str(getattr(plan, "area", "contact")), "boundary": str(getattr(plan, "boundary", "")),
        "branches_solved": "approach and retraction" if getattr(plan, "retraction", True) else "approach",
        "contact_config": json.dumps({k: v for k, v in plan.contact_table.items()}, sort_keys=True, default=str),
    }
    from tengsim.design.breakdown import design_breakdown  # issue 51: the air gap's cap on σ A/S

    a_max = float(np.nanmax(data["charged_area_fraction"][1][0])) if np.any(
        np.isfinite(data["charged_area_fraction"][1][0])) else math.nan
    b = design_breakdown(plan.sigma, plan.eps_r, plan.T, plan.gap, a_max)
    attrs.update({**b, "breakdown_exceeded": int(b["breakdown_exceeded"])})  # 0/1: NetCDF has no booleans
    from tengsim.design.breakdown import FINITE_FIELD

    attrs["field_models"] = f"voc_eq12, voc_eq17: parallel plates (the paper's); voc_finite_at_p_max_V: {FINITE_FIELD}"
    from tengsim.design.nearfield import attributes as nearfield_attributes

    attrs.update(nearfield_attributes(summary.get("nearfield")))  # the charged pattern's near field (issue 51)
    sensor, reasons = summary.get("sensor"), summary.get("reasons") or {}
    for k, v in summary.items():
        if k in SUMMARY_UNITS and k != "tabor":
            why = reasons.get(k, "")
            attrs[k] = float(v) if v is not None and math.isfinite(float(v)) else f"n/a: {why}" if why else "n/a"
    if sensor is not None:
        _sensor_regions(ds, sensor)
    ds.attrs = {**attrs, **ds.attrs}
    ds["branch"].encoding["dtype"] = "S1"  # a char array: CF's checker cannot judge a string coordinate variable
    return cf_conventions(ds, f"tengsim design: {plan.name}")


GRID_DIM = "refinement_grid"
CHANGE_NA = "n/a: one grid, or not present on both of the last two grids"
REGION_DIM = "sensor_region"


def _sensor_regions(ds, sensor) -> None:
    """The sensor's pressure regions (:mod:`tengsim.device.sensor`) along ``sensor_region``: their name, pressure
    range, sensitivity (V Pa-1), relative sensitivity (Pa-1) and the R² of their line."""
    regs = sensor.regions
    ds["sensor_region_name"] = (REGION_DIM, np.array([r.name for r in regs], dtype=object),
                                {"long_name": "pressure region of V_OC(P) (eq. 12, approach)"})
    for name, attr, units, long in (
            ("sensor_region_p_lo", "p_lo_Pa", "Pa", "lowest pressure of the region"),
            ("sensor_region_p_hi", "p_hi_Pa", "Pa", "highest pressure of the region"),
            ("sensor_region_sensitivity", "sensitivity_V_per_Pa", "V Pa-1", "least-squares slope dV_OC/dP"),
            ("sensor_region_relative_sensitivity", "relative_per_Pa", "Pa-1",
             "(dV_OC/dP)/V0, V0 = V_OC at the lowest pressure"),
            ("sensor_region_r2", "r2", "1", "R2 of the region's least-squares line")):
        ds[name] = (REGION_DIM, np.array([getattr(r, attr) for r in regs], float), {"units": units, "long_name": long})


def _by_grid(ds, res, plan) -> None:
    """The refinement's record, one entry per grid (coarse to fine; ``refinement_grid`` dimension): its spacing,
    pixels per side, the charged area on both branches at the asked pressures, the pull-off force and the
    hysteresis energy; and ``change_*`` attributes: each number's relative change between the last two grids
    (:func:`tengsim.design.curves.convergence`).  Nothing with one grid run outside the refinement."""
    from tengsim.design.curves import convergence
    from tengsim.design.curves import area_name

    tab = res.params.get("resolution") or {}
    if not tab:
        return
    sc = res.scaling
    n = len(tab["dx"])
    nan = [math.nan] * n

    def col(name):
        return np.asarray([math.nan if v is None else float(v) for v in tab.get(name, nan)], float)

    area = np.stack([np.stack([col(area_name(b, p)) for p in plan.pressures], axis=-1) for b in BRANCHES], axis=1)
    ds["grid_spacing"] = (GRID_DIM, sc.lateral * col("dx"), {"units": "m", "long_name": "grid spacing dx"})
    ds["grid_pixels"] = (GRID_DIM, np.asarray(tab["nx"], dtype=np.int32),
                         {"units": "1", "long_name": "pixels along x"})
    ds["charged_area_fraction_by_grid"] = ((GRID_DIM, "branch", PRESSURE_DIM), area,
                                           {"units": "1", "long_name": "charged area A/S on each grid"})
    ds["pull_off_force_by_grid"] = (GRID_DIM, sc.force(1.0) * col("pull_off_F"),
                                    {"units": "N", "long_name": "pull-off force per cell on each grid"})
    ds["hysteresis_by_grid"] = (GRID_DIM, sc.work(1.0) / sc.cell_area * col("hysteresis_W"),
                                {"units": "J m-2", "long_name": "energy lost per cycle per unit area on each grid"})
    for label, v in convergence(res).items():
        key = "change_" + re.sub(r"[^A-Za-z0-9]+", "_", label.split("(")[0]).strip("_")  # CF: letters, digits, _
        ds.attrs[key] = float(v) if math.isfinite(v) else CHANGE_NA


def csv_columns(ds) -> dict:
    """design.csv: one row per (branch, pressure), pressures in Pa and kPa."""
    rows = {"branch": [], "pressure_Pa": [], "pressure_kPa": []}
    for name in VARIABLES:
        rows[name] = []
    for b in BRANCHES:
        for i, p in enumerate(ds["pressure"].values):
            rows["branch"].append(b)
            rows["pressure_Pa"].append(float(p))
            rows["pressure_kPa"].append(float(p) / 1e3)
            for name in VARIABLES:
                rows[name].append(float(ds[name].sel(branch=b).values[i]))
    return {k: np.asarray(v) for k, v in rows.items()}


def _finite(v):
    return float(v) if v is not None and math.isfinite(float(v)) else None


def write_design(result, out_dir, figures: bool = True) -> list:
    """Write design.nc, design.csv, the figures and report.md of ``result`` into ``out_dir``; returns the paths."""
    from tengsim.io import csv_text, write_dataset, write_text

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    ds = result.dataset
    write_dataset(ds, out / "design.nc")
    header = {"design": result.plan.name, "status": result.status, "grids": result.summary["grids"],
              "tolerance": result.plan.rel_tol, "charged_area_definition": result.summary["charged_area_definition"],
              # the loop energy (J/m2) and its uncertainty: 0 where within it (tengsim.results.hysteresis)
              **{k: _finite(result.summary.get(k)) for k in ("hysteresis_J_m2", "hysteresis_bound_J_m2")}}
    write_text(out / "design.csv", csv_text(csv_columns(ds), header, missing=""))
    paths = [out / "design.nc", out / "design.csv"]
    figs = []
    if figures:
        from tengsim.design.plots import save_design_figures

        figs = save_design_figures(result, out)
        paths += figs
    from tengsim.design.report import report_text

    write_text(out / "report.md", report_text(result, [Path(f).name for f in figs]))
    paths.append(out / "report.md")
    return paths
