"""Automatic grid refinement (``resolve = "auto"``): a contact run repeated on finer grids until it is converged.

:func:`resolve_contact` runs the same path on grids dx0, dx0/√2, dx0/2, ... (:data:`FACTOR` = √2 in dx, twice
the pixels per level) and stops when

(a) no equilibrium of the finest grid is ``under_resolved`` (:mod:`tengsim.status`; a run whose rows are
    ``out_of_law_range`` or ``not_converged`` is not refined further for that: a finer grid does not cure
    them, and the result keeps that status),
(b) each observable changed by at most ``resolve_tol`` between the last two grids, and
(c) the finest grid's Richardson error estimate of each observable is within ``resolve_tol``,

all relative to the observable, with an absolute floor for values near 0 (:data:`FLOORS`: 1 ε for the D
observables, 0.01 for F and for an area fraction).  If the next grid would have more than ``max_pixels``
pixels (default: what the machine's free memory holds, :func:`default_max_pixels`) it stops with status
``under_resolved`` and one line naming the dx reached and the dx still needed (extrapolated from the
observed order).

Observables (:func:`contact_observables`): the pull-off force (``ContactResult.pull_off_force``), the D of
the first jump-in and jump-out (``ContactResult.jumps``) and, given the shape's full-contact length, the
transition D (``ContactResult.transition_D``); a caller adds its own (a study: A/S and V_OC at its named
pressures) with ``observe``.  An observable NaN on both of the last grids is not judged; NaN on one only is
a change (a jump that appears on the finer grid).

Richardson (:func:`richardson`), with h the grid spacings, coarse to fine, and f the values: from the last
three grids the observed order p solves (f1 − f2)/(f2 − f3) = (h1^p − h2^p)/(h2^p − h3^p) (the spacings are
not exactly in ratio √2: the pixel counts are FFT-friendly), clipped to [:data:`P_MIN`, :data:`P_MAX`]; with
two grids, or differences of opposite sign (no monotone convergence), p = 1 (conservative).  The error of
the finest value is e = (f3 − f2)/((h2/h3)^p − 1) and the extrapolated value f3 + e.

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

from tengsim import backend
from tengsim.errors import TengsimError
from tengsim.grid import Grid
from tengsim.run.checkpoint import Checkpoint

FACTOR = math.sqrt(2.0)
"""Refinement factor in dx between two grids (twice the pixels)."""
DEFAULT_TOL = 0.01
P_MIN, P_MAX = 0.5, 4.0
"""Range the observed order is clipped to."""
FLOORS = {"D": 1.0, "F": 0.01, "fraction": 0.01, "V": 0.01}
"""Absolute floor of the relative change of an observable by kind (D in ε, F of Eq. 10, A/S, V_OC in V):
|Δf| <= tol · max(|f|, floor)."""
MIN_SIDE = 9
"""Fewest pixels across the cell of a default starting grid."""
PHASE_TOL = 0.1
"""How far (in pixels) a shape's edge may sit from its place in the first grid's pixel on a finer grid."""
PHASE_SPAN = 1.3
"""Largest pixel count, relative to the plain next grid's, searched for a grid that keeps the edges' places."""


def _kind(name: str) -> str:
    if name.endswith("_D") or name.startswith("D_"):
        return "D"
    if name.startswith("area_fraction") or name.startswith("A_"):
        return "fraction"
    if name.startswith("V_OC"):
        return "V"
    return "F"


def floor_of(name: str) -> float:
    return FLOORS[_kind(name)]


def contact_observables(res, full_length: float | None = None, fraction: float = 0.95) -> dict:
    """{name: value} judged by the refinement: pull_off_F, jump_in_D, jump_out_D, and transition_D when the
    shape's full-contact length ``full_length`` is given (NaN where a run has none)."""
    out = {"pull_off_F": res.pull_off_force}
    jumps = res.jumps
    out["jump_in_D"] = next((j.D_after for j in jumps if j.kind == "jump-in"), math.nan)
    out["jump_out_D"] = next((j.D_after for j in jumps if j.kind == "jump-out"), math.nan)
    if full_length is not None and math.isfinite(full_length):
        out["transition_D"] = res.transition_D(full_length, fraction)
    return out


