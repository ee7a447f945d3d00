"""Assembling DIR/study.nc and DIR/study.csv from DIR/study.json and DIR/points/ (idempotent).

study.nc is indexed by the axes for a full grid (a zip group is one dimension, its parameters
coordinates along it) and by ``point`` for sampled studies; its names are CF's (:func:`cf_name`:
'contact.tabor' → 'contact_tabor', the key kept in the attribute ``tengsim_key``).  study.csv has one row per point: the axis
values in columns named as in [axes], ``id``, ``status`` (the one status of the point: the run's own,
tengsim.status — ok, under_resolved, out_of_law_range, not_converged — or failed, or pending),
``run_status`` (the same for a computed point, empty otherwise; kept for scripts that read it), the
scalar observables (units in
tengsim.study.observe.SCALARS; pull_off_F and jump_in_D as in ``tengsim contact``'s CSV), V_OC at the
named pressures, and an empty cell wherever there is no value.
"""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from tengsim.errors import TengsimError
from tengsim.io import interrupts_held
from tengsim.status import SEVERITY
from tengsim.study.layout import StudyDir
from tengsim.study.observe import SCALARS, observe, pressure_grid
from tengsim.study.points import check_point

STATUSES = (*SEVERITY, "failed", "pending")
"""A point's status: its run's (tengsim.status.SEVERITY, best first), 'failed' (no result; the message
says why) or 'pending' (not computed yet)."""


def _read_point(sd, pid):
    """(status, message, ContactResult or None, seconds) of one point id.  A point file is trusted only
    when sound (:func:`tengsim.study.points.check_point`); a bad one is a failed point naming the fault."""
    nc = sd.nc(pid)
    if nc.exists():
        status, why = check_point(nc, pid)
        if status is None:
            return "failed", f"point file {nc.name} {why}", None, math.nan
        try:
            with interrupts_held():
                res, a = _light_result(nc)
        except (OSError, KeyError, ValueError) as exc:
            return "failed", f"unreadable point file {nc.name}: {exc}", None, math.nan
        return status, str(a.get("message", "")), res, float(a.get("compute_seconds", math.nan))
    f = sd.failed(pid)
    if f.exists():
        try:
            d = json.loads(f.read_text(encoding="utf-8"))
        except (OSError, ValueError):
            d = {"message": "unreadable failure record"}
        s = d.get("seconds")
        return "failed", str(d.get("message", "")), None, float(s) if s is not None else math.nan
    return "pending", "", None, math.nan


_COLUMNS = ("branch", "D", "F", "contact_length", "jump", "converged", "pressure_Pa", "F_N", "contact_length_m",
            "status", "area_fraction_greenwood", "charged_fraction")


def _light_result(nc):
    """The curves the observables need and the point's attrs, read with h5py (an xarray open costs ~10×)."""
    import h5py

    from tengsim.grid import Grid
    from tengsim.results import ContactResult

    def text(v):
        return v.decode() if isinstance(v, bytes) else v

    with h5py.File(nc, "r") as f:
        attrs = {k: text(v.item() if hasattr(v, "item") and getattr(v, "size", 2) == 1 else v)
                 for k, v in f.attrs.items() if k in ("status", "message", "compute_seconds", "params")}
        table = {k: f[k][()] for k in _COLUMNS if k in f}
    table["branch"] = np.array([text(b) for b in table["branch"]])
    if "status" in table:
        table["status"] = np.array([text(b) for b in table["status"]])
    for k in ("jump", "converged"):
        table[k] = table[k].astype(bool)
    params = json.loads(attrs.get("params", "{}"))
    return ContactResult(table=table, grid=Grid(3, 3, 1.0, 1.0), params=params), attrs


