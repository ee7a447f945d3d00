"""Writing a :class:`~tengsim.results.result.ContactResult`: CSV (curves, parameters in '#' header
lines) and CF-1.10 NetCDF (curves, maps, the refinement's table, parameters); atomic, through
:mod:`tengsim.io`.  The rows of a run as it goes are written by :mod:`tengsim.results.stream`."""
from __future__ import annotations

import json

import numpy as np

from tengsim.results.columns import FLAGS


# NetCDF (CF-1.10) metadata of the table's columns, used by ContactResult.to_dataset: name -> (long_name,
# unit).  A unit of _SCALES marks a dimensionless column (CF units "1"); the quantity one unit of it stands
# for is written as attributes: unit_scale_text (in the paper's symbols), and for a physical run
# unit_scale (a number) with unit_scale_units (its UDUNITS unit).  Any other unit is a UDUNITS unit.
_SCALES = {"eps": ("ε", "m"), "lateral": ("ℓ", "m"), "area": ("ℓ²", "m2"),
           "force": ("3π W ℓ²/ε per cell (Eq. 10)", "N"), "pressure": ("W/ε (Eq. 8)", "Pa")}
_CF_COLUMNS = {
    "D": ("rigid approach D of the plate (Eq. 7)", "eps"),
    "F": ("force per cell F (Eq. 10; positive: compressive)", "force"),
    "contact_length": ("Greenwood contact length Λc (tensile-peak distance along X)", "lateral"),
    "area_repulsive": ("area per cell where the pressure is repulsive (P > 0)", "area"),
    "charged_fraction": ("charged-area fraction A/S of the cell: the gap below the law's peak-tension separation", "1"),
    "residual": ("largest |r| of Eq. (9) at the accepted state", "eps"),
    "iterations": ("solver iterations", "1"),
    "n_conv": ("convolutions (FFT pairs) the solve spent", "1"),
    "min_gap": ("smallest gap H (g = H + 1)", "eps"),
    "max_pressure": ("largest surface pressure P (Eq. 8)", "pressure"),
    "min_pressure": ("smallest surface pressure P (Eq. 8; negative: tensile)", "pressure"),
    "energy": ("total energy E(q) of the cell as the solver minimises it (dimensionless)", "1"),
    "seconds": ("wall time of the solve", "s"),
    "process_zone": ("measured cohesive window at the narrowest contact edge (tengsim.status)", "lateral"),
    "F_N": ("force per cell (positive: compressive)", "N"),
    "pressure_Pa": ("nominal pressure: force per cell / cell area (positive: compressive)", "Pa"),
    "contact_length_m": ("Greenwood contact length Λc", "m"),
    "branch": ("branch of the path: approach or retraction", None),
    "status": ("status of the equilibrium (tengsim.status): ok, under_resolved, out_of_law_range, "
               "not_converged", None),
    "converged": ("1 if the solver converged", None),
    "on_grid": ("1 if D lies on the fixed step grid (0: a refinement step)", None),
    "jump": ("1 if the state jumped from the previous row's", None),
    "in_law_range": ("1 if every gap lies where the surface law is valid", None),
    "map_D": ("rigid approach D of the map (Eq. 7)", "eps"),
    "map_branch": ("branch of the map: approach or retraction", None),
    "P": ("surface pressure P (Eq. 8; positive: repulsive)", "pressure"),
    "H": ("gap H of the surface (g = H + 1; Eq. 9)", "eps"),
    "x": ("in-plane position X", "lateral"),
    "y": ("in-plane position Y", "lateral"),
}
# the refinement's table (tengsim.run.resolve) along dimension 'level': column -> (long_name, unit as above)
_RESOLUTION_CF = {"dx": ("grid spacing of the level", "lateral"), "nx": ("pixels along x", "1"),
                  "ny": ("pixels along y", "1"), "seconds": ("wall time of the level's run", "s"),
                  "convolutions": ("convolutions (FFT pairs) of the level's run", "1")}