def _order(h, f) -> tuple[float, bool]:
    """(observed order clipped to [P_MIN, P_MAX], True) from three grids, or (1, False) where it cannot be had."""
    from scipy.optimize import brentq

    (h1, h2, h3), (f1, f2, f3) = h, f
    d12, d23 = f1 - f2, f2 - f3
    if d23 == 0 or d12 == 0 or (d12 > 0) != (d23 > 0):
        return 1.0, False

    def g(p):
        return (h1**p - h2**p) / (h2**p - h3**p) - d12 / d23

    lo, hi = g(P_MIN), g(P_MAX)
    if lo >= 0:
        return P_MIN, True
    if hi <= 0:
        return P_MAX, True
    return float(brentq(g, P_MIN, P_MAX, xtol=1e-10)), True


def richardson(h, f) -> dict:
    """Richardson extrapolation of the values ``f`` on grids of spacing ``h`` (coarse to fine): the last
    three (or two) grids give {'order', 'observed' (bool: the order was measured, else 1 was assumed),
    'extrapolated', 'error' (of the finest value, signed: extrapolated − finest)}; NaN with fewer than two
    finite values."""
    h = [float(x) for x in h]
    f = [float(x) for x in f]
    nan = {"order": math.nan, "observed": False, "extrapolated": math.nan, "error": math.nan}
    if len(h) < 2 or not all(math.isfinite(x) for x in f[-2:]):
        return nan
    if len(h) >= 3 and all(math.isfinite(x) for x in f[-3:]):
        p, observed = _order(h[-3:], f[-3:])
    else:
        p, observed = 1.0, False
    r = h[-2] / h[-1]
    err = (f[-1] - f[-2]) / (r**p - 1.0)
    return {"order": p, "observed": observed, "extrapolated": f[-1] + err, "error": err}


def relative(name: str, delta: float, value: float) -> float:
    """|delta| relative to max(|value|, floor of ``name``)."""
    return abs(delta) / max(abs(value), floor_of(name))


def default_max_pixels(boundary: str = "free", solver: str = "fast") -> int:
    """The largest n² whose run fits in the machine's free memory (:mod:`tengsim.resources`); 4096² if that
    cannot be read."""
    from tengsim.resources import available_bytes, estimate_bytes

    avail = available_bytes()
    if avail is None:
        return 4096**2
    lo, hi = 3, 3
    while estimate_bytes(hi, hi, boundary, solver) <= avail and hi < 2**17:
        lo, hi = hi, hi * 2
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if estimate_bytes(mid, mid, boundary, solver) <= avail:
            lo = mid
        else:
            hi = mid
    return max(9, lo * lo)


def default_dx(shape, law, coupling: float, boundary: str = "free") -> float:
    """Starting dx when none is given: the a-priori Dugdale zone ℓ_D (:func:`tengsim.status.process_zone_estimate`)
    over ``status.RESOLUTION`` (the zone spans the pixels the grid status asks for) and the dx at which the pixel
    snap number s ∝ dx (:func:`tengsim.status.pixel_snap_number`, measured on a grid of the cell) falls to
    ``status.SNAP_LIMIT``, whichever is
    smaller, and at most cell/MIN_SIDE.  Coarser grids are under-resolved by those criteria whatever their
    observables do, so they would only be spent."""
    from tengsim import status
    from tengsim.kernels import make_kernel

    cell = float(getattr(shape, "cell"))
    dx = cell / MIN_SIDE
    lD = status.process_zone_estimate(law, coupling)
    if math.isfinite(lD) and lD > 0:
        dx = min(dx, lD / status.RESOLUTION)  # the zone spans the pixels the status asks for
    g = shape.grid(dx)
    s = status.pixel_snap_number(law, make_kernel(boundary, g, coupling))
    if s > status.SNAP_LIMIT:
        dx = g.dx * status.SNAP_LIMIT / s
    return dx


def edge_phases(shape, grid) -> tuple:
    """Where each of the shape's edges (``Shape.edge_offsets``, from the centre pixel along X) falls in its
    pixel on ``grid``: the fractional part of offset/dx, in [0, 1)."""
    offsets = getattr(shape, "edge_offsets", lambda: ())()
    return tuple(float((e / grid.dx) % 1.0) for e in offsets)


