"""A design's walk: the first grid, the path's D range and each grid's path, the maps kept on the way.

The first dx is the user's (a length) or :func:`start_dx`: the first grid of the refinement's sequence
(:mod:`tengsim.run.grids`) whose dx is at most the law's process zone over :data:`START_ZONE_PIXELS`.
The path to p_max is the run layer's (:mod:`tengsim.run.reach`): an adaptive D walk from D = -1 ε to a d_max found on
a grid twice as coarse as the default first grid (:func:`find_d_max`), each finer grid's walk ending a little past
the D at which the grid before it reached p_max (:func:`grid_path`).  The design chooses where the pressure and gap
maps are kept: at the asked pressures nearest 10 %, 50 % and 100 % of p_max (:func:`map_pressures`).
"""
from __future__ import annotations

import math

import numpy as np

from tengsim.run.reach import D_MIN, D_STEP, EXTEND_TRIES, path_to, reach as _reach  # noqa: F401
from tengsim.run.reach import D_MARGIN, find_d_max as reach_d_max, grid_path as reach_grid_path  # noqa: F401
from tengsim.run.reach import map_depths as reach_depths


def _say(progress, text):
    if progress is not None and hasattr(progress, "say"):
        progress.say(text)

START_ZONE_PIXELS = 12.0
"""Pixels across the law's a-priori process zone ℓ_D on a design's first grid (by default).  The grid status asks
for :data:`tengsim.status.RESOLUTION` (1.2); a design's numbers (A/S at the smallest contact of the curve, the
pull-off) ask for far more, and the refinement judges from the last three grids only, so coarser first grids are
walked and thrown away (the measurements behind the 12: docs/benchmarks.md, "A design's walk").  A design that
would converge on a coarser grid pays for one or two grids finer than it needs."""

def start_dx(plan, cplan) -> float:
    """The first grid's dx in X units: the plan's (a length), or the refinement's first grid whose dx is at most
    the law's process zone over :data:`START_ZONE_PIXELS` (:func:`tengsim.run.grids.start_dx`)."""
    from tengsim.run.grids import start_dx as first_dx

    if plan.dx is not None:
        return plan.dx / cplan.scaling.lateral
    return first_dx(cplan.shape, cplan.law, cplan.coupling, cplan.boundary, START_ZONE_PIXELS)


def height_eps(cplan, dx) -> float:
    """The structure's height in ε (the range of its gap U0 on the grid)."""
    U0 = cplan.shape.gap(cplan.shape.grid(dx))
    return float(np.nanmax(U0) - np.nanmin(U0))


def _simulate(cplan, dx, d_max, **kw):
    """``cplan`` on the grid of spacing ``dx``, walked from D_MIN to ``d_max``."""
    import dataclasses

    from tengsim.run.simulate import simulate_plan

    return simulate_plan(dataclasses.replace(cplan, dx=dx, grid=None, path=path_to(d_max)), **kw)


def find_d_max(plan, cplan, dx, progress=None, guard=None):
    """(d_max, the coarse result): the D range that reaches p_max on a grid twice as coarse as the first
    (:func:`tengsim.run.reach.find_d_max`; each extension said in one line); ``guard`` (called per path row,
    e.g. :func:`tengsim.design.estimate.deadline`) may stop it."""
    from tengsim.design.units import pressure_text

    def extending(top, d_max):
        _say(progress, f"path: {pressure_text(top)} reached at D = {d_max:.3g} ε, extending")

    return reach_d_max(cplan, dx, plan.pressures[-1], height_eps(cplan, dx), extending, guard)


MAP_FRACTIONS = (0.1, 0.5, 1.0)
"""Maps are kept at the asked pressures nearest these fractions of p_max."""


def map_pressures(plan) -> tuple:
    """The asked pressures (Pa) nearest :data:`MAP_FRACTIONS` of p_max (above 0), in that order: where the maps are
    kept (none without a positive asked pressure)."""
    asked = [p for p in plan.pressures if p > 0]
    return tuple(min(asked, key=lambda x: abs(x - f * plan.pressures[-1])) for f in MAP_FRACTIONS) if asked else ()


def map_depths(res, plan) -> dict:
    """{D (ε): asked pressure (Pa)}: for the asked pressures nearest :data:`MAP_FRACTIONS` of p_max (above 0),
    the approach D at which ``res`` (the finest grid) reaches each (:func:`tengsim.run.reach.map_depths`)."""
    return reach_depths(res, map_pressures(plan))


def grid_path(plan, d_max, cut: bool = True):
    """``path_for`` of the design's refinement (:func:`tengsim.run.reach.grid_path`): each finer grid walks a little
    past the D at which the grid before it reached p_max and keeps the maps at the asked pressures nearest
    :data:`MAP_FRACTIONS` of p_max (``plan.maps`` false: no maps); ``cut`` false: every grid walks to ``d_max``."""
    return reach_grid_path(plan.pressures[-1], d_max, map_pressures(plan) if plan.maps else (), cut)


def maps_asked(res, plan) -> dict:
    """{D (ε): asked pressure (Pa)} of the approach maps ``res`` kept: the asked pressures nearest
    :data:`MAP_FRACTIONS` of p_max, in order of D (the maps were predicted at them from the grid before)."""
    asked = [p for p in plan.pressures if p > 0]
    want = sorted({min(asked, key=lambda x: abs(x - f * plan.pressures[-1])) for f in MAP_FRACTIONS}) if asked else []
    Ds = sorted(float(m["D"]) for m in (res.maps or []) if str(m["branch"]) == "approach")
    return {round(D, 9): p for D, p in zip(Ds, want)} if len(Ds) == len(want) else {}

def _observer(plan):
    from tengsim.design.curves import area_name, branch_curves

    def observe(res) -> dict:
        c = branch_curves(res, plan)
        return {area_name("approach", p): float(a) for p, a in zip(plan.pressures, c["approach"]["area"])}

    return observe


def _watcher(plan):
    """The retraction's numbers, recorded per grid with their convergence but not judged (the pull-off force
    is judged by the refinement itself): A/S on the retraction at the asked pressures and the hysteresis."""
    from tengsim.design.curves import area_name, branch_curves

    def watch(res) -> dict:
        c = branch_curves(res, plan)
        out = {area_name("retraction", p): float(a) for p, a in zip(plan.pressures, c["retraction"]["area"])}
        out["hysteresis_W"] = float(res.hysteresis)
        return out

    return watch
