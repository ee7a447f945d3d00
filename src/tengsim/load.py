"""Read results written by tengsim back in (NetCDF or CSV): contact runs, device time series, load sweeps.

Nothing is invented: a file that lacks a required column is refused (the columns are named), and a
CSV without its grid in the header gives a result with ``grid=None`` (curves need no grid).
"""
from __future__ import annotations

import csv
import itertools
import json
from pathlib import Path

import numpy as np

from tengsim.errors import TengsimError
from tengsim.grid import Grid
from tengsim.results import CURVE_COLUMNS, ContactResult

BOOL_COLUMNS = ("converged", "on_grid", "jump", "in_law_range")
# written by every tengsim version; later additions (in_law_range, process_zone, status) are taken when present
LATER_COLUMNS = ("in_law_range", "process_zone", "status")
REQUIRED_CONTACT = tuple(k for k in CURVE_COLUMNS if k not in LATER_COLUMNS)
SWEEP_COLUMNS = ("R", "energy_per_cycle", "average_power")


def _read_csv(path: Path):
    """('# key: json' header lines as a dict, {column: array}) of a CSV written by
    :func:`tengsim.io.write_csv`: quoted fields are read by :mod:`csv`; a column of numbers is a float
    array, any other a str array."""
    header, rows, names = {}, [], None
    with open(path, newline="") as fh:
        for line in fh:
            if not line.startswith("#"):
                break
            k, _, v = line[1:].rstrip("\r\n").partition(":")
            try:
                header[k.strip()] = json.loads(v)
            except json.JSONDecodeError:
                header[k.strip()] = v.strip()
        else:
            line = ""
        for row in csv.reader(itertools.chain([line], fh)):
            if not row:
                continue
            if names is None:
                names = row
            else:
                rows.append(row)
    if names is None:
        raise TengsimError(f"{path}: no column header found")
    bad = next((i for i, r in enumerate(rows) if len(r) != len(names)), None)
    if bad is not None:
        raise TengsimError(f"{path}: data row {bad + 1} has {len(rows[bad])} fields, the header has {len(names)}")
    cols = {}
    for j, n in enumerate(names):
        vals = [r[j] for r in rows]
        try:
            cols[n] = np.array([float(v) for v in vals])
        except ValueError:
            cols[n] = np.array(vals)
    return header, cols


def _require(path, cols, required, what):
    missing = [k for k in required if k not in cols]
    if missing:
        raise TengsimError(f"{path}: {what} lacks column(s) {', '.join(missing)}")


def _contact_table(path, cols, dx=None) -> dict:
    """Every column of the file (SI and observer columns too); a file older than the status column gets
    its status worked out from its other columns."""
    from tengsim import status as _status

    _require(path, cols, REQUIRED_CONTACT, "contact result")
    table = {k: np.asarray(v) for k, v in cols.items() if np.ndim(v) == 1 and len(v) == len(cols["D"])}
    for k in BOOL_COLUMNS:
        if k in table:
            table[k] = table[k].astype(bool)
    table["branch"] = table["branch"].astype(str)
    if "status" in table:
        table["status"] = table["status"].astype(str)
    else:
        table.setdefault("in_law_range", np.ones(len(table["D"]), bool))
        table["status"] = _status.classify(table, dx if dx else np.nan)
    return table


def _header_grid(header: dict):
    """Grid from the '# nx', '# ny', '# dx' (and '# dy') header lines, or None if they are absent."""
    if not all(k in header for k in ("nx", "dx")):
        return None
    try:
        nx = int(header["nx"])
        ny = int(header.get("ny", nx))
        dx = float(header["dx"])
        return Grid(nx, ny, dx, float(header.get("dy", dx)))
    except (TypeError, ValueError, TengsimError) as exc:
        raise TengsimError(f"header grid nx={header.get('nx')!r}, dx={header.get('dx')!r} is not valid: {exc}") \
            from None


def load_result(path) -> tuple[str, object]:
    """Return ``(kind, obj)``: ('contact', ContactResult), ('device', Dataset or columns dict) for a time
    series, or ('sweep', dict of columns plus 'header') for a load-resistance sweep."""
    path = Path(path)
    if not path.exists():
        raise TengsimError(f"result file {path} not found")
    if path.is_dir():
        raise TengsimError(f"{path} is a directory, not a result file")
    suffix = path.suffix.lower()
    if suffix == ".csv":
        header, cols = _read_csv(path)
        if "branch" in cols and "D" in cols:
            try:
                grid = _header_grid(header)
            except TengsimError as exc:
                raise TengsimError(f"{path}: {exc}") from None
            table = _contact_table(path, cols, grid.dx if grid else None)
            return "contact", ContactResult(table=table, grid=grid, params=header)
        if "t" in cols:
            return "device", cols
        if "R" in cols:
            _require(path, cols, SWEEP_COLUMNS, "load sweep")
            return "sweep", {**cols, "header": header}
        raise TengsimError(f"{path}: not a tengsim result (no 'branch'/'D', 't' or 'R' columns)")
    if suffix == ".nc":
        from tengsim.io import read_dataset

        try:
            ds = read_dataset(path)
        except Exception as exc:  # noqa: BLE001 - any reader failure is a bad input file
            raise TengsimError(f"cannot read {path} as NetCDF: {exc}") from None
        if "branch" in ds and "D" in ds:
            params = json.loads(ds.attrs.get("params", "{}"))
            x, y = ds["x"].values, ds["y"].values
            if len(x) < 3 or len(y) < 3:
                raise TengsimError(f"{path}: grid coordinates x, y have {len(x)}, {len(y)} points (need >= 3)")
            grid = Grid(len(x), len(y), float(x[1] - x[0]), float(y[1] - y[0]))
            table = _contact_table(path, {k: ds[k].values for k in ds.data_vars if ds[k].dims == ("step",)},
                                   grid.dx)
            maps = []
            if "P" in ds:
                for i in range(ds.sizes["map"]):
                    maps.append(dict(branch=str(ds["map_branch"].values[i]), D=float(ds["map_D"].values[i]),
                                     P=ds["P"].values[i], H=ds["H"].values[i]))
            return "contact", ContactResult(table=table, grid=grid, maps=maps, params=params)
        if "t" in ds:
            return "device", ds
        if "R" in ds.coords and "average_power" in ds:
            _require(path, set(ds.variables), SWEEP_COLUMNS, "load sweep")
            cols = {k: ds[k].values for k in SWEEP_COLUMNS + ("peak_voltage", "peak_current") if k in ds.variables}
            return "sweep", {**cols, "header": dict(ds.attrs)}
        raise TengsimError(f"{path}: not a tengsim result")
    raise TengsimError(f"{path}: unknown result format {suffix!r} (use .nc or .csv)")
