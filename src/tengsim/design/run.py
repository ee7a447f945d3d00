"""Run a design: the grid chosen and said, the path extended to the pressures asked for, the grid refined to tol.

:func:`run_design` (a :class:`tengsim.design.plan.DesignPlan` → :class:`DesignResult`):

1. **Checks.**  :func:`preflight` checks every bound from the sizes alone (the solver, the first grid, the memory,
   the budget) before any array is allocated; :func:`choose_solver` puts a cohesive law with a wall on 'pk'.
2. **Path.**  The first grid (:func:`tengsim.design.walk.start_dx`), the refinement's grids
   (:class:`tengsim.run.grids.GridSequence`) and the path's D range, found on a coarse grid
   (:func:`tengsim.run.reach.find_d_max`).
3. **Estimate.**  The grids, the memory and the expected time (:func:`tengsim.design.estimate.estimate`), the worst
   case up to the budget's largest grid (:func:`tengsim.design.estimate.cap_line`); an expected time over the
   budget is refused before the refinement is solved or anything written.
4. **Refinement.**  :func:`tengsim.run.reach.resolve_to` on dx, dx/√2, ... (:mod:`tengsim.run.grids`) until the
   charged-area fraction A/S on the approach at every asked pressure, the pull-off force and the jump D values change
   by at most tol between the last two grids (and their Richardson error is within tol).  If the finest grid does
   not reach p_max (a finer grid is softer), d_max grows and the refinement runs again (once).  The retraction's
   numbers (A/S on the retraction, the hysteresis energy) are recorded per grid with their change and Richardson
   error but not judged (:func:`tengsim.design.walk._watcher`); the pull-off force is judged.  Each finished grid is
   kept (:func:`tengsim.run.checkpoint.open_checkpoint`, under :func:`tengsim.design.keep.identity`), so a killed
   run resumes.
5. **Maps.**  Each grid after the first keeps the pressure and gap maps at the D where the grid before it reached
   the asked pressures nearest 10 %, 50 % and 100 % of p_max (:func:`tengsim.design.walk.grid_path`): the finest
   grid's maps come from its own walk, at the coarser grid's prediction of those D (the figure titles say the
   pressure each map is at and the one asked).  ``maps = false``: none.
"""
from __future__ import annotations

from dataclasses import dataclass, field

from tengsim.design.estimate import (BudgetSpent, budget_pixels, cap_line, check_budget, deadline,  # noqa: F401
                                     estimate, run_cost)
from tengsim.design.plan import PK_LAWS, SOLVER_TOL_PER_TOL, solver_tol  # noqa: F401
from tengsim.design.keep import checkpoint, identity, kept_path  # noqa: F401
from tengsim.design.walk import (D_MIN, D_STEP, _observer, _reach, _say, _simulate, _watcher,  # noqa: F401
                                 find_d_max, grid_path, height_eps, map_pressures, maps_asked, path_to, start_dx)
from tengsim.errors import TengsimError
from tengsim.run.grids import refinement_grids  # noqa: F401


@dataclass(frozen=True)
class DesignResult:
    """One design's answer: ``dataset`` (the design.nc contract, :func:`tengsim.design.write.to_dataset`),
    ``summary`` (per-design numbers, SI), ``convergence`` {number: relative change between the last two grids},
    ``finest`` (the finest grid's :class:`tengsim.results.ContactResult`), its ``plan`` and ``maps`` (the run
    holding the pressure maps near 10 %, 50 % and 100 % of p_max, or None)."""

    plan: object
    dataset: object
    summary: dict
    convergence: dict
    finest: object = field(repr=False)
    notes: tuple = ()
    maps: object = field(default=None, repr=False)
    """The finest grid's approach again up to the map pressures, with the pressure and gap maps there (or None)."""

    @property
    def status(self) -> str:
        return str(self.summary["status"])

def preflight(plan, progress=None):
    """Every bound of a design checked from its sizes alone, before any array is allocated or anything is
    written: the first grid fits the cell (in the user's units), is within ``max_pixels`` and the memory, and
    its shortest path (D to 2 ε: no structure at all) fits the budget.  The full estimate, with the structure's
    height, follows in :func:`run_design`; this one needs no gap array (a --dx of 0.02 nm was killed for its
    memory before any check)."""
    from tengsim.design.units import length_text, time_text
    from tengsim.errors import GeometryError
    from tengsim.resources import check_memory
    from tengsim.run.plan import _metres
    from tengsim.solvers import make_solver

    cplan = choose_solver(plan, plan.contact_plan, progress)  # the plan the run will use
    solver = make_solver(cplan.solver, tol=cplan.tol)  # a solver this machine lacks (gpu): refused now
    if hasattr(solver, "solves") and not solver.solves(cplan.law):  # a law it cannot solve: refused now
        from tengsim.solvers.pk import PKSolver, wall_model

        if isinstance(solver, PKSolver):
            wall_model(cplan.law)  # raises the solver's own line, naming the solvers that can
        raise TengsimError(f"solver {cplan.solver!r} cannot solve law {type(cplan.law).__name__}")
    lateral = cplan.scaling.lateral
    try:
        dx = start_dx(plan, cplan)
        g = cplan.shape.grid(dx)
        first = f"the first grid {g.nx}×{g.ny} (dx {length_text(g.dx * lateral)})"
        if plan.max_pixels is not None and g.nx * g.ny > plan.max_pixels:
            raise TengsimError(f"{plan.name[:80]}: {first} has {g.nx * g.ny} pixels, over max_pixels = "
                               f"{plan.max_pixels}: give a larger --max-pixels or a coarser --dx")
        if (cplan.kernel_params or {}).get("thickness") is not None:
            from tengsim.kernels.film import check_film_pixels

            check_film_pixels(cplan.kernel_params["thickness"], max(g.dx, g.dy), lateral)
        check_memory(g.nx, g.ny, cplan.boundary, cplan.solver)
    except GeometryError as exc:  # a size that does not fit, said in the user's units
        raise exc.in_metres(lateral, _metres) from None
    secs = run_cost(cplan, 2.0).grid_seconds(cplan.shape, g)  # the shortest path, on the backend's cost model
    if secs > plan.budget_s:
        raise TengsimError(f"{plan.name[:80]}: {first} alone is estimated at {time_text(secs)}, over the budget "
                           f"of {time_text(plan.budget_s)}: give a coarser --dx, a coarser --tol (now "
                           f"{plan.tol:g}) or a larger --budget")
    return cplan