def _aligned(shape, grid, phases, max_pixels: int):
    """``grid`` or, for a shape with edges, the first plain square grid of the same cell with FFT-friendly odd
    pixel count between grid.nx and PHASE_SPAN × grid.nx (and within ``max_pixels``) whose edges fall where the
    first grid's did (``phases``, to PHASE_TOL of a pixel); ``grid`` itself if none does."""
    if not phases or type(grid) is not Grid or grid.nx != grid.ny:
        return grid
    L = grid.nx * grid.dx
    n, top = grid.nx, min(int(PHASE_SPAN * grid.nx), int(math.isqrt(int(max_pixels))))
    while n <= top:
        g = Grid(n, n, L / n, L / n)
        if all(min(abs(a - b), 1.0 - abs(a - b)) <= PHASE_TOL for a, b in zip(edge_phases(shape, g), phases)):
            return g
        n = backend.fast_odd_len(n + 2)
    return grid


def _levels_table(levels: list, names: list) -> dict:
    cols = {k: [lv[k] for lv in levels] for k in ("dx", "nx", "ny", "seconds", "convolutions", "status")}
    for n in names:
        cols[n] = [lv["obs"].get(n, math.nan) for lv in levels]
    return cols


def _judge(levels: list, names: list, tol: float) -> tuple[bool, dict, dict]:
    """(converged, {name: relative change of the last two grids}, {name: richardson dict with 'rel_error'})."""
    h = [lv["dx"] for lv in levels]
    changes, rich = {}, {}
    ok = len(levels) >= 2 and levels[-1]["status"] != "under_resolved"  # other problems: refining cannot fix
    for n in names:
        f = [lv["obs"].get(n, math.nan) for lv in levels]
        if len(f) >= 2:
            a, b = f[-2], f[-1]
            if math.isnan(a) and math.isnan(b):
                continue
            if math.isnan(a) != math.isnan(b):
                changes[n] = math.inf
                ok = False
                continue
            changes[n] = relative(n, b - a, b)
            ok = ok and changes[n] <= tol
        r = richardson(h, f)
        if math.isfinite(r["error"]):
            r["rel_error"] = relative(n, r["error"], r["extrapolated"])
            ok = ok and r["rel_error"] <= tol
        rich[n] = r
    return ok, changes, rich


#: an extrapolated dx finer than the last grid's / NEED_FLOOR (64× its pixels) is not given as a number: it comes
#: from an order clipped at 0.5 or a jump on one grid only, and says only "much finer"
NEED_FLOOR = 8.0


def _dx_needed(levels: list, rich: dict, changes: dict, tol: float) -> float:
    """dx at which every observable's error estimate and change between grids would be tol, both scaling as
    h^p (p the observed order, else 1): h·(tol/e)^(1/p) with e the larger of the two, the smallest dx of all."""
    h = levels[-1]["dx"]
    need = h
    for n, r in rich.items():
        e = max((x for x in (r.get("rel_error", math.nan), changes.get(n, math.nan)) if math.isfinite(x)),
                default=math.nan)
        p = r["order"] if math.isfinite(r["order"]) else 1.0
        if math.isfinite(e) and e > tol:
            need = min(need, h * (tol / e) ** (1.0 / p))
    return need


