"""Automatic grid refinement (``resolve = "auto"``): a contact run repeated on finer grids until it is converged.

:func:`resolve` runs a :class:`tengsim.run.plan.ContactPlan`'s path on grids dx0, dx0/√2, dx0/2, ...
(:data:`FACTOR` = √2 in dx, twice the pixels per level) and stops when

(a) no equilibrium of the finest grid is ``under_resolved`` (:mod:`tengsim.status`; a run whose rows are
    ``out_of_law_range`` or ``not_converged`` is not refined further for that: a finer grid does not cure
    them, and the result keeps that status),
(b) each observable changed by at most ``resolve_tol`` between the last two grids, and
(c) the finest grid's Richardson error estimate of each observable is within ``resolve_tol``,

all relative to the observable, with an absolute floor for values near 0 (:data:`tengsim.run.judge.FLOORS`:
1 ε for the D observables, 0.01 for F and for an area fraction).  If the next grid would have more than
``max_pixels`` pixels (default: what the machine's free memory holds, :func:`default_max_pixels`) it stops
with status ``under_resolved`` and one line naming the dx reached and the dx still needed (extrapolated from
the observed order).

Observables (:func:`tengsim.run.judge.contact_observables`): the pull-off force
(``ContactResult.pull_off_force``), the D of the first jump-in and jump-out (``ContactResult.jumps``) and,
given the shape's full-contact length, the transition D (``ContactResult.transition_D``); a caller adds its
own (a study: A/S and V_OC at its named pressures) with ``observe``.  An observable NaN on both of the last
grids is not judged; NaN on one only is a change (a jump that appears on the finer grid).

Richardson (:func:`tengsim.run.judge.richardson`), with h the grid spacings, coarse to fine, and f the
values: from the last three grids the observed order p solves (f1 − f2)/(f2 − f3) = (h1^p − h2^p)/(h2^p − h3^p)
(the spacings are not exactly in ratio √2: the pixel counts are FFT-friendly), clipped to
[:data:`tengsim.run.judge.P_MIN`, :data:`tengsim.run.judge.P_MAX`]; with two grids, or differences of
opposite sign (no monotone convergence), p = 1 (conservative).  The error of the finest value is
e = (f3 − f2)/((h2/h3)^p − 1) and the extrapolated value f3 + e.

Edges kept in place: a shape with kinks (``Shape.edge_offsets``: the base edge of a pyramid, cone, hemisphere or
punch, the wall of a cube or line) has the grid error of what is measured at them (the contact edge in full
contact, so A/S) set by where each edge falls in its pixel, and refinement by √2 moves that place from grid to
grid: the values then oscillate about their limit (docs/validation.md, "Automatic refinement"), Richardson
sees differences of opposite sign and cannot certify them.  So each
finer grid is the first FFT-friendly odd one from the plain next grid up to :data:`PHASE_SPAN` × its pixels whose
edges fall within :data:`PHASE_TOL` of a pixel of their place on the first grid (the plain next grid if none
does; ``params['resolve_edge_phases']`` records the places): grids similar with respect to the geometry, as a
Richardson sequence asks.

Why √2: the change between the last two grids is e·(r^p − 1) for a ratio r; with r = √2 and second order
it equals the finest grid's error, so criteria (b) and (c) ask the same; with r = 2 (b) would demand an
error of tol/3 and a grid up to 4× larger than needed.  A level costs about twice the one before, so the
whole sequence about twice the finest grid.

Nested start: not used; each grid walks the whole path from the zero state (why: docs/validation.md,
"Automatic refinement").
"""
from __future__ import annotations

import dataclasses
import math
import time

import numpy as np

from tengsim.errors import TengsimError
from tengsim.run.checkpoint import Checkpoint
from tengsim.run.grids import FACTOR, default_dx, edge_phases, next_grid
from tengsim.run.memory import default_max_pixels
from tengsim.run.judge import NEED_FLOOR, GridRecord, _dx_needed, _judge, _levels_table, _why, contact_observables


@dataclasses.dataclass(frozen=True)
class Refining:
    """How a refinement runs beyond its plan, given to the engine under :func:`resolve` and
    :func:`tengsim.run.refine.refine` (:func:`_refine_grids`): ``settings`` a :class:`tengsim.run.plan.ResolveSettings`
    used instead of ``plan.resolve`` (one plan serves every refinement pass of a caller: a ContactPlan is built per
    grid only); ``observe(result) -> dict`` more observables to converge; ``full_length`` the shape's full-contact
    Λc (for transition_D); ``watch(result) -> dict`` observables recorded per grid, with their change and Richardson
    error, but not judged (they do not decide when to stop: numbers a caller reports how converged they are, e.g.
    a design's hysteresis); ``path_for(result) -> path`` the path of the next grid from the grid before it (None on
    the first grid; e.g. the D at which its maps are kept, predicted from the coarser curve; default
    ``plan.path``); ``checkpoint(levels, phases, result)`` called after each finished grid (to keep it: a killed
    refinement keeps every grid it finished, :class:`Checkpoint`); ``start = (levels, phases, result)`` continues a
    refinement from such a record instead of computing those grids again."""

    settings: object = None
    observe: object = None
    full_length: float | None = None
    watch: object = None
    path_for: object = None
    checkpoint: object = None
    start: tuple | None = None