def collect(root) -> dict:
    """Per study point (in study.json order): axes, id, status, message, scalars, curves."""
    sd = StudyDir(Path(root))
    try:
        spec = json.loads(sd.spec.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise TengsimError(f"{root} is not a study directory (no study.json)") from None
    except (OSError, ValueError) as exc:
        raise TengsimError(f"cannot read {sd.spec}: {exc}") from None
    settings = spec["observables"]
    cache, rows = {}, []
    for p in spec["points"]:
        pid = p["id"]
        if pid not in cache:
            cache[pid] = _read_point(sd, pid)
        status, msg, res, secs = cache[pid]
        obs = None
        if res is not None and res.params.get("resolve") == "auto" and not res.params.get("resolve_message"):
            grids = res.params.get("resolve_grids") or [res.grid.dx if res.grid is not None else math.nan]
            note = f"resolve auto: converged at dx = {grids[-1]:.4g} ({len(grids)} grids)"  # dx reached
            msg = "; ".join([msg, note]) if msg else note
        if res is not None:
            try:
                obs = observe(res, p["tables"]["device"], settings)
                if obs.get("notes"):
                    msg = "; ".join([msg, *obs["notes"]] if msg else obs["notes"])
            except TengsimError as exc:
                msg = (msg + "; " if msg else "") + f"observables: {exc}"
            except Exception as exc:  # noqa: BLE001 - one point's observables never cost the study its table
                msg = (msg + "; " if msg else "") + f"observables: {type(exc).__name__}: {exc}"
        rows.append({"axes": p["axes"], "index": p["index"], "id": pid, "status": status, "message": msg,
                     "seconds": secs, "obs": obs, "run_status": status if res is not None else ""})
    return {"spec": spec, "rows": rows, "settings": settings}


def _cf_units(text: str) -> dict:
    """CF attributes of a unit text of tengsim.study.observe.SCALARS: a UDUNITS unit as ``units``
    ('J/m²' as 'J/m2'); a unit in the paper's symbols (ε, 3π W ε m²/n², ...: one number per point, not
    per study) as ``units = "1"`` with the symbols in ``unit_scale_text``."""
    u = text.replace("²", "2")
    if u in ("1", "Pa", "V", "V/kPa", "J/m2", "N", "m", "s"):
        return {"units": u}
    return {"units": "1", "unit_scale_text": text}


def cf_name(key: str) -> str:
    """The study.nc name of an axis or parameter ``key`` ('contact.tabor' → 'contact_tabor'): CF-1.10 §2.3
    names begin with a letter and hold letters, digits and underscores; the key itself is kept in the
    variable's ``tengsim_key`` attribute (readers: :func:`key_of`)."""
    import re

    name = re.sub(r"[^A-Za-z0-9_]", "_", str(key))
    return name if name[:1].isalpha() else f"v_{name}"


def key_of(ds, name: str) -> str:
    """The [axes] key of the study.nc variable ``name`` (its ``tengsim_key``; the name itself in a file
    written before CF names)."""
    return str(ds[name].attrs.get("tengsim_key", name)) if name in ds.variables else name


def _coord(values):
    vals = list(values)
    if all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in vals):
        return np.array(vals, dtype=float)
    return np.array([str(v) for v in vals])


