"""Read results written by tengsim back in (NetCDF or CSV): contact runs, device time series, load sweeps.

Nothing is invented: a file that lacks a required column is refused (the columns are named), and a
CSV without its grid in the header gives a result with ``grid=None`` (curves need no grid).
"""
from __future__ import annotations

import csv
import io
import json
from pathlib import Path

import numpy as np

from tengsim.errors import TengsimError
from tengsim.grid import Grid
from tengsim.results.columns import CURVE_COLUMNS
from tengsim.results.result import ContactResult

BOOL_COLUMNS = ("converged", "on_grid", "jump", "in_law_range")
# written by every tengsim version; later additions (in_law_range, process_zone, status, charged_fraction) are
# taken when present (a file without charged_fraction: A/S by the paper's Λc, tengsim.run.area.loaded_area)
LATER_COLUMNS = ("in_law_range", "process_zone", "status", "charged_fraction")
REQUIRED_CONTACT = tuple(k for k in CURVE_COLUMNS if k not in LATER_COLUMNS)
SWEEP_COLUMNS = ("R", "energy_per_cycle", "average_power")


def _header(lines):
    """('# key: json' lines read from the iterator ``lines`` as a dict, the first other line or '')."""
    header = {}
    for line in lines:
        if not line.startswith("#"):
            return header, line
        k, _, v = line[1:].rstrip("\r\n").partition(":")
        try:
            header[k.strip()] = json.loads(v)
        except json.JSONDecodeError:
            header[k.strip()] = v.strip()
    return header, ""


def _read_csv(path: Path, allow_empty: bool = False):
    """('# key: json' header lines as a dict, {column: array}) of a CSV written by
    :func:`tengsim.io.write_csv`: quoted fields are read by :mod:`csv`; a column of numbers is a float
    array, any other a str array.  In a partial file (header ``complete: false``, written as the run went,
    :class:`tengsim.results.RowStream`) a last line without its newline, half written when the run was
    killed, is left out.  ``allow_empty``: a file with no column line gives ({header}, {})."""
    rows, names = [], None
    with open(path, newline="", encoding="utf-8") as fh:
        lines = iter(io.StringIO(fh.read(), newline=""))  # lines split as the file's own reader splits them
    header, line = _header(lines)
    body = [line, *lines]
    if header.get("complete") is False and body and body[-1] and not body[-1].endswith(("\n", "\r")):
        body.pop()  # torn by a kill mid-write
    for row in csv.reader(body):
        if not row:
            continue
        if names is None:
            names = row
        else:
            rows.append(row)
    if names is None:
        if allow_empty:
            return header, {}
        if header.get("complete") is False:
            raise TengsimError(f"{path}: an incomplete run that had finished no equilibrium yet")
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


def _require(path, cols, required, what, text=("branch", "status")):
    """Refuse a file lacking a column of ``required``, or whose required column (other than the ``text``
    ones) holds text: a hand-edited 'abc' in D is named, not a TypeError inside a plot."""
    from tengsim.errors import shown

    missing = [k for k in required if k not in cols]
    if missing:
        raise TengsimError(f"{path}: {what} lacks column(s) {', '.join(missing)}")
    for k in required:
        a = np.asarray(cols[k])
        if k not in text and a.dtype.kind not in "fiub":
            row = next((i for i, v in enumerate(a.tolist()) if not _is_number(v)), 0)
            raise TengsimError(f"{path}: column {k!r} must hold numbers, but data row {row + 1} is "
                               f"{shown(a.tolist()[row] if len(a) else '')}")


def _is_number(v) -> bool:
    try:
        float(v)
    except (TypeError, ValueError):
        return False
    return True


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


def _partial_maps(path: Path, header: dict) -> list:
    """The maps an incomplete run writing a NetCDF file kept beside its partial rows (``OUT.partial.maps.npz``,
    :class:`tengsim.results.RowStream`); none for any other file."""
    npz = Path(str(path)[: -len(".csv")] + ".maps.npz")
    if header.get("complete") is not False or not npz.is_file():
        return []
    try:
        with np.load(npz) as z:
            return [dict(branch=str(b), D=float(d), P=p, H=h)
                    for b, d, p, h in zip(z["map_branch"], z["map_D"], z["P"], z["H"])]
    except (OSError, KeyError, ValueError) as exc:
        raise TengsimError(f"{npz}: cannot read the maps of this incomplete run: {exc}") from None


