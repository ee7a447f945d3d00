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
        refined = self.params.get("resolve_status")  # resolve = auto stopped by max_pixels (tengsim.run.resolve)
        return _status.overall([*np.asarray(s).astype(str).tolist(), *([str(refined)] if refined else [])])

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
    def unit_scales(self) -> dict:
        """SI value of one unit of each dimensionless scale of :data:`_SCALES` ('eps' and 'lateral' in m,
        'area' in m², 'force' in N per cell, 'pressure' in Pa): from the run's scaling, else from the
        parameters a physical run records (eps_m, W_J_m2, and lateral_m or base_m/height_m); {} for a
        dimensionless run."""
        import math

        s, p = self.scaling, self.params
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

    def _cf_attrs(self, name: str, scales: dict) -> dict:
        """CF attributes of one variable (see :data:`_CF_COLUMNS`): long_name and units, a dimensionless
        one's scale, a flag's values and meanings."""
        attrs = {}
        if name in _CF_COLUMNS:
            long, unit = _CF_COLUMNS[name]
        else:  # an observer's column: the unit text it declared
            long, unit = f"{name} (observer column)", None
            text = self.column_units().get(name)
            if text is not None:
                head = str(text).split(" (")[0].strip()
                unit = _OBSERVER_SCALES.get(head, head if head in _UDUNITS else None)
                if unit is None or head != text:
                    attrs["comment"] = f"units declared by the observer: {text}"
        attrs["long_name"] = long
        if unit in _SCALES:
            text, si = _SCALES[unit]
            lat = self.params.get("lateral_unit", "ℓ")
            if "ℓ" in text and lat != "ℓ":
                text += f" with ℓ = {lat}"
            attrs.update(units="1", unit_scale_text=text)
            if unit in scales:
                attrs.update(unit_scale=scales[unit], unit_scale_units=si)
        elif unit is not None:
            attrs["units"] = unit
        if name in _FLAGS:
            attrs.update(flag_values=np.array([0, 1], dtype=np.int8), flag_meanings="false true")
        return attrs

    def to_dataset(self):
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

        t = self.table
        data = {}
        for k in self.columns:
            if k not in t:  # files from before a column existed lack it
                continue
            v = np.asarray(t[k])
            data[k] = ("step", v.astype(str) if k in ("branch", "status") else
                       v.astype(np.int8) if k in _FLAGS else v)
        ds = xr.Dataset(data).set_coords(["D", "branch"])
        if self.maps:
            ds = ds.assign(
                P=(("map", "x", "y"), np.stack([m["P"] for m in self.maps])),
                H=(("map", "x", "y"), np.stack([m["H"] for m in self.maps])),
            ).assign_coords(map_D=("map", np.array([m["D"] for m in self.maps], dtype=float)),
                            map_branch=("map", np.array([str(m["branch"]) for m in self.maps])))
        if self.grid is not None:
            ds = ds.assign_coords(x=("x", self.grid.x), y=("y", self.grid.y))
        scales = self.unit_scales()
        for k, var in ds.variables.items():
            var.attrs.update(self._cf_attrs(k, scales))
        params, ds = self._resolution_vars(ds, scales)
        conv = t["converged"].astype(bool)
        attrs = {"params": json.dumps(params, default=str), "status": self.status,
                 "pull_off_F": self.pull_off_force, "n_unconverged": int(np.count_nonzero(~conv))}
        if "in_law_range" in t:
            attrs["n_outside_law_range"] = int(np.count_nonzero(~t["in_law_range"].astype(bool)))
        attrs.update(jumps=json.dumps([j.__dict__ for j in self.jumps]), seconds=self.seconds)
        ds.attrs = attrs
        return cf_conventions(ds, "tengsim contact result: approach-retraction curves of a rigid plate on an "
                                  "adhesive micro-structured half-space")

    def _resolution_vars(self, ds, scales):
        """(params without 'resolution', ds with it): the refinement's table (tengsim.run.resolve, one row per grid)
        as variables ``resolution_<column>`` along dimension ``level`` (coarsest first), CF attributes as the
        curves' (dx in ℓ, F in its unit, D in ε)."""
        tab = self.params.get("resolution")
        if not isinstance(tab, dict) or not tab.get("dx"):
            return self.params, ds
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
        return {k: v for k, v in self.params.items() if k != "resolution"}, ds

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


# ---- writing as the run goes ----------------------------------------------------------------------
PARTIAL_SUFFIX = ".partial.csv"
_STREAM_KEYS = ("complete", "partial_of", "run_digest")  # the stream's own header lines
_RESUME_RTOL = 1e-5  # a re-solved row and the file's row agree in F to this, relative to max(1, |F|)
_PATH_ENDS = ("d_max", "f_max")  # a resumed run may raise these: the same path, longer (its start is kept)