# a unit text an observer may declare (its `units`) -> the scale it names; other texts that are not
# UDUNITS units below are written as a `comment`, never as `units`
_OBSERVER_SCALES = {"ε": "eps", "W/ε": "pressure", "ℓ": "lateral", "ℓ²": "area", "1": "1"}
_UDUNITS = {"1", "m", "m2", "N", "Pa", "s", "J", "J/m2", "N/m", "V", "A", "C", "C/m2", "W", "ohm", "Hz", "kg",
            "m/s", "F/m", "K"}



def unit_scales(result) -> dict:
    """SI value of one unit of each dimensionless scale of :data:`_SCALES` ('eps' and 'lateral' in m,
    'area' in m², 'force' in N per cell, 'pressure' in Pa): from the run's scaling, else from the
    parameters a physical run records (eps_m, W_J_m2, and lateral_m or base_m/height_m); {} for a
    dimensionless run."""
    import math

    s, p = result.scaling, result.params
    try:
        if s is not None:
            eps, lat, W = float(s.eps), float(s.lateral), float(s.W)
        else:
            eps, W = float(p["eps_m"]), float(p["W_J_m2"])
            lat = float(p["lateral_m"]) if "lateral_m" in p else eps * float(p["base_m"]) / float(p["height_m"])
    except (KeyError, TypeError, ValueError, ZeroDivisionError, AttributeError):
        return {}
    if not all(math.isfinite(v) and v > 0 for v in (eps, lat, W)):
        return {}
    return {"eps": eps, "lateral": lat, "area": lat * lat, "force": 3 * math.pi * W * lat * lat / eps,
            "pressure": W / eps}

def _cf_attrs(result, name: str, scales: dict) -> dict:
    """CF attributes of one variable (see :data:`_CF_COLUMNS`): long_name and units, a dimensionless
    one's scale, a flag's values and meanings."""
    attrs = {}
    if name in _CF_COLUMNS:
        long, unit = _CF_COLUMNS[name]
    else:  # an observer's column: the unit text it declared
        long, unit = f"{name} (observer column)", None
        text = result.column_units().get(name)
        if text is not None:
            head = str(text).split(" (")[0].strip()
            unit = _OBSERVER_SCALES.get(head, head if head in _UDUNITS else None)
            if unit is None or head != text:
                attrs["comment"] = f"units declared by the observer: {text}"
    attrs["long_name"] = long
    if unit in _SCALES:
        text, si = _SCALES[unit]
        lat = result.params.get("lateral_unit", "ℓ")
        if "ℓ" in text and lat != "ℓ":
            text += f" with ℓ = {lat}"
        attrs.update(units="1", unit_scale_text=text)
        if unit in scales:
            attrs.update(unit_scale=scales[unit], unit_scale_units=si)
    elif unit is not None:
        attrs["units"] = unit
    if name in FLAGS:
        attrs.update(flag_values=np.array([0, 1], dtype=np.int8), flag_meanings="false true")
    return attrs