def resolve(plan, progress=None, sink=None):
    """The run of ``plan`` (a :class:`tengsim.run.plan.ContactPlan`, or a [contact] table planned here once) on
    finer and finer grids until converged (module doc): the run layer's second entry point (one grid is
    :func:`tengsim.run.simulate.simulate`, a refinement to a pressure :func:`tengsim.run.refine.refine`).

    The refinement's settings are ``plan.resolve`` (a :class:`tengsim.run.plan.ResolveSettings`, checked when
    built; None: its defaults): ``rel_tol`` the relative tolerance, ``max_pixels`` the largest grid nx·ny (None:
    :func:`default_max_pixels`), ``dx`` the first grid's spacing (None: :func:`default_dx`; ``plan.dx`` and
    ``plan.grid`` are the one-grid run's and not read here) and ``pressures`` (Pa), at which A/S
    (:func:`tengsim.run.area.area_at`) converges too; transition_D is judged with the shape's own full-contact
    length.  ``progress`` as for ``simulate``; ``sink``: a row stream whose file keeps each finished grid (its
    checkpoint, :meth:`Checkpoint.of`: a killed refinement started again takes them back), not given the rows
    (the grids would mix in one file: the result is written whole at the end).  Returns the finest grid's
    ContactResult with ``params['resolution']`` (the table: one row per grid), ``params['richardson']``,
    ``resolve``, ``resolve_tol``, ``max_pixels``, ``resolve_grids``, ``resolve_status``, ``config`` (the table,
    when planned from one) and, if stopped by ``max_pixels``, ``resolve_message``."""
    from tengsim.run.plan import as_plan

    plan = as_plan(plan)
    ck = Checkpoint.of(sink, plan.config)
    full = getattr(plan.shape, "full_contact_length", None)
    how = Refining(full_length=None if full is None else full(), checkpoint=None if ck is None else ck.save,
                   start=None if ck is None else ck.load())
    res = _refine_grids(plan, how, progress)
    params = {k: v for k, v in res.params.items() if k != Checkpoint.KEY}
    if plan.config:
        params["config"] = dict(plan.config)
    return dataclasses.replace(res, params=params)