def incomplete_note(kind: str, obj) -> str | None:
    """One line saying that a loaded result is an incomplete run (written as it went and cut short), or None."""
    if kind != "contact" or obj.params.get("complete") is not False:
        return None
    n = len(obj.table["D"])
    return (f"an incomplete run: {n} finished equilibri{'um' if n == 1 else 'a'} of {obj.params.get('partial_of', '?')} "
            "(continue it with --resume)")


def read_partial(path) -> tuple[dict, dict]:
    """``(header, columns)`` of a partial file written by :class:`tengsim.results.RowStream`, for
    ``--resume``; columns is empty when the run had finished no equilibrium.  Anything else is refused."""
    path = Path(path)
    try:
        header, cols = _read_csv(path, allow_empty=True)
    except TengsimError as exc:
        raise TengsimError(f"--resume: {exc}") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise TengsimError(f"--resume: cannot read {path}: {getattr(exc, 'strerror', None) or exc}") from None
    if header.get("complete") is not False or not header.get("run_digest"):
        raise TengsimError(f"--resume: {path} is not a partial file written by tengsim (no 'complete: false' "
                           "and 'run_digest' header)")
    missing = [k for k in ("branch", "D", "F", "on_grid", "jump") if cols and k not in cols]
    if missing:
        raise TengsimError(f"--resume: {path} lacks column(s) {', '.join(missing)}")
    return header, cols


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
            return "contact", ContactResult(table=table, grid=grid, params=header, maps=_partial_maps(path, header))
        if "t" in cols:
            _require(path, cols, ("t",), "device time series")
            if not len(cols["t"]):
                raise TengsimError(f"{path}: a device time series with no rows")
            return "device", cols
        if "R" in cols:
            _require(path, cols, SWEEP_COLUMNS, "load sweep")
            R = np.asarray(cols["R"], dtype=float)
            if not len(R) or not np.all(np.isfinite(R) & (R > 0)):
                raise TengsimError(f"{path}: a load sweep needs rows with load resistances R > 0 (finite), "
                                   f"got {len(R)} row(s)" + ("" if not len(R) else f", R from {R.min():g}"))
            return "sweep", {**cols, "header": header}
        raise TengsimError(f"{path}: not a tengsim result (no 'branch'/'D', 't' or 'R' columns)")
    if suffix == ".nc":
        from tengsim.io import read_dataset

        try:
            ds = read_dataset(path)
        except Exception as exc:  # noqa: BLE001 - any reader failure is a bad input file
            raise TengsimError(f"cannot read {path} as NetCDF: {exc}") from None
        if "branch" in ds and "D" in ds:
            try:  # the run's parameters, stored once as JSON text (CF layout and older files alike)
                params = json.loads(ds.attrs.get("params", "{}"))
            except (TypeError, ValueError) as exc:
                raise TengsimError(f"{path}: its 'params' attribute is not JSON: {exc}") from None
            if not isinstance(params, dict):
                raise TengsimError(f"{path}: its 'params' attribute is not a JSON object")
            if "level" in ds.dims:  # resolve = auto: the table of the grids (tengsim.results.write._resolution_vars)
                params["resolution"] = {k[len("resolution_"):]: [None if isinstance(x, float) and x != x else x
                                                                 for x in v.values.tolist()]
                                        for k, v in ds.variables.items() if v.dims == ("level",)
                                        and k.startswith("resolution_")}
            if "x" not in ds.variables or "y" not in ds.variables:
                raise TengsimError(f"{path}: a contact result without its grid coordinates x, y")
            x, y = ds["x"].values, ds["y"].values
            if len(x) < 3 or len(y) < 3:
                raise TengsimError(f"{path}: grid coordinates x, y have {len(x)}, {len(y)} points (need >= 3)")
            grid = Grid(len(x), len(y), float(x[1] - x[0]), float(y[1] - y[0]))
            # every column along 'step', coordinates (D, branch: CF layout) and data variables (older files)
            table = _contact_table(path, {k: v.values for k, v in ds.variables.items() if v.dims == ("step",)},
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
