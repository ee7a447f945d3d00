"""A design's walk: the first grid, the path's D range and each grid's path, the maps kept on the way.

The first dx is the user's (a length) or :func:`start_dx`: the first grid of the refinement's sequence
(:mod:`tengsim.run.grids`) whose dx is at most the law's process zone over :data:`START_ZONE_PIXELS`.
The path is an adaptive D walk (:class:`tengsim.continuation.path.PathSpec`) from D = -1 ε to a d_max found on a grid
twice as coarse as the default first grid (:func:`find_d_max`): from 1.2 × the structure's height (+2 ε), extended in
chunks (the last rows' dP/dD, extrapolated to 1.3 × the pressure still missing) until the approach reaches p_max, at
most :data:`EXTEND_TRIES` times; else an error naming the highest pressure reached, in kPa.  A finer grid's walk ends
a little past the D at which the grid before it reached p_max (:func:`grid_path`), and keeps the pressure and gap maps
at the D where the grid before it reached the asked pressures nearest 10 %, 50 % and 100 % of p_max.
"""
from __future__ import annotations

import math

import numpy as np

from tengsim.errors import TengsimError

D_MIN = -1.0
D_STEP = 0.4
"""Largest D step (ε) of the adaptive walk (refine_levels 4: smallest 0.025 ε)."""
EXTEND_TRIES = 6


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

    from tengsim.continuation import PathSpec
    from tengsim.run.simulate import simulate_plan

    path = PathSpec(D_MIN, d_max, D_STEP, adaptive=True)
    return simulate_plan(dataclasses.replace(cplan, dx=dx, grid=None, path=path), **kw)


def _reach(res, p_max):
    """(reached, D where the approach first reaches p_max (NaN if not), highest approach pressure, slope dP/dD)."""
    a = res.branch("approach")
    D, P = np.asarray(a["D"], float), np.asarray(a["pressure_Pa"], float)
    hit = np.flatnonzero(P >= p_max)
    n = max(2, len(D) // 10)
    slope = (P[-1] - P[-n]) / (D[-1] - D[-n]) if len(D) > n and D[-1] > D[-n] else math.nan
    return bool(len(hit)), (float(D[hit[0]]) if len(hit) else math.nan), float(np.max(P)), slope


def find_d_max(plan, cplan, dx, progress=None, guard=None):
    """(d_max, the coarse result): the D range that reaches p_max on a grid twice as coarse as the first
    (module doc); ``guard`` (called per path row, e.g. :func:`tengsim.design.estimate.deadline`) may stop it."""
    from tengsim.design.units import pressure_text

    from tengsim.run.grids import default_dx

    p_max = plan.pressures[-1]

    # the default grid's (the cell over 9 pixels at most): cheap, whatever the first grid (a --dx too)
    coarse = 2 * max(dx, default_dx(cplan.shape, cplan.law, cplan.coupling, cplan.boundary))
    d_max = 1.2 * height_eps(cplan, dx) + 2.0
    for _ in range(EXTEND_TRIES):
        res = _simulate(cplan, coarse, d_max, **({} if guard is None else {"progress": guard}))
        ok, D_hit, top, slope = _reach(res, p_max)
        if ok:
            return 1.1 * D_hit + 1.0, res
        grow = 1.3 * (p_max - top) / slope if math.isfinite(slope) and slope > 0 else 0.5 * d_max
        _say(progress, f"path: {pressure_text(top)} reached at D = {d_max:.3g} ε, extending")
        d_max += min(max(grow, 2.0), 2.0 * d_max)
    raise TengsimError(f"the approach reached only {top / 1e3:.4g} kPa of p_max = {p_max / 1e3:.4g} kPa after "
                       f"{EXTEND_TRIES} extensions of the path (to D = {d_max:.4g} ε = "
                       f"{d_max * cplan.scaling.eps * 1e6:.3g} µm): give a lower p_max")


MAP_FRACTIONS = (0.1, 0.5, 1.0)
"""Maps are kept at the asked pressures nearest these fractions of p_max."""


def map_depths(res, plan) -> dict:
    """{D (ε): asked pressure (Pa)}: for the asked pressures nearest :data:`MAP_FRACTIONS` of p_max (above 0),
    the approach D at which ``res`` (the finest grid) reaches each on its load-controlled states, linear
    between the two states around it."""
    from tengsim.run.area import load_control

    F, D = load_control(res, "D")
    P = res.scaling.pressure(1.0) * F
    asked = [p for p in plan.pressures if p > 0]
    out = {}
    for f in MAP_FRACTIONS:
        if not asked or len(P) < 2:
            break
        p = min(asked, key=lambda x: abs(x - f * plan.pressures[-1]))
        i = int(np.searchsorted(P, p))
        if 0 < i < len(P) and D[i] - D[i - 1] <= D_STEP:
            w = (p - P[i - 1]) / (P[i] - P[i - 1])
            out[round(float(D[i - 1] + w * (D[i] - D[i - 1])), 9)] = p
        elif 0 < i < len(P):  # states dropped between them (a snap): the state the load reaches
            out[round(float(D[i]), 9)] = p
        elif i == 0:
            out[round(float(D[0]), 9)] = p
    return out


D_MARGIN = 0.03
"""A finer grid's path ends at the D where the grid before it reached p_max, plus this fraction of that D
(at least 2 d_step): a finer grid is softer, and between the issue's grids that D moved by less than 0.1 ε."""


def grid_path(plan, d_max, cut: bool = True):
    """``path_for`` of the refinement (:func:`tengsim.run.resolve.resolve_contact`): the first grid walks to
    ``d_max`` (found on the coarse grid, :func:`find_d_max`); each finer grid to the D at which the grid before
    it reached p_max, plus :data:`D_MARGIN` (on the path's lattice, never beyond ``d_max``): about 10 % of the
    rows were past p_max.  Each finer grid's path also keeps the pressure and gap maps at the map depths of the
    grid before it (:func:`map_depths` of its curve), so the finest grid's maps are recorded during its own walk
    (an extra row at each such D, solved from the rows around it: the walk's other rows are unchanged);
    ``plan.maps`` false: no maps.  ``cut`` false: every grid walks to ``d_max`` (a second pass, after a finer
    grid fell short of p_max at the D the grid before it reached p_max)."""
    from tengsim.continuation import PathSpec

    def on_lattice(D):
        return D_MIN + math.ceil((D - D_MIN) / D_STEP - 1e-9) * D_STEP

    def path_for(prev):
        depths, top = (), d_max
        if prev is not None and prev.scaling is not None:
            ok, D_hit, _, _ = _reach(prev, plan.pressures[-1])
            if ok and cut:
                top = min(d_max, on_lattice(D_hit + max(D_MARGIN * abs(D_hit), 2 * D_STEP)))
            if plan.maps:
                last = D_MIN + math.floor((top - D_MIN) / D_STEP + 1e-9) * D_STEP
                depths = tuple(sorted(D for D in map_depths(prev, plan) if D_MIN <= D <= last))
        return PathSpec(D_MIN, top, D_STEP, adaptive=True, maps_at=depths)

    return path_for


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
