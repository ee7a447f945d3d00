"""Observers: scalar observables of each equilibrium, one column each in the result table.

The continuation path calls every observer once per recorded equilibrium with the solved state
``eq`` (``eq.P``, ``eq.H`` in the units of Eq. 7) and a :class:`Context` (grid, apex index, initial
gap U0, law, kernel).  The built-in :class:`Summary` gives the columns every run has (Eq. 10's F, the
contact length, ...); more observers are passed to :func:`tengsim.simulate` or
:func:`tengsim.continuation.run_path` as ``observers=`` (registered names or objects) and their columns are
appended to the table, CSV and NetCDF.  A user registers one with::

    @OBSERVERS.register("mine")
    class Mine:
        columns = ("my_col",)
        def __call__(self, eq, ctx): return {"my_col": float(eq.P.max())}
"""
from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from tengsim.analysis import summarize
from tengsim.errors import TengsimError
from tengsim.registry import OBSERVERS


@dataclass(frozen=True)
class Context:
    """What an observer may look at besides the equilibrium itself."""

    grid: object
    apex: tuple
    U0: np.ndarray
    law: object = None
    kernel: object = None


@OBSERVERS.register("summary")
class Summary:
    """Force (Eq. 10), Greenwood contact length Λc, repulsive area, charged area (the 2-D area inside the law's
    peak-tension separation, :func:`tengsim.analysis.charged_area`), min gap, max/min pressure."""

    columns = ("F", "contact_length", "area_repulsive", "charged_fraction", "min_gap", "max_pressure", "min_pressure")
    units = {"min_gap": "ε", "max_pressure": "W/ε (Eq. 8)", "min_pressure": "W/ε (Eq. 8)"}

    def __call__(self, eq, ctx: Context) -> dict:
        return asdict(summarize(eq.P, eq.H, ctx.grid, ctx.apex, ctx.law,
                                bool(getattr(ctx.kernel, "periodic", False))))


def resolve(observers) -> list:
    """Observer objects for ``observers``: registered names (or aliases), classes, or instances.

    A registered class is instantiated without arguments.  An observer needs ``columns`` and to be
    callable; a TengsimError names the one that is not.  The built-in :class:`Summary` always runs,
    so naming it adds nothing.
    """
    if observers is None:
        return []
    if isinstance(observers, str):
        observers = [s for s in (x.strip() for x in observers.split(",")) if s]
    out = []
    for o in observers:
        obj = OBSERVERS.get(o) if isinstance(o, str) else o
        if isinstance(obj, type):
            obj = obj()
        if type(obj) is Summary:
            continue
        cols = getattr(obj, "columns", None)
        if not callable(obj) or not cols or isinstance(cols, str):
            raise TengsimError(f"observer {o!r} must be callable and name its columns (a tuple of names)")
        out.append(obj)
    return out


def check_columns(observers, taken) -> list:
    """The new column names of ``observers``; a TengsimError if one repeats a name in ``taken``."""
    seen = set(taken)
    cols = []
    for o in observers:
        for c in o.columns:
            if c in seen:
                raise TengsimError(f"observer {type(o).__name__} column {c!r} is already in the result table")
            seen.add(c)
            cols.append(c)
    return cols


def observe(o, eq, ctx) -> dict:
    """Call one observer and check it returned exactly its columns as numbers."""
    vals = o(eq, ctx)
    if not isinstance(vals, dict) or set(vals) != set(o.columns):
        raise TengsimError(f"observer {type(o).__name__} must return a dict with keys {tuple(o.columns)}")
    return {k: float(v) for k, v in vals.items()}


@OBSERVERS.register("array_area")
class ArrayArea:
    """Charged area over a K × K array (``tengsim.shapes.arrays``; a plain grid is one cell).

    ``area_fraction_greenwood`` = Σ_cells Λc,k² / (K L̄)²: the paper's A/S of Eq. (12), λc²/L², summed
    over the cells, with Λc,k the Greenwood contact length of cell k (twice the distance from the
    cell's highest point to the tensile pressure peak along X, as the built-in ``contact_length``).
    ``area_fraction_repulsive`` = (area with P > 0)/(K L̄)²; ``cells_in_contact`` counts the cells
    with Λc,k > 0.
    """

    columns = ("area_fraction_greenwood", "area_fraction_repulsive", "cells_in_contact")
    units = {"area_fraction_greenwood": "1 (A/S, Eq. 12)", "area_fraction_repulsive": "1 (A/S)",
             "cells_in_contact": "cells"}

    def __call__(self, eq, ctx: Context) -> dict:
        from tengsim.analysis import apex_index, contact_length
        from tengsim.grid import Grid

        g = ctx.grid
        K = int(getattr(g, "cells", 1))
        nx, ny = g.nx // K, g.ny // K
        cg = Grid(nx, ny, g.dx, g.dy)
        total, n_in = 0.0, 0
        for i in range(K):
            for j in range(K):
                sl = (slice(i * nx, (i + 1) * nx), slice(j * ny, (j + 1) * ny))
                lam = contact_length(eq.P[sl], cg, apex_index(ctx.U0[sl]))
                total += lam * lam
                n_in += lam > 0
        A = g.lx * g.ly
        return {"area_fraction_greenwood": min(total / A, 1.0),
                "area_fraction_repulsive": float(np.count_nonzero(eq.P > 0)) * g.area / A,
                "cells_in_contact": n_in}
