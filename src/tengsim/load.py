"""Read results written by tengsim back in (NetCDF or CSV)."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from tengsim.errors import TengsimError
from tengsim.grid import Grid
from tengsim.results import CURVE_COLUMNS, ContactResult


def _read_csv(path: Path):
    header, rows, names = {}, [], None
    with open(path) as fh:
        for line in fh:
            line = line.rstrip("\n")
            if line.startswith("#"):
                k, _, v = line[1:].partition(":")
                try:
                    header[k.strip()] = json.loads(v)
                except json.JSONDecodeError:
                    header[k.strip()] = v.strip()
            elif names is None:
                names = line.split(",")
            elif line:
                rows.append(line.split(","))
    if names is None:
        raise TengsimError(f"{path}: no column header found")
    cols = {}
    for j, n in enumerate(names):
        vals = [r[j] for r in rows]
        try:
            cols[n] = np.array([float(v) for v in vals])
        except ValueError:
            cols[n] = np.array(vals)
    return header, cols


def load_result(path) -> tuple[str, object]:
    """Return ('contact', ContactResult) or ('device', xarray.Dataset / columns dict)."""
    path = Path(path)
    if not path.exists():
        raise TengsimError(f"result file {path} not found")
    suffix = path.suffix.lower()
    if suffix == ".csv":
        header, cols = _read_csv(path)
        if "branch" in cols and "D" in cols:
            table = {}
            for k in CURVE_COLUMNS:
                if k in cols:
                    table[k] = cols[k]
                else:
                    table[k] = np.zeros(len(cols["D"]))
            if "in_law_range" not in cols:
                table["in_law_range"] = np.ones(len(cols["D"]))
            for k in ("converged", "on_grid", "jump", "in_law_range"):
                table[k] = table[k].astype(bool)
            dx = float(header.get("dx", 1.0))
            n = int(header.get("nx", 3))
            return "contact", ContactResult(table=table, grid=Grid(max(n, 3), max(n, 3), dx, dx), params=header)
        if "t" in cols:
            return "device", cols
        raise TengsimError(f"{path}: not a tengsim result (no 'branch'/'D' or 't' columns)")
    if suffix == ".nc":
        import xarray as xr

        try:
            ds = xr.load_dataset(path, engine="h5netcdf")
        except Exception as exc:  # noqa: BLE001 - any reader failure is a bad input file
            raise TengsimError(f"cannot read {path} as NetCDF: {exc}") from None
        if "branch" in ds and "D" in ds:
            table = {k: ds[k].values for k in CURVE_COLUMNS if k in ds}
            table.setdefault("in_law_range", np.ones(ds.sizes["step"]))
            for k in ("converged", "on_grid", "jump", "in_law_range"):
                table[k] = table[k].astype(bool)
            table["branch"] = table["branch"].astype(str)
            params = json.loads(ds.attrs.get("params", "{}"))
            x = ds["x"].values
            dx = float(x[1] - x[0]) if len(x) > 1 else 1.0
            grid = Grid(len(x), len(ds["y"]), dx, dx)
            maps = []
            if "P" in ds:
                for i in range(ds.sizes["map"]):
                    maps.append(dict(branch=str(ds["map_branch"].values[i]), D=float(ds["map_D"].values[i]),
                                     P=ds["P"].values[i], H=ds["H"].values[i]))
            return "contact", ContactResult(table=table, grid=grid, maps=maps, params=params)
        if "t" in ds:
            return "device", ds
        raise TengsimError(f"{path}: not a tengsim result")
    raise TengsimError(f"{path}: unknown result format {suffix!r} (use .nc or .csv)")