def _refine_grids(plan, how: Refining = Refining(), progress=None):
    """The refinement engine under :func:`resolve` and :func:`tengsim.run.reach.resolve_to`: ``plan`` on finer and
    finer grids until converged (module doc), each grid :func:`tengsim.run.simulate.simulate` of the plan with that
    grid and its path, run as ``how`` says (:class:`Refining`); the result as for :func:`resolve`."""
    from tengsim.progress import say_to
    from tengsim.run.plan import ResolveSettings, chosen_solver
    from tengsim.run.simulate import _one_grid

    observe, watch, path_for, full_length = how.observe, how.watch, how.path_for, how.full_length
    checkpoint, start, settings = how.checkpoint, how.start, how.settings
    if settings is None:  # a caller's settings for this refinement (no plan built for them), else the plan's
        settings = plan.resolve if plan.resolve is not None else ResolveSettings()
    tol = settings.rel_tol
    shape = plan.shape
    if settings.pressures:
        from tengsim.run.area import area_at

        extra = area_at(settings.pressures, shape=plan.shape)  # the paper's A/S asks the shape object
        observe = extra if observe is None else (lambda res, a=observe, b=extra: {**a(res), **b(res)})
    dx = default_dx(shape, plan.law, plan.coupling, plan.boundary) if settings.dx is None else settings.dx
    max_pixels = settings.max_pixels
    if max_pixels is None:  # what the machine's memory holds (tengsim.run.memory)
        max_pixels = default_max_pixels(plan.boundary, plan.solver if isinstance(plan.solver, str) else "fast")
    levels, names, res, seen, watched, said_solver = [], [], None, set(), [], None
    stop, phases, done = None, (), False
    if start is not None:  # a refinement kept by its checkpoint: its grids are not computed again
        levels, phases, res = [GridRecord.of(lv) for lv in start[0]], tuple(start[1]), start[2]
        for lv in levels:
            names.extend(k for k in lv.obs if k not in names)
            watched.extend(k for k in lv.watched if k not in watched)
        seen = {(lv.nx, lv.ny) for lv in levels}
        done = _judge(levels, [n for n in names if n not in watched], tol)[0]
        dx = levels[-1].dx / FACTOR
    while not done:
        # keep the shape's edges where they fell in the first grid's pixels (module doc)
        grid = next_grid(shape, dx, phases if levels else None, seen, max_pixels)
        if not levels:
            phases = edge_phases(shape, grid)
        if grid.nx * grid.ny > max_pixels:
            if not levels:
                raise TengsimError(f"max_pixels = {max_pixels} is below the first grid's {grid.nx}×{grid.ny} "
                                   f"pixels (dx = {grid.dx:.4g}): give a larger max_pixels or a coarser dx")
            stop = grid
            break
        seen.add((grid.nx, grid.ny))
        t0 = time.perf_counter()
        this_path = plan.path if path_for is None else path_for(res)
        this = dataclasses.replace(plan, dx=grid.dx, grid=grid, path=this_path, resolve=None)
        solver, why = chosen_solver(this)  # 'auto' chooses on each grid: said where the choice changes
        if why and solver != said_solver:
            say_to(progress, why)
            said_solver = solver
        res = _one_grid(this, progress=progress)
        obs = contact_observables(res, full_length)
        if observe is not None:
            obs.update(observe(res))
        seen_watch = watch(res) if watch is not None else {}
        watched.extend(k for k in seen_watch if k not in watched)
        obs.update(seen_watch)
        names.extend(k for k in obs if k not in names)
        levels.append(GridRecord(grid.dx, grid.nx, grid.ny, time.perf_counter() - t0,
                                 int(res.params.get("n_conv_spent",
                                                    np.nansum(np.asarray(res.table["n_conv"], dtype=float)))),
                                 res.status, obs, tuple(seen_watch)))
        if checkpoint is not None:
            checkpoint(levels, phases, res)
        done, changes, rich = _judge(levels, [n for n in names if n not in watched], tol)
        if done:
            break
        dx = grid.dx / FACTOR
    _, changes, rich = _judge(levels, [n for n in names if n not in watched], tol)
    _, w_changes, w_rich = _judge(levels, watched, tol)
    p = dict(res.params)  # the result's parameters, then the refinement's
    p.update(resolve="auto", resolve_tol=tol, max_pixels=int(max_pixels),
             resolve_grids=[lv.dx for lv in levels], resolution=_levels_table(levels, names),
             richardson={n: {k: r[k] for k in ("order", "observed", "extrapolated", "error")}
                         | {"rel_error": r.get("rel_error", math.nan), "change": changes.get(n, math.nan)}
                         for n, r in rich.items()},
             watched={n: {k: r[k] for k in ("order", "observed", "extrapolated", "error")}
                      | {"rel_error": r.get("rel_error", math.nan), "change": w_changes.get(n, math.nan)}
                      for n, r in w_rich.items()},
             resolve_seconds=sum(lv.seconds for lv in levels), resolve_edge_phases=list(phases))
    if stop is not None:
        msg = _stop_message(levels, rich, changes, tol, max_pixels, stop, p.get("lateral_m"))
        p["resolve_status"] = "under_resolved"
        p["resolve_message"] = msg
        p["warning"] = "; ".join(x for x in (p.get("warning", ""), msg) if x)
    else:
        p["resolve_status"] = "ok"
    res = dataclasses.replace(res, params=p)
    return dataclasses.replace(res, params={**p, "status": res.status})


def _stop_message(levels, rich, changes, tol, max_pixels, stop, lateral) -> str:
    """The line of a refinement stopped by max_pixels: where it got, what moved most, the dx still needed
    (lengths in the run's units, nm or µm, when ``lateral`` (m per X unit) is given, else X units)."""
    need = _dx_needed(levels, rich, changes, tol)
    floor = levels[-1].dx / NEED_FLOOR

    def length(d, digits=3):
        if lateral:
            from tengsim.units import format_si

            return format_si(d * lateral, "m", digits)
        return f"{d:.{digits}g}"

    need_text = (f"dx ≈ {length(need)} needed" if need >= floor else
                 f"dx below {length(floor)} needed (the grids so far converge too irregularly to extrapolate "
                 "further)")
    return (f"under-resolved: refinement stopped by max_pixels = {max_pixels} at dx = {length(levels[-1].dx, 4)} "
            f"({levels[-1].nx}×{levels[-1].ny}; next {stop.nx}×{stop.ny}); {_why(changes)}, "
            f"{need_text} for resolve_tol = {tol:g}")