def choose_solver(plan, cplan, progress=None):
    """The contact plan a design runs: :func:`tengsim.design.plan.plan_design` put a cohesive law with a wall
    (``md``, ``exp``) on the constrained solver 'pk' (tengsim.solvers.pk) unless the design names its solver;
    said here in one line."""
    if not plan.solver_given and type(cplan.law).__name__ in PK_LAWS and cplan.solver == "pk":
        _say(progress, "solver: pk (Polonsky–Keer constrained CG with a cohesive zone: the law's hard-wall "
                       "limit; give solver = 'fast' or 'homotopy' for the penalty wall)")
    return cplan


def _grid_done(progress, cplan, grids):
    """The refinement's call after each finished (and kept) grid: a line with its measured time and the next
    grid's expected one (:func:`tengsim.design.estimate.next_grid_line`; ``grids`` the refinement's sequence,
    :class:`tengsim.run.grids.GridSequence`)."""
    from tengsim.design.estimate import next_grid_line

    def done(levels):
        _say(progress, next_grid_line(cplan.shape, grids[:len(levels) + 1], levels[-1]["seconds"],
                                      cplan.scaling.lateral))

    return done


def run_design(plan, progress=None, keep=None) -> DesignResult:
    """Run one design (module doc).  ``progress``: a :class:`tengsim.progress.Progress`-like callable (the
    path's progress) and/or an object with ``say(text)``, which gets the lines said before and during the run
    (the Tabor number, the solver, the grids, memory and expected time).  ``keep`` (a file path, or None): where each
    finished grid is kept (:func:`tengsim.design.keep.checkpoint`), so a killed run of the same design resumes from it."""
    from tengsim.run.plan import ResolveSettings
    from tengsim.design.curves import summarize
    from tengsim.design.write import to_dataset
    from tengsim.run.grids import GridSequence
    from tengsim.run.reach import resolve_to

    import time

    started = time.monotonic()
    # what lives on the design's own floor first: the kept grids' identity, the observers, the guards
    base = identity(plan)
    later = kept_path(keep, base)
    observe, watch = _observer(plan), _watcher(plan)
    coarse_guard, guard = deadline(None, plan, keep, started), deadline(progress, plan, keep, started)
    maps_at = map_pressures(plan) if plan.maps else ()

    def said(text):
        _say(progress, text)

    cplan = preflight(plan, progress)  # the plan plan_design built, with the design's solver and tolerance
    dx = start_dx(plan, cplan)
    _say(progress, f"{plan.name}: Tabor number {cplan.tabor:.3g} (from eps = {plan.eps * 1e9:.3g} nm), "
                   f"lateral unit {cplan.scaling.lateral * 1e9:.3g} nm")
    if cplan.solver_note:
        _say(progress, cplan.solver_note)
    grids = GridSequence(cplan.shape, dx)  # the refinement's grids: its estimate, its budget, its lines
    done = _grid_done(progress, cplan, grids)
    d_max, coarse = find_d_max(plan, cplan, dx, progress, guard=coarse_guard)  # the path's range, on a cheap grid
    est = estimate(plan, cplan, grids, d_max, run_cost(cplan, d_max, coarse))
    for line in est.lines():
        _say(progress, line)
    if later is not None and later > d_max:  # killed in its second pass: go on on that pass's path
        d_max = later
    cost = run_cost(cplan, d_max, coarse)
    max_pixels = plan.max_pixels or budget_pixels(plan, cplan.shape, grids, cost)
    check_budget(plan, est, max_pixels)
    _say(progress, cap_line(cplan.shape, grids, cost, max_pixels))
    res = resolve_to(cplan, plan.pressures[-1], d_max, ResolveSettings(plan.tol, max_pixels, dx), maps_at, observe,
                     watch, guard, keep, base, done, said)
    maps, depths = (res, maps_asked(res, plan)) if plan.maps and res.maps else (None, {})
    summary, conv, notes = summarize(res, plan)
    summary["map_pressures_asked"] = tuple(depths.items())
    return DesignResult(plan, to_dataset(res, plan, summary), summary, conv, res, tuple(notes), maps)