def _longer_path(now: dict, header: dict) -> bool:
    """True when the run ``now`` differs from the partial file's run only by a longer path (a larger d_max
    or f_max), so the file's rows up to where the paths part are this run's too."""
    keys = {k for k in [*now, *header] if k not in _STREAM_KEYS}
    diff = [k for k in keys if now.get(k) != header.get(k)]
    try:
        return bool(diff) and all(k in _PATH_ENDS and float(now[k]) >= float(header[k]) for k in diff)
    except (KeyError, TypeError, ValueError):
        return False


def partial_path(out):
    """The file a run writes its rows to as they are computed: ``OUT.partial.csv`` beside ``OUT``."""
    from pathlib import Path

    return Path(str(out) + PARTIAL_SUFFIX)


def checkpoint_path(out):
    """Where a refinement (``resolve = 'auto'``) writing ``OUT`` keeps its finished grids, the finest one's
    result and the levels so far: ``OUT.resolve.nc`` beside it (:class:`tengsim.run.resolve.Checkpoint`)."""
    from pathlib import Path

    return Path(str(out) + ".resolve.nc")


def partial_maps_path(out):
    """The maps of a run writing to a NetCDF ``OUT``, kept as they are computed: ``OUT.partial.maps.npz``."""
    from pathlib import Path

    return Path(str(out) + ".partial.maps.npz")


def run_digest(params: dict) -> str:
    """SHA-256 of the run's parameters (strict JSON, sorted keys): a partial file resumes only under the
    run that wrote it (same parameters, same tengsim version)."""
    import hashlib

    from tengsim.io import jsonable

    return hashlib.sha256(json.dumps(jsonable(params), sort_keys=True).encode()).hexdigest()