def resolve_contact(shape, tabor: float, path, dx: float | None = None, law=None, boundary: str = "free",
                    resolve_tol: float = DEFAULT_TOL, max_pixels: int | None = None, observe=None,
                    full_length: float | None = None, progress=None, checkpoint=None, start=None,
                    watch=None, path_for=None, **simulate_kw):
    """Run :func:`tengsim.run.simulate.simulate` on finer and finer grids until converged (module doc).

    ``dx`` the first grid's spacing (None: :func:`default_dx`), ``resolve_tol`` the relative tolerance,
    ``max_pixels`` the largest grid nx·ny (None: :func:`default_max_pixels`), ``observe(result) -> dict``
    extra observables, ``full_length`` the shape's full-contact Λc (for transition_D); the other keywords go
    to ``simulate``.  Returns the finest grid's ContactResult with ``params['resolution']`` (the table: one
    row per grid), ``params['richardson']``, ``resolve``, ``resolve_tol``, ``max_pixels``, ``resolve_grids``,
    ``resolve_status`` and, if stopped by ``max_pixels``, ``resolve_message``.

    ``checkpoint(levels, phases, result)``, if given, is called after each finished grid (to keep it: a
    killed refinement keeps every grid it finished, :class:`Checkpoint`); ``start = (levels, phases,
    result)`` continues a refinement from such a record instead of computing those grids again.

    ``watch(result) -> dict``: observables recorded per grid, with their change and Richardson error, but not
    judged (they do not decide when to stop: numbers a caller reports how converged they are, e.g. a design's
    hysteresis).  ``path_for(result) -> path``: the path of the next grid from the grid before it (None on the
    first grid; e.g. the D at which its maps are kept, predicted from the coarser curve); default ``path``."""
    from tengsim.run.simulate import simulate
    from tengsim.errors import positive
    from tengsim.laws import LJ93, make_law
    from tengsim.run.plan import check_max_pixels, check_tol, coupling

    tol = check_tol(resolve_tol)
    law = make_law(law) if isinstance(law, str) else (law or LJ93())
    solver = simulate_kw.get("solver", "fast")
    if max_pixels is None:
        max_pixels = default_max_pixels(boundary, solver if isinstance(solver, str) else "fast")
    max_pixels = check_max_pixels(max_pixels)
    dx = default_dx(shape, law, coupling(tabor), boundary) if dx is None else positive("dx", dx)
    levels, names, res, seen, watched = [], [], None, set(), []
    stop, phases, done = None, (), False
    if start is not None:  # a refinement kept by its checkpoint: its grids are not computed again
        levels, phases, res = [dict(lv) for lv in start[0]], tuple(start[1]), start[2]
        for lv in levels:
            names.extend(k for k in lv["obs"] if k not in names)
            watched.extend(k for k in lv.get("watched", ()) if k not in watched)
        seen = {(lv["nx"], lv["ny"]) for lv in levels}
        done = _judge(levels, [n for n in names if n not in watched], tol)[0]
        dx = levels[-1]["dx"] / FACTOR
    while not done:
        grid = shape.grid(dx)
        if levels:  # keep the shape's edges where they fell in the first grid's pixels (module doc)
            grid = _aligned(shape, grid, phases, max_pixels)
        else:
            phases = edge_phases(shape, grid)
        if (grid.nx, grid.ny) in seen:  # the FFT-friendly pixel count did not change: one more step
            dx /= FACTOR
            continue
        if grid.nx * grid.ny > max_pixels:
            if not levels:
                raise TengsimError(f"max_pixels = {max_pixels} is below the first grid's {grid.nx}×{grid.ny} "
                                   f"pixels (dx = {grid.dx:.4g}): give a larger max_pixels or a coarser dx")
            stop = grid
            break
        seen.add((grid.nx, grid.ny))
        t0 = time.perf_counter()
        this_path = path if path_for is None else path_for(res)
        res = simulate(shape, tabor, grid.dx, this_path, boundary=boundary, law=law, grid=grid, progress=progress,
                       **simulate_kw)
        obs = contact_observables(res, full_length)
        if observe is not None:
            obs.update(observe(res))
        seen_watch = watch(res) if watch is not None else {}
        watched.extend(k for k in seen_watch if k not in watched)
        obs.update(seen_watch)
        names.extend(k for k in obs if k not in names)
        levels.append({"dx": grid.dx, "nx": grid.nx, "ny": grid.ny, "seconds": time.perf_counter() - t0,
                       "convolutions": int(res.params.get("n_conv_spent",
                                                          np.nansum(np.asarray(res.table["n_conv"], dtype=float)))),
                       "status": res.status, "obs": obs, "watched": list(seen_watch)})
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
             resolve_grids=[lv["dx"] for lv in levels], resolution=_levels_table(levels, names),
             richardson={n: {k: r[k] for k in ("order", "observed", "extrapolated", "error")}
                         | {"rel_error": r.get("rel_error", math.nan), "change": changes.get(n, math.nan)}
                         for n, r in rich.items()},
             watched={n: {k: r[k] for k in ("order", "observed", "extrapolated", "error")}
                      | {"rel_error": r.get("rel_error", math.nan), "change": w_changes.get(n, math.nan)}
                      for n, r in w_rich.items()},
             resolve_seconds=sum(lv["seconds"] for lv in levels), resolve_edge_phases=list(phases))
    if stop is not None:
        need = _dx_needed(levels, rich, changes, tol)
        why = _why(changes)
        floor = levels[-1]["dx"] / NEED_FLOOR
        lateral = p.get("lateral_m")  # a physical run: lengths in its units (nm, µm), else X units

        def length(d, digits=3):
            if lateral:
                from tengsim.units import format_si

                return format_si(d * lateral, "m", digits)
            return f"{d:.{digits}g}"

        need_text = (f"dx ≈ {length(need)} needed" if need >= floor else
                     f"dx below {length(floor)} needed (the grids so far converge too irregularly to extrapolate "
                     "further)")
        msg = (f"under-resolved: refinement stopped by max_pixels = {max_pixels} at dx = {length(levels[-1]['dx'], 4)} "
               f"({levels[-1]['nx']}×{levels[-1]['ny']}; next {stop.nx}×{stop.ny}); {why}, "
               f"{need_text} for resolve_tol = {tol:g}")
        p["resolve_status"] = "under_resolved"
        p["resolve_message"] = msg
        p["warning"] = "; ".join(x for x in (p.get("warning", ""), msg) if x)
    else:
        p["resolve_status"] = "ok"
    res = dataclasses.replace(res, params=p)
    return dataclasses.replace(res, params={**p, "status": res.status})