def build_study(root) -> dict:
    """Write DIR/study.nc and DIR/study.csv from what DIR/points/ holds; returns counts by status."""
    import xarray as xr

    from tengsim.io import cf_conventions, write_dataset, write_text

    root = Path(root)
    c = collect(root)
    spec, rows, settings = c["spec"], c["rows"], c["settings"]
    grid = pressure_grid(settings)
    labels = settings["pressure_labels"]
    nan = math.nan
    n = len(rows)
    scal = {k: np.full(n, nan) for k in SCALARS}
    voc = np.full((n, len(grid)), nan)
    area = np.full((n, len(grid)), nan)
    vat = np.full((n, len(labels)), nan)
    for i, r in enumerate(rows):
        if r["obs"] is not None:
            for k in SCALARS:
                scal[k][i] = r["obs"]["scalars"][k]
            voc[i] = r["obs"]["curves"]["V_OC"]
            area[i] = r["obs"]["curves"]["area_fraction"]
            vat[i] = r["obs"]["curves"]["V_OC_at"]
    per_point = {
        "id": np.array([r["id"] for r in rows]),
        "status": np.array([r["status"] for r in rows]),
        "run_status": np.array([r["run_status"] for r in rows]),
        "message": np.array([r["message"] for r in rows]),
        "seconds": np.array([r["seconds"] for r in rows], dtype=float),
        **scal,
    }
    axes = spec["axes"]
    is_grid = spec["sampling"] == "grid"
    if is_grid and axes:
        dims = [a["name"] for a in axes]
        shape = tuple(len(a["coord"]) for a in axes)
        order = [tuple(r["index"]) for r in rows]

        def arr(v, extra=()):
            v = np.asarray(v)
            out = np.empty(shape + tuple(extra), dtype=v.dtype)
            for i, ix in enumerate(order):
                out[ix] = v[i]
            return out

        coords = {}
        for a in axes:
            coords[a["name"]] = _coord(a["coord"])
            if len(a["members"]) > 1:
                for j, m in enumerate(a["members"]):
                    coords[m] = (a["name"], _coord([a["values"][k][j] for k in range(len(a["coord"]))]))
        data = {k: (dims, arr(v)) for k, v in per_point.items()}
        data["V_OC"] = (dims + ["pressure"], arr(voc, (len(grid),)))
        data["area_fraction"] = (dims + ["pressure"], arr(area, (len(grid),)))
        data["V_OC_at"] = (dims + ["pressure_named"], arr(vat, (len(labels),)))
    else:
        dims = ["point"]
        coords = {"point": np.arange(n)}
        members = [m for a in axes for m in a["members"]]
        for m in members:
            coords[m] = ("point", _coord([r["axes"][m] for r in rows]))
        data = {k: ("point", v) for k, v in per_point.items()}
        data["V_OC"] = (["point", "pressure"], voc)
        data["area_fraction"] = (["point", "pressure"], area)
        data["V_OC_at"] = (["point", "pressure_named"], vat)
    coords["pressure"] = ("pressure", grid, {"units": "Pa", "long_name": "nominal applied pressure (common grid)"})
    # CF: a coordinate variable is numeric and monotonic, so the named pressures (in the user's order) are
    # a dimension without one, labelled by two auxiliary coordinates (select with
    # ds.set_xindex("pressure_label").sel(pressure_label="10kPa"))
    coords["pressure_label"] = ("pressure_named", np.array(labels),
                                {"long_name": "named pressure as given in [observables] pressures"})
    coords["pressure_named_Pa"] = ("pressure_named", np.array(settings["pressures"], float),
                                   {"units": "Pa", "long_name": "named pressure"})
    # CF: 'pressure' as a dimension name is taken for air pressure (a vertical axis)
    ds = xr.Dataset(data, coords=coords).rename({"pressure": "applied_pressure"})
    keys = [k for k in dict.fromkeys(n for a in axes for n in (a["name"], *a["members"])) if k in ds.variables]
    ds = ds.rename({k: cf_name(k) for k in keys if cf_name(k) != k})  # CF names: 'contact.tabor' → 'contact_tabor'
    for k in keys:
        ds[cf_name(k)].attrs["tengsim_key"] = k
    for k, (u, long) in SCALARS.items():
        ds[k].attrs.update(_cf_units(u), long_name=long)
    for a in axes:  # the axes' coordinates: CF asks every variable for a long_name
        for m in dict.fromkeys([a["name"], *a["members"]]):
            if cf_name(m) in ds.variables:
                ds[cf_name(m)].attrs.setdefault("long_name", f"study axis {a['name']}" if m == a["name"] else
                                                f"parameter {m} along study axis {a['name']}")
    if "point" in ds.variables:
        ds["point"].attrs.setdefault("long_name", "sampled point (study.json order)")
    ds["V_OC"].attrs.update(units="V", long_name="Eq. (12) open-circuit voltage under load control")
    ds["area_fraction"].attrs.update(units="1", long_name="charged-area fraction A/S")
    ds["V_OC_at"].attrs.update(units="V", long_name="V_OC at the named pressures")
    ds["seconds"].attrs.update(units="s", long_name="compute time of the point")
    ds["id"].attrs.setdefault("long_name", "point id (DIR/points/<id>.nc)")
    ds["message"].attrs.setdefault("long_name", "why a point failed, or the run's warning")
    ds["status"].attrs["long_name"] = ("the point's status: its run's (the worst of its equilibria, "
                                       "tengsim.status: ok, under_resolved, out_of_law_range, not_converged), "
                                       "failed or pending")
    ds["run_status"].attrs["long_name"] = "the run's status, as status, for a computed point; empty otherwise"
    from tengsim._version import __version__

    ds.attrs.update({"study": json.dumps({k: spec[k] for k in ("source", "sampling", "n", "seed", "base")},
                                         default=str),
                     "axes": json.dumps(axes), "observables": json.dumps(settings),
                     "tengsim_version": __version__})
    write_dataset(cf_conventions(ds, "tengsim design study: observables of every point"), root / "study.nc")
    write_text(root / "study.csv", _csv(spec, rows, per_point, vat, labels))
    counts = {s: int(np.count_nonzero(per_point["status"] == s)) for s in STATUSES}
    return {**counts, "points": n}


def _csv(spec, rows, per_point, vat, labels) -> str:
    """study.csv text (tengsim.io.csv_text): an empty cell for a missing or non-finite value."""
    from tengsim.io import csv_text

    cols = {}
    for a in spec["axes"]:
        names = ([a["name"]] if len(a["members"]) > 1 else []) + list(a["members"])
        for m in names:
            vals = [r["axes"].get(m, "") if m == a["name"] else r["axes"][m] for r in rows]
            # each value formatted by its own type (a bool as True/False, as in study.nc)
            cols[m] = np.array([str(v) if isinstance(v, bool) else v for v in vals], dtype=object)
    for k in ("id", "status", "run_status"):
        cols[k] = [r[k] for r in rows]
    cols.update({k: per_point[k] for k in SCALARS})
    cols.update({f"V_OC_{lab}": vat[:, j] for j, lab in enumerate(labels)})
    cols["seconds"] = per_point["seconds"]
    cols["message"] = [r["message"] for r in rows]
    return csv_text(cols, missing="")
