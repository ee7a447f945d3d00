"""Result of an approach–retraction run: curves, maps, events and every parameter; NetCDF/CSV out."""
from __future__ import annotations

import json
from dataclasses import dataclass, field

import numpy as np
from scipy.integrate import trapezoid

from tengsim import status as _status
from tengsim.grid import Grid

CURVE_COLUMNS = ["branch", "D", "F", "contact_length", "area_repulsive", "converged", "residual",
                 "iterations", "n_conv", "on_grid", "jump", "min_gap", "max_pressure",
                 "min_pressure", "energy", "seconds", "in_law_range", "process_zone", "status"]
PHYSICAL_COLUMNS = ["F_N", "pressure_Pa", "contact_length_m"]
_FLAGS = ("converged", "on_grid", "jump", "in_law_range")


@dataclass(frozen=True)
class Jump:
    """A discontinuity on a branch: the state jumped between D_before and D_after."""

    branch: str
    D_before: float
    D_after: float
    F_before: float
    F_after: float
    length_before: float
    length_after: float

    @property
    def kind(self) -> str:
        if self.branch == "approach":
            return "jump-in" if self.length_after >= self.length_before else "jump"
        return "jump-out" if self.length_after <= self.length_before else "jump"


@dataclass
class ContactResult:
    """Curves (one entry per equilibrium, in path order), maps at chosen D, and parameters.

    ``table`` holds the columns of :data:`CURVE_COLUMNS`, then any observer columns, then (for a
    physical run, see :meth:`add_physical`) ``F_N``, ``pressure_Pa`` and ``contact_length_m``.
    ``units`` maps a column to its unit text; ``scaling`` is the run's physical scaling or None.
    """

    table: dict
    grid: Grid
    maps: list = field(default_factory=list)
    params: dict = field(default_factory=dict)
    seconds: float = 0.0
    final_state: object = None
    units: dict = field(default_factory=dict)
    scaling: object = None

    @classmethod
    def from_rows(cls, rows, maps, grid, seconds=0.0, final_state=None, extra_columns=()):
        table = {k: np.array([r.get(k, np.nan) for r in rows], dtype=float if k == "process_zone" else None)
                 for k in [*CURVE_COLUMNS, *extra_columns] if k != "status"}
        if rows and all("status" in r for r in rows):  # classified as recorded (tengsim.continuation)
            table["status"] = np.array([r["status"] for r in rows]).astype(str)
        else:
            table["status"] = _status.classify(table, grid.dx)
        return cls(table=table, grid=grid, maps=maps, seconds=seconds, final_state=final_state)

    def add_physical(self, scaling) -> None:
        """Append F_N (force per cell, N), pressure_Pa (F_N / cell area, if known) and contact_length_m
        from the dimensionless F and Λc, with ``scaling`` (a :class:`tengsim.units.Scaling`)."""
        t = self.table
        t["F_N"] = np.asarray(scaling.force(t["F"]), dtype=float)
        if getattr(scaling, "cell_area", None):
            t["pressure_Pa"] = t["F_N"] / scaling.cell_area
        t["contact_length_m"] = np.asarray(scaling.length(t["contact_length"]), dtype=float)
        self.scaling = scaling
        self.units.update(scaling.units())

    def column_units(self) -> dict:
        """Unit text of every column that has one: the shape's own scaling, then observers' units."""
        lat = self.params.get("lateral_unit", "ℓ")
        u = {"D": "ε (rigid approach, Eq. 7)", "F": f"3π W ℓ²/ε with ℓ = {lat} (per cell, Eq. 10)",
             "contact_length": f"ℓ = {lat} (Λc, Eq. 7)", "residual": "ε (max |r| of Eq. 9)",
             "area_repulsive": f"ℓ² with ℓ = {lat}", "min_gap": "ε",
             "max_pressure": "W/ε (Eq. 8)", "min_pressure": "W/ε (Eq. 8)"}
        u.update(self.units)
        return {k: v for k, v in u.items() if k in self.table}

    @property
    def columns(self) -> list:
        """Table columns in output order."""
        return [*CURVE_COLUMNS, *[k for k in self.table if k not in CURVE_COLUMNS]]

    # ---- selections -------------------------------------------------------------------------
    def branch(self, name: str) -> dict:
        """Columns restricted to one branch ('approach' or 'retraction'), in path order."""
        m = self.table["branch"] == name
        return {k: v[m] for k, v in self.table.items()}

    @property
    def all_converged(self) -> bool:
        return bool(np.all(self.table["converged"]))

    @property
    def status(self) -> str:
        """Overall status, the worst row's: 'ok', 'under_resolved', 'out_of_law_range' or 'not_converged'
        (criteria in :mod:`tengsim.status`)."""
        s = self.table.get("status")
        if s is None or np.asarray(s).dtype.kind not in "US":  # older files: classify from the columns
            s = _status.classify(self.table, self.grid.dx)
        return _status.overall(s)

    def raise_for_status(self) -> "ContactResult":
        """Raise :class:`tengsim.status.ResultStatusError` unless :attr:`status` is 'ok'; else return self."""
        _status.raise_for_status(self)
        return self

    # ---- events -----------------------------------------------------------------------------
    @property
    def jumps(self) -> list[Jump]:
        out = []
        t = self.table
        for i in np.flatnonzero(t["jump"]):
            if i == 0 or t["branch"][i - 1] != t["branch"][i]:
                continue
            out.append(Jump(str(t["branch"][i]), float(t["D"][i - 1]), float(t["D"][i]),
                            float(t["F"][i - 1]), float(t["F"][i]),
                            float(t["contact_length"][i - 1]), float(t["contact_length"][i])))
        return out

    @property
    def pull_off_force(self) -> float:
        """Most tensile force on the retraction branch (the pull-off force, F of Eq. 10)."""
        r = self.branch("retraction")
        if len(r["F"]) == 0:
            return float("nan")
        return float(np.min(r["F"]))

    @property
    def hysteresis(self) -> float:
        """∮ F dD, approach minus retraction: the energy lost per cycle (for the paper's scaling the work
        per cell is 3π m² W ε²/n² times this value)."""
        a, r = self.branch("approach"), self.branch("retraction")
        if len(r["D"]) < 2:
            return 0.0
        ia = np.argsort(a["D"])
        ir = np.argsort(r["D"])
        return float(trapezoid(a["F"][ia], a["D"][ia]) - trapezoid(r["F"][ir], r["D"][ir]))

    def transition_D(self, full_length: float, fraction: float = 0.95) -> float:
        """First approach D at which Λc reaches ``fraction`` × ``full_length`` (linear interpolation):
        the partial-to-full contact transition of paper Fig. 4(a).  NaN if never reached."""
        a = self.branch("approach")
        L = a["contact_length"]
        target = fraction * full_length
        hit = np.flatnonzero(L >= target)
        if len(hit) == 0:
            return float("nan")
        i = hit[0]
        if i == 0:
            return float(a["D"][0])
        x0, x1, y0, y1 = a["D"][i - 1], a["D"][i], L[i - 1], L[i]
        if a["jump"][i] or y1 == y0:
            return float(x1)
        return float(x0 + (target - y0) * (x1 - x0) / (y1 - y0))

    # ---- output -----------------------------------------------------------------------------
    def to_dataset(self):
        """xarray Dataset: curves along dim 'step', maps along ('map', 'x', 'y'), parameters in attrs."""
        import xarray as xr

        t = self.table
        data = {k: ("step", t[k].astype(str) if k in ("branch", "status") else t[k])
                for k in self.columns if k in t}  # files from before a column existed lack it
        for k in _FLAGS:
            data[k] = ("step", t[k].astype(np.int8))
        ds = xr.Dataset(data)
        for k, u in self.column_units().items():
            ds[k].attrs["units"] = u
        if self.maps:
            ds = ds.assign(
                map_branch=("map", np.array([m["branch"] for m in self.maps])),
                map_D=("map", np.array([m["D"] for m in self.maps])),
                P=(("map", "x", "y"), np.stack([m["P"] for m in self.maps])),
                H=(("map", "x", "y"), np.stack([m["H"] for m in self.maps])),
            )
        ds = ds.assign_coords(x=("x", self.grid.x), y=("y", self.grid.y))
        ds.attrs["params"] = json.dumps(self.params, default=str)
        ds.attrs["pull_off_F"] = self.pull_off_force
        ds.attrs["n_unconverged"] = int(np.count_nonzero(~t["converged"].astype(bool)))
        ds.attrs["n_outside_law_range"] = int(np.count_nonzero(~t["in_law_range"].astype(bool)))
        ds.attrs["status"] = self.status
        ds.attrs["jumps"] = json.dumps([j.__dict__ for j in self.jumps])
        ds.attrs["seconds"] = self.seconds
        for k, v in self.params.items():
            if isinstance(v, (int, float, str)) and not isinstance(v, bool):
                ds.attrs[k] = v
        return ds

    def csv_columns(self) -> dict:
        t = self.table
        return {k: t[k] for k in self.columns if k in t}

    def save(self, path) -> None:
        """Write ``.csv`` (curves, parameters in '#' header lines) or ``.nc`` (everything), atomically."""
        from pathlib import Path

        from tengsim import io
        from tengsim.errors import TengsimError

        suffix = Path(path).suffix.lower()
        if suffix == ".csv":
            io.write_csv(path, self.csv_columns(), header={**self.params, "units": self.column_units()})
        elif suffix in (".nc", ".netcdf", ".nc4"):
            io.write_dataset(self.to_dataset(), path)
        else:
            raise TengsimError(f"unknown output format {suffix!r} for {path} (use .csv or .nc)")