def _why(changes: dict) -> str:
    """What keeps the refinement from converging, in words: the observable that moved most."""
    worst = max(changes, key=lambda n: changes[n], default=None)
    if worst is None:
        return "one grid only"
    if math.isinf(changes[worst]):  # NaN on one of the two grids: a jump or transition seen on one only
        return f"{worst} exists on one of the last two grids only (NaN on the other)"
    return f"{worst} changed {changes[worst]:.2%} between the last two grids"


def run_contact(plan, progress=None, sink=None, observe=None):
    """Run a :class:`tengsim.run.plan.ContactPlan` (or a [contact] table, planned here once): one grid
    (:func:`tengsim.run.simulate.run_contact`), or refined automatically when its ``resolve`` settings say so
    (:func:`resolve_contact`, transition_D judged with the shape's own full-contact length).

    The refinement's grids each stream their rows to ``sink`` would mix grids in one file, so a sink is not
    given rows of a refined run (its result is written whole at the end).  ``observe(result) -> dict``: more
    observables to converge, beside A/S at the plan's ``resolve.pressures`` (Pa; :func:`tengsim.run.area.area_at`)."""
    from tengsim.run import simulate as contact
    from tengsim.run.plan import as_plan

    plan = as_plan(plan)
    if plan.resolve is None:  # one grid
        kw = {k: v for k, v in (("progress", progress), ("sink", sink)) if v is not None}
        return contact.run_contact(plan, **kw)
    settings = plan.resolve
    if settings.pressures:
        from tengsim.run.area import area_at

        extra = area_at(settings.pressures, plan.config)
        observe = extra if observe is None else (lambda res, a=observe, b=extra: {**a(res), **b(res)})
    ck = Checkpoint.of(sink, plan.config)
    full = getattr(plan.shape, "full_contact_length", None)
    res = resolve_contact(plan.shape, plan.tabor, plan.path, dx=settings.dx, law=plan.law,
                          boundary=plan.boundary, resolve_tol=settings.tol,
                          max_pixels=settings.max_pixels, progress=progress,
                          full_length=None if full is None else full(),
                          observe=observe, symmetry=plan.symmetry,
                          solver=plan.solver, tol=plan.tol, extra_params=plan.extra, observers=plan.observers,
                          scaling=plan.scaling, kernel_params=plan.kernel_params,
                          checkpoint=None if ck is None else ck.save, start=None if ck is None else ck.load())
    params = {k: v for k, v in res.params.items() if k != Checkpoint.KEY}
    return dataclasses.replace(res, params={**params, "config": dict(plan.config)})
