"""The result of an approach–retraction run, a value: curves, maps, events and every parameter.

A :class:`ContactResult` is frozen and complete when it is made; a changed one is a new one
(:meth:`ContactResult.with_physical`, :func:`dataclasses.replace`).  Writing it is
:mod:`tengsim.results.write`'s, reading it back :mod:`tengsim.results.read`'s.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np

from tengsim import status as _status
from tengsim.grid import Grid
from tengsim.results import write
from tengsim.results.hysteresis import LoopEnergy, loop_energy
from tengsim.results.columns import CURVE_COLUMNS

TRANSITION_LENGTH_FRACTION = 0.95
"""The partial-to-full contact transition of paper Fig. 4(a) (:meth:`ContactResult.transition_D`, a study's
``transition_D``): the approach D where the contact length Λc reaches this fraction of its full-contact value.
Not the design's full contact (tengsim.run.area.FULL_CONTACT_AREA_FRACTION, the same 0.95 of another measure:
the charged area A/S, where it saturates under the load) nor a study's adhesive full contact (0.9 of Λc at zero
load): three questions, each with its own name; the values are those their results were published with."""


@dataclass(frozen=True)
class Jump:
    """A discontinuity on a branch: the state jumped between D_before and D_after.  ``area_before`` and
    ``area_after``: the charged area fraction on each side (NaN where the table has none)."""

    branch: str
    D_before: float
    D_after: float
    F_before: float
    F_after: float
    length_before: float
    length_after: float
    area_before: float = float("nan")
    area_after: float = float("nan")

    @property
    def kind(self) -> str:
        """'jump-in' (the approach's contact grew), 'jump-out' (the retraction's shrank), else 'jump'.  The
        contact is the charged area where the table has it: the 2-D area does not depend on how a state
        whose symmetry the jump broke lies in the cell, while the contact length (measured along the row
        through the apex) does; the contact length otherwise."""
        if math.isfinite(self.area_before) and math.isfinite(self.area_after):
            before, after = self.area_before, self.area_after
        else:
            before, after = self.length_before, self.length_after
        if self.branch == "approach":
            return "jump-in" if after >= before else "jump"
        return "jump-out" if after <= before else "jump"


@dataclass(frozen=True)
class ContactResult:
    """Curves (one entry per equilibrium, in path order), maps at chosen D, and parameters.

    ``table`` holds the columns of :data:`~tengsim.results.columns.CURVE_COLUMNS`, then any observer
    columns, then (for a physical run, see :meth:`with_physical`) ``F_N``, ``pressure_Pa`` and
    ``contact_length_m``.  ``units`` maps a column to its unit text; ``scaling`` is the run's physical
    scaling or None.  Frozen: its parameters are complete when it is made.
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
    def from_rows(cls, rows, maps, grid, seconds=0.0, final_state=None, extra_columns=(), params=None,
                  units=None):
        """The result of recorded rows (dicts of the columns); ``params`` and ``units`` as they are to stay."""
        table = {k: np.array([r.get(k, np.nan) for r in rows], dtype=float if k == "process_zone" else None)
                 for k in [*CURVE_COLUMNS, *extra_columns] if k != "status"}
        if rows and all("status" in r for r in rows):  # classified as recorded (tengsim.continuation)
            table["status"] = np.array([r["status"] for r in rows]).astype(str)
        else:
            table["status"] = _status.classify(table, grid.dx)
        return cls(table=table, grid=grid, maps=maps, params=dict(params or {}), seconds=seconds,
                   final_state=final_state, units=dict(units or {}))

    def with_physical(self, scaling) -> "ContactResult":
        """This result with F_N (force per cell, N), pressure_Pa (F_N / cell area, if known) and
        contact_length_m appended, from the dimensionless F and Λc with ``scaling`` (a
        :class:`tengsim.units.Scaling`), which it then carries."""
        t = dict(self.table)
        t["F_N"] = np.asarray(scaling.force(t["F"]), dtype=float)
        if getattr(scaling, "cell_area", None):
            t["pressure_Pa"] = t["F_N"] / scaling.cell_area
        t["contact_length_m"] = np.asarray(scaling.length(t["contact_length"]), dtype=float)
        return dataclasses.replace(self, table=t, scaling=scaling, units={**self.units, **scaling.units()})

    def column_units(self) -> dict:
        """Unit text of every column that has one: the shape's own scaling, then observers' units."""
        lat = self.params.get("lateral_unit", "ℓ")
        u = {"D": "ε (rigid approach, Eq. 7)", "F": f"3π W ℓ²/ε with ℓ = {lat} (per cell, Eq. 10)",
             "contact_length": f"ℓ = {lat} (Λc, Eq. 7)", "residual": "ε (max |r| of Eq. 9)",
             "area_repulsive": f"ℓ² with ℓ = {lat}", "charged_fraction": "1 (A/S of the cell)", "min_gap": "ε",
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
    def status(self) -> _status.Status:
        """Overall status, the worst row's (a :class:`tengsim.status.Status`, equal to its text): 'ok',
        'under_resolved', 'out_of_law_range' or 'not_converged' (criteria in :mod:`tengsim.status`)."""
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
            area = t.get("charged_fraction")
            out.append(Jump(str(t["branch"][i]), float(t["D"][i - 1]), float(t["D"][i]),
                            float(t["F"][i - 1]), float(t["F"][i]),
                            float(t["contact_length"][i - 1]), float(t["contact_length"][i]),
                            *((float(area[i - 1]), float(area[i])) if area is not None else ())))
        return out

    @property
    def pull_off_force(self) -> float:
        """Most tensile force on the retraction branch (the pull-off force, F of Eq. 10)."""
        r = self.branch("retraction")
        if len(r["F"]) == 0:
            return float("nan")
        return float(np.min(r["F"]))

    @property
    def loop_energy(self) -> LoopEnergy:
        """∮ F dD, approach minus retraction, over the D range both branches cover, with its quadrature
        uncertainty (:func:`tengsim.results.hysteresis.loop_energy`)."""
        t = self.table
        return loop_energy(t["D"], t["F"], t["branch"], t.get("jump"), t.get("residual"))

    @property
    def hysteresis(self) -> float:
        """∮ F dD, approach minus retraction: the energy lost per cycle (for the paper's scaling the work
        per cell is 3π m² W ε²/n² times this value); 0 where it is within its quadrature uncertainty
        (:attr:`loop_energy`'s bound), never a negative energy that is only quadrature error."""
        return self.loop_energy.value

    def transition_D(self, full_length: float, fraction: float = TRANSITION_LENGTH_FRACTION) -> float:
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

    # ---- output (tengsim.results.write) -------------------------------------------------------
    def unit_scales(self) -> dict:
        """SI value of one unit of each dimensionless scale (:func:`tengsim.results.write.unit_scales`)."""
        return write.unit_scales(self)

    def to_dataset(self):
        """xarray Dataset by the CF-1.10 conventions (:func:`tengsim.results.write.to_dataset`)."""
        return write.to_dataset(self)

    def csv_columns(self) -> dict:
        return write.csv_columns(self)

    def save(self, path) -> None:
        """Write ``.csv`` or ``.nc``, atomically (:func:`tengsim.results.write.save`)."""
        write.save(self, path)
