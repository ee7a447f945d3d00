"""A design's walk: the first grid, the path's D range and each grid's path, the maps kept on the way.

The first dx is the user's (a length) or the run layer's (:func:`tengsim.run.refine.first_dx`): the first grid of the refinement's sequence
(:mod:`tengsim.run.grids`) whose dx is at most the law's process zone over :data:`tengsim.run.refine.START_ZONE_PIXELS`.
The path to p_max is the run layer's (:mod:`tengsim.run.reach`): an adaptive D walk from D = -1 ε to a d_max found on
a grid twice as coarse as the default first grid (:func:`tengsim.run.refine.find_range`), each finer grid's walk ending a little past
the D at which the grid before it reached p_max (:func:`grid_path`).  The design chooses where the pressure and gap
maps are kept: at the asked pressures nearest 10 %, 50 % and 100 % of p_max (:func:`map_pressures`).
"""
from __future__ import annotations

from tengsim.run.reach import grid_path as reach_grid_path, map_depths as reach_depths, path_to


def _simulate(cplan, dx, d_max, **kw):
    """``cplan`` on the grid of spacing ``dx``, walked from D_MIN to ``d_max``."""
    import dataclasses

    from tengsim.run.simulate import simulate

    return simulate(dataclasses.replace(cplan, dx=dx, grid=None, path=path_to(d_max), resolve=None), **kw)


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

def observers(plan):
    """(observe, watch): the refinement's observers of a design.  ``observe`` (judged): A/S on the approach at the
    asked pressures; ``watch`` (recorded per grid with its convergence, not judged; the pull-off force is judged by
    the refinement itself): A/S on the retraction at the asked pressures and the hysteresis energy.  A/S by the
    plan's definition on the load-controlled branches (:func:`tengsim.run.area.areas_at`)."""
    from tengsim.design.curves import _params, _shape, area_definition, area_name
    from tengsim.run.area import areas_at

    names = {b: [area_name(b, p) for p in plan.pressures] for b in ("approach", "retraction")}

    def areas(res):
        return areas_at(res, plan.pressures, area_definition(plan), _params(res, plan), _shape(plan))

    def observe(res) -> dict:
        return {n: float(a) for n, a in zip(names["approach"], areas(res)["approach"])}

    def watch(res) -> dict:
        if not plan.retraction:  # the approach only: nothing of the retraction to record
            return {}
        out = {n: float(a) for n, a in zip(names["retraction"], areas(res)["retraction"])}
        out["hysteresis_W"] = float(res.hysteresis)
        return out

    return observe, watch


def peak_separation(plan):
    """The law's peak-tension separation g_c (ε) of a design plan, the charged area's edge on its kept gap maps;
    None if it cannot be had."""
    from tengsim.analysis import law_edge

    law = getattr(getattr(plan, "contact_plan", None), "law", None)
    return None if law is None else law_edge(law)[0]
