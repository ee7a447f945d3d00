"""A path that reaches a pressure: the D walk of a refinement whose approach must reach p_max.

The path is an adaptive D walk (:class:`tengsim.continuation.path.PathSpec`) from :data:`D_MIN` to a d_max found
on a coarse grid (:func:`find_d_max`): from 1.2 × the structure's height (+2 ε), extended in chunks (the last
rows' dP/dD, extrapolated to 1.3 × the pressure still missing: :func:`extended`, the one rule for a D range that
fell short) until the approach reaches p_max, at most :data:`EXTEND_TRIES` times; else an error naming the highest
pressure reached, in kPa.  :func:`reach` says whether,
and where, a result's approach reaches a pressure.
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np

from tengsim.errors import TengsimError

D_MIN = -1.0
D_STEP = 0.4
"""Largest D step (ε) of the adaptive walk (refine_levels 4: smallest 0.025 ε)."""
EXTEND_TRIES = 6


def path_to(d_max: float, maps_at=(), retract: bool = True, stop_force: float | None = None):
    """The adaptive D walk from :data:`D_MIN` to ``d_max`` (maps kept at ``maps_at``) and back (``retract`` false:
    the approach only); ``stop_force`` (ε units of F): the approach ends just past it (``PathSpec.stop_force``)."""
    from tengsim.continuation import PathSpec

    return PathSpec(D_MIN, d_max, D_STEP, adaptive=True, maps_at=tuple(maps_at), retract=retract,
                    stop_force=stop_force)


def height_eps(cplan, dx) -> float:
    """The structure's height in ε (the range of its gap U0 on the grid of spacing ``dx``)."""
    U0 = cplan.shape.gap(cplan.shape.grid(dx))
    return float(np.nanmax(U0) - np.nanmin(U0))