def to_dataset(result):
    """xarray Dataset by the CF-1.10 conventions (the IOOS compliance checker's CF check passes).

    Curves along dimension ``step`` (one per equilibrium, in path order); ``D`` and ``branch`` are
    auxiliary coordinates along it (D repeats across the two branches, so it cannot be the dimension):
    select by D with ``ds.swap_dims(step="D")`` on one branch
    (``ds.where(ds.branch == "approach", drop=True)``), or ``ds.set_xindex("D").sel(D=0.5)`` for both.
    Maps ``P`` and ``H`` along (``map``, ``x``, ``y``) with auxiliary coordinates ``map_D`` and
    ``map_branch``.  Units: SI columns (F_N, pressure_Pa, contact_length_m, seconds) in UDUNITS units;
    the dimensionless ones ``units = "1"`` with ``unit_scale_text`` (one unit, in the paper's
    symbols) and, for a physical run, ``unit_scale`` and ``unit_scale_units`` (its SI value, e.g.
    ``D``: ε in m).  The flags (converged, on_grid, jump, in_law_range) are int8 0/1.  Parameters are
    stored once, as the JSON text of the global attribute ``params``; beside them ``status``,
    ``pull_off_F`` (units of F), ``n_unconverged``, ``n_outside_law_range``, ``jumps`` (JSON) and
    ``seconds``.
    """
    import xarray as xr

    from tengsim.io import cf_conventions

    t = result.table
    data = {}
    for k in result.columns:
        if k not in t:  # files from before a column existed lack it
            continue
        v = np.asarray(t[k])
        data[k] = ("step", v.astype(str) if k in ("branch", "status") else
                   v.astype(np.int8) if k in FLAGS else v)
    ds = xr.Dataset(data).set_coords(["D", "branch"])
    if result.maps:
        ds = ds.assign(
            P=(("map", "x", "y"), np.stack([m["P"] for m in result.maps])),
            H=(("map", "x", "y"), np.stack([m["H"] for m in result.maps])),
        ).assign_coords(map_D=("map", np.array([m["D"] for m in result.maps], dtype=float)),
                        map_branch=("map", np.array([str(m["branch"]) for m in result.maps])))
    if result.grid is not None:
        ds = ds.assign_coords(x=("x", result.grid.x), y=("y", result.grid.y))
    scales = unit_scales(result)
    for k, var in ds.variables.items():
        var.attrs.update(_cf_attrs(result, k, scales))
    params, ds = _resolution_vars(result, ds, scales)
    conv = t["converged"].astype(bool)
    attrs = {"params": json.dumps(params, default=str), "status": result.status,
             "pull_off_F": result.pull_off_force, "n_unconverged": int(np.count_nonzero(~conv))}
    if "in_law_range" in t:
        attrs["n_outside_law_range"] = int(np.count_nonzero(~t["in_law_range"].astype(bool)))
    attrs.update(jumps=json.dumps([j.__dict__ for j in result.jumps]), seconds=result.seconds)
    ds.attrs = attrs
    return cf_conventions(ds, "tengsim contact result: approach-retraction curves of a rigid plate on an "
                              "adhesive micro-structured half-space")

def _resolution_vars(result, ds, scales):
    """(params without 'resolution', ds with it): the refinement's table (tengsim.run.resolve, one row per grid)
    as variables ``resolution_<column>`` along dimension ``level`` (coarsest first), CF attributes as the
    curves' (dx in ℓ, F in its unit, D in ε)."""
    tab = result.params.get("resolution")
    if not isinstance(tab, dict) or not tab.get("dx"):
        return result.params, ds
    for k, v in tab.items():
        if k == "status":
            a = np.array([str(x) for x in v])
            long, unit = "status of the grid's run (tengsim.status)", None
        else:
            a = np.array([np.nan if x is None else x for x in v], dtype=float)
            if k in ("nx", "ny", "convolutions"):
                a = a.astype(np.int64)
            long, unit = _RESOLUTION_CF.get(k) or (
                (f"{k} on the grid (observable of the refinement)", "eps") if k.endswith("_D") else
                (f"{k} on the grid (observable of the refinement)", "force") if k.endswith("_F") else
                (f"{k} on the grid (observable of the refinement)", "1"))
        name = f"resolution_{k}"
        ds[name] = ("level", a)
        attrs = {"long_name": long}
        if unit in _SCALES:
            text, si = _SCALES[unit]
            attrs.update(units="1", unit_scale_text=text)
            if unit in scales:
                attrs.update(unit_scale=scales[unit], unit_scale_units=si)
        elif unit is not None:
            attrs["units"] = unit
        ds[name].attrs.update(attrs)
    return {k: v for k, v in result.params.items() if k != "resolution"}, ds

def csv_columns(result) -> dict:
    t = result.table
    return {k: t[k] for k in result.columns if k in t}

def save(result, path) -> None:
    """Write ``.csv`` (curves, parameters in '#' header lines) or ``.nc`` (everything), atomically."""
    from pathlib import Path

    from tengsim import io
    from tengsim.errors import TengsimError

    suffix = Path(path).suffix.lower()
    if suffix == ".csv":
        io.write_csv(path, csv_columns(result), header={**result.params, "units": result.column_units()})
    elif suffix in (".nc", ".netcdf", ".nc4"):
        io.write_dataset(to_dataset(result), path)
    else:
        raise TengsimError(f"unknown output format {suffix!r} for {path} (use .csv or .nc)")