class RowStream:
    """Writes a contact run's rows to ``OUT.partial.csv`` as each equilibrium finishes, so a run that is
    killed (even by SIGKILL) keeps every finished equilibrium.

    Pass it as ``sink`` to :func:`tengsim.run.simulate.simulate` / ``run_contact``.  The first row writes the
    file, whole (atomically): the header (``# complete: false``, ``# partial_of``, ``# run_digest`` and the
    run's parameters given to :meth:`begin`, as '# key: json' lines) and the column names, so a run that
    fails before its first equilibrium leaves nothing; each row is then appended as one CSV line (the
    format of :meth:`ContactResult.save`) and flushed to the operating system, so it survives the process
    being killed; ``os.fsync`` runs at
    most every ``fsync_seconds`` (against a machine crash, kept cheap).  For a NetCDF output (``maps=True``)
    the maps go to ``OUT.partial.maps.npz`` (written whole, atomically, when a map is added).  Once the
    whole result is saved, :meth:`finish` removes both.  A partial file is a readable result
    (:func:`tengsim.load.load_result`), marked incomplete by its ``complete: false`` header.

    ``resume=(header, columns)`` (:func:`tengsim.load.read_partial`) continues such a file: :meth:`begin`
    refuses it unless its run digest is this run's (the first differing parameter is named), and the rows
    it holds are solved again and each checked against the file (branch, D, on_grid and jump equal, F
    within 1e-5 of max(1, |F|)) instead of being written; later rows are appended.  The path is walked
    from its start again because each equilibrium is warm-started from the states before it, which the
    file does not hold: a resumed file is the uninterrupted run's, and resuming costs the finished part's
    solves once more.
    """

    def __init__(self, out, resume=None, maps: bool = False, fsync_seconds: float = 10.0):
        self.out, self.path = out, partial_path(out)
        self.maps_path = partial_maps_path(out) if maps else None
        self.resume = resume
        self.fsync_seconds = fsync_seconds
        self.fh, self.columns, self.n, self.maps = None, None, 0, []
        self._old, self._head, self._longer = {}, None, False
        if resume is not None:
            header, cols = resume
            self._old = cols
            self.columns = list(cols) or None
        self.n_old = len(next(iter(self._old.values()))) if self._old else 0
        self._synced = 0.0

    @property
    def n_written(self) -> int:
        """Rows the partial file holds now."""
        return max(self.n, self.n_old)

    def begin(self, params: dict) -> None:
        import time

        from tengsim import io
        from tengsim.errors import TengsimError

        digest = run_digest(params)
        if self.resume is not None:
            header = self.resume[0]
            self._truncate_torn_line()
            now = io.jsonable(params)
            self._longer = header.get("run_digest") != digest and _longer_path(now, header)
            if self._longer:  # the file takes this run's header; its rows are checked as they come
                self._head = {"complete": False, "partial_of": str(self.out), "run_digest": digest, **params}
                self._rewrite(self.n_old)
            elif header.get("run_digest") != digest:
                keys = [k for k in [*now, *header] if k not in _STREAM_KEYS]
                diff = next((k for k in keys if now.get(k) != header.get(k)), None)
                what = (f"{diff}: {header.get(diff)!r} there, {now.get(diff)!r} now" if diff
                        else "its run digest differs")
                raise TengsimError(f"--resume: {self.path} was written by another run ({what}); "
                                   "delete it to start afresh")
            if self.fh is None:
                self.fh = open(self.path, "a", newline="")
        else:  # written with the first row: a run that fails before it leaves nothing behind
            self._head = {"complete": False, "partial_of": str(self.out), "run_digest": digest, **params}
        self._synced = time.monotonic()

    def _rewrite(self, keep: int) -> None:
        """The partial file again, whole (atomically): this run's header, the column names and its first
        ``keep`` rows (a longer path resumed: the rows past where the paths part are dropped)."""
        from tengsim import io

        if self.fh is not None:
            self.fh.close()
        lines = [ln for ln in open(self.path, newline="").read().splitlines(keepends=True) if not ln.startswith("#")]
        body = "".join(lines[:1 + keep]) if lines else ""
        io.write_text(self.path, io.header_lines(self._head) + body)
        self.fh = open(self.path, "a", newline="")

    def _truncate_torn_line(self) -> None:
        """Cut a last line that a kill left half written (no newline): the reader skipped it too."""
        with open(self.path, "rb+") as fh:
            data = fh.read()
            if data and not data.endswith(b"\n"):
                fh.truncate(data.rfind(b"\n") + 1)

    def __call__(self, row: dict, maps=()) -> None:
        import os
        import time

        from tengsim import io
        from tengsim.errors import TengsimError

        cols = [*[k for k in CURVE_COLUMNS if k in row], *[k for k in row if k not in CURVE_COLUMNS]]
        if self.fh is None:  # a new file: header and column names appear whole, then rows are appended
            io.write_text(self.path, io.header_lines(self._head) + io.csv_row(cols))
            self.fh = open(self.path, "a", newline="")
        if self.columns is None:
            if self.resume is not None:  # a partial file that had no row yet
                self.fh.write(io.csv_row(cols))
            self.columns = cols
        elif cols != self.columns:
            raise TengsimError(f"--resume: {self.path} has columns {', '.join(self.columns)}; this run "
                               f"has {', '.join(cols)}; delete it to start afresh")
        i, self.n = self.n, self.n + 1
        if maps and self.maps_path is not None:
            self.maps.extend(maps)
            self._write_maps()
        if i < self.n_old:
            self._check(i, row)
            return
        self.fh.write(io.csv_row([row[k] for k in self.columns]))
        self.fh.flush()  # in the operating system's hands: survives the process being killed
        if time.monotonic() - self._synced >= self.fsync_seconds:
            os.fsync(self.fh.fileno())
            self._synced = time.monotonic()

    def _check(self, i: int, row: dict) -> None:
        from tengsim.errors import TengsimError

        old = {k: self._old[k][i] for k in ("branch", "D", "F", "on_grid", "jump")}
        same = (str(old["branch"]) == str(row["branch"]) and float(old["D"]) == float(row["D"])
                and bool(float(old["on_grid"])) == bool(row["on_grid"])
                and bool(float(old["jump"])) == bool(row["jump"])
                and abs(float(old["F"]) - float(row["F"])) <= _RESUME_RTOL * max(1.0, abs(float(row["F"]))))
        if not same and self._longer:  # the longer path parts from the file's here: the rest is solved anew
            self._rewrite(i)
            self.n_old = i
            from tengsim import io

            self.fh.write(io.csv_row([row[k] for k in self.columns]))
            self.fh.flush()
            return
        if not same:
            raise TengsimError(
                f"--resume: row {i + 1} of {self.path} ({old['branch']}, D={float(old['D']):.10g}, "
                f"F={float(old['F']):.10g}) is not what this run gives ({row['branch']}, D={float(row['D']):.10g}, "
                f"F={float(row['F']):.10g}); delete it to start afresh")

    def _write_maps(self) -> None:
        from tengsim import io

        with io.atomic_path(self.maps_path) as tmp, open(tmp, "wb") as fh:
            np.savez(fh, map_branch=np.array([m["branch"] for m in self.maps]),
                     map_D=np.array([m["D"] for m in self.maps], dtype=float),
                     P=np.stack([m["P"] for m in self.maps]), H=np.stack([m["H"] for m in self.maps]))

    def close(self) -> None:
        """Flush, sync and close the partial file (it stays: a readable, incomplete result)."""
        import os

        if self.fh is not None and not self.fh.closed:
            self.fh.flush()
            os.fsync(self.fh.fileno())
            self.fh.close()

    def finish(self) -> None:
        """The whole result is saved: close and remove the partial file (and maps)."""
        self.close()
        for p in (self.path, self.maps_path, checkpoint_path(self.out)):  # a refinement's grids too
            if p is not None:
                p.unlink(missing_ok=True)