def reach(res, p_max):
    """(reached, D where the approach first reaches p_max (NaN if not), highest approach pressure, slope dP/dD)."""
    a = res.branch("approach")
    D, P = np.asarray(a["D"], float), np.asarray(a["pressure_Pa"], float)
    hit = np.flatnonzero(P >= p_max)
    n = max(2, len(D) // 10)
    slope = (P[-1] - P[-n]) / (D[-1] - D[-n]) if len(D) > n and D[-1] > D[-n] else math.nan
    return bool(len(hit)), (float(D[hit[0]]) if len(hit) else math.nan), float(np.max(P)), slope


def extended(d_max: float, top: float | None = None, p_max: float | None = None, slope: float = math.nan) -> float:
    """The D range (ε) to walk next after a walk to ``d_max`` fell short of ``p_max``: with the walk's highest
    pressure ``top`` (Pa) and its last rows' slope dP/dD, d_max plus the D extrapolated to 1.3 × the pressure
    still missing (half d_max without a rising slope), at least 2 ε and at most 2 × d_max (the coarse pre-run,
    :func:`find_d_max`); without them (a refinement's finest grid fell short, :func:`resolve_to`, where a finer
    grid is softer), 1.2 × d_max + 2 ε."""
    if top is None:
        return 1.2 * d_max + 2.0
    grow = 1.3 * (p_max - top) / slope if math.isfinite(slope) and slope > 0 else 0.5 * d_max
    return d_max + min(max(grow, 2.0), 2.0 * d_max)


def find_d_max(cplan, dx, p_max: float, height: float, extending=None, guard=None):
    """(d_max, the coarse result): the D range whose approach reaches ``p_max`` (Pa) on a grid twice as coarse as
    the first (spacing ``dx``) or the default one, whichever is coarser (module doc); ``height`` the structure's
    height (ε).  ``extending(top, d_max)`` is told each extension (the highest pressure reached, Pa, and the D
    range walked); ``guard`` (called per path row) may stop it."""
    from tengsim.run.grids import default_dx
    from tengsim.run.simulate import _one_grid

    # the default grid's (the cell over 9 pixels at most): cheap, whatever the first grid (a given dx too)
    coarse = 2 * max(dx, default_dx(cplan.shape, cplan.law, cplan.coupling, cplan.boundary))
    d_max = 1.2 * height + 2.0
    kw = {} if guard is None else {"progress": guard}
    for _ in range(EXTEND_TRIES):
        res = _one_grid(dataclasses.replace(cplan, dx=coarse, grid=None, path=path_to(d_max), resolve=None), **kw)
        ok, D_hit, top, slope = reach(res, p_max)
        if ok:
            return 1.1 * D_hit + 1.0, res
        if extending is not None:
            extending(top, d_max)
        d_max = extended(d_max, top, p_max, slope)
    raise TengsimError(f"the approach reached only {top / 1e3:.4g} kPa of p_max = {p_max / 1e3:.4g} kPa after "
                       f"{EXTEND_TRIES} extensions of the path (to D = {d_max:.4g} ε = "
                       f"{d_max * cplan.scaling.eps * 1e6:.3g} µm): give a lower p_max")


D_MARGIN = 0.03
"""A finer grid's path ends at the D where the grid before it reached p_max, plus this fraction of that D
(at least 2 d_step): a finer grid is softer, and between the refinement's grids that D moved by less than 0.1 ε."""


def map_depths(res, map_pressures) -> dict:
    """{D (ε): pressure (Pa)}: for each of ``map_pressures`` (Pa, in order), the approach D at which ``res``
    reaches it on its load-controlled states (:func:`tengsim.run.area.load_control`), linear between the two
    states around it; after a snap (states dropped between them), the state the load reaches."""
    from tengsim.run.area import load_control

    F, D = load_control(res, "D")
    P = res.scaling.pressure(1.0) * F
    out = {}
    for p in map_pressures:
        if len(P) < 2:
            break
        i = int(np.searchsorted(P, p))
        if 0 < i < len(P) and D[i] - D[i - 1] <= D_STEP:
            w = (p - P[i - 1]) / (P[i] - P[i - 1])
            out[round(float(D[i - 1] + w * (D[i] - D[i - 1])), 9)] = p
        elif 0 < i < len(P):  # states dropped between them (a snap): the state the load reaches
            out[round(float(D[i]), 9)] = p
        elif i == 0:
            out[round(float(D[0]), 9)] = p
    return out


def grid_path(p_max: float, d_max: float, map_pressures=(), cut: bool = True, retract: bool = True,
              stop_force: float | None = None):
    """``path_for`` of the refinement (:func:`tengsim.run.resolve.resolve`): the first grid walks to
    ``d_max`` (:func:`find_d_max`); each finer grid to the D at which the grid before it reached ``p_max``, plus
    :data:`D_MARGIN` (on the path's lattice, never beyond ``d_max``).  Each finer grid's path also keeps the
    pressure and gap maps at the D where the grid before it reached ``map_pressures`` (:func:`map_depths`), so the
    finest grid's maps are recorded during its own walk (an extra row at each such D, solved from the rows around
    it: the walk's other rows are unchanged).  ``cut`` false: every grid walks to ``d_max``; ``retract`` false: the
    approach only.  ``stop_force`` (the force of p_max, ε units): every grid's approach ends at the step after its
    first row past it, short of that D when it gets there first (the rows beyond p_max are never read)."""

    def on_lattice(D):
        return D_MIN + math.ceil((D - D_MIN) / D_STEP - 1e-9) * D_STEP

    def path_for(prev):
        depths, top = (), d_max
        if prev is not None and prev.scaling is not None:
            ok, D_hit, _, _ = reach(prev, p_max)
            if ok and cut:
                top = min(d_max, on_lattice(D_hit + max(D_MARGIN * abs(D_hit), 2 * D_STEP)))
            if map_pressures:
                last = D_MIN + math.floor((top - D_MIN) / D_STEP + 1e-9) * D_STEP
                depths = tuple(sorted(D for D in map_depths(prev, map_pressures) if D_MIN <= D <= last))
        return path_to(top, depths, retract, stop_force)

    return path_for


def resolve_to(plan, d_max: float, settings, progress=None, keep=None, key: str = "", done=None, say=None):
    """The refinement (:func:`tengsim.run.resolve.resolve`, with ``settings``, a
    :class:`tengsim.run.plan.ResolveSettings`) of ``plan`` (a :class:`tengsim.run.refine.RefinementPlan`: its
    ``cplan``, ``p_max``, ``maps_at``, ``observe``, ``watch`` and ``retraction``) on the path to ``d_max``
    (:func:`grid_path`), whose finest grid must reach ``p_max``: if it does not (a finer grid is softer), d_max
    grows to 1.2 d_max + 2 ε and the refinement runs again, once, every grid walking to d_max; else an error naming
    the pressure reached.  ``keep`` (a file, or None): each finished grid is kept there for the run ``key`` and
    path (:func:`tengsim.run.checkpoint.open_checkpoint`, ``say`` told what it finds), and taken back by a run of
    the same key and path.  ``done(levels)`` is called after each finished grid is kept; ``progress`` as for
    :func:`tengsim.run.resolve.resolve`; ``plan.retraction`` false: each grid walks the approach only."""
    from tengsim.run.checkpoint import open_checkpoint
    from tengsim.run.resolve import Refining, _refine_grids

    cplan, p_max = plan.cplan, plan.p_max

    res = None
    for attempt in range(2):
        ck, found = open_checkpoint(keep, key, d_max, say) if keep is not None else (None, None)

        def after(levels, phases, result, ck=ck):
            if ck is not None:
                ck.save(levels, phases, result)
            if done is not None:
                done(levels)

        stop = p_max / cplan.scaling.pressure(1.0) * (1.0 + 1e-9)  # p_max's force: each grid's approach ends past it
        path_for = grid_path(p_max, d_max, plan.maps_at, attempt == 0, plan.retraction, stop)

        def scaled_path_for(prev, path_for=path_for):  # a grid taken back from the file keeps its columns only
            if prev is not None and prev.scaling is None:
                prev = dataclasses.replace(prev, scaling=cplan.scaling)
            return path_for(prev)

        how = Refining(settings, plan.observe, watch=plan.watch, path_for=scaled_path_for, checkpoint=after,
                       start=found)
        res = _refine_grids(cplan, how, progress)
        if res.scaling is None:  # every grid taken back from the checkpoint file, which keeps the columns only
            res = dataclasses.replace(res, scaling=cplan.scaling)
        ok, D_hit, top, slope = reach(res, p_max)
        if ok:
            return res
        d_max = extended(d_max)
    raise TengsimError(f"the approach reached only {top / 1e3:.4g} kPa of p_max = {p_max / 1e3:.4g} "
                       f"kPa on the finest grid, walked to D = {d_max:.4g} ε "
                       f"({d_max * cplan.scaling.eps * 1e6:.3g} µm) on every grid: give a lower p_max")
