"""Run a design: the grid chosen and said, the path extended to the pressures asked for, the grid refined to tol.

:func:`run_design` (a :class:`tengsim.design.plan.DesignPlan` → :class:`DesignResult`):

The design's own floor says what is asked (the pressures, the tolerance, the budget, the charged-area
definition, the maps) and reads the answer (:mod:`tengsim.design.curves`); everything between is one call to the
run layer, :func:`tengsim.run.refine.refine`:

1. **Checks.**  :func:`tengsim.run.refine.plan_refinement` plans the refinement once (a frozen
   :class:`tengsim.run.refine.RefinementPlan`) and :func:`tengsim.run.refine.preflight` checks every bound from
   its sizes alone (the solver, the first grid, the memory, the budget) before any array is allocated, once per
   design (:func:`preflight`); :func:`choose_solver` puts a cohesive law with a wall on 'pk'.
2. **Path.**  The first grid (:func:`tengsim.run.refine.first_dx`), the refinement's grids
   (:class:`tengsim.run.grids.GridSequence`) and the path's D range, found on a coarse grid
   (:func:`tengsim.run.refine.find_range`).
3. **Estimate.**  The grids, the memory and the expected time (:func:`tengsim.run.refine.estimate`), the worst
   case up to the budget's largest grid (:func:`tengsim.run.budget.cap_line`); an expected time over the
   budget is refused before the refinement is solved or anything written.
4. **Refinement.**  :func:`tengsim.run.reach.resolve_to` on dx, dx/√2, ... (:mod:`tengsim.run.grids`) until the
   charged-area fraction A/S on the approach at every asked pressure, the pull-off force and the jump D values change
   by at most tol between the last two grids (and their Richardson error is within tol).  If the finest grid does
   not reach p_max (a finer grid is softer), d_max grows and the refinement runs again (once).  The retraction's
   numbers (A/S on the retraction, the hysteresis energy) are recorded per grid with their change and Richardson
   error but not judged (:func:`tengsim.design.walk.observers`); the pull-off force is judged.  Each finished grid is
   kept (:func:`tengsim.run.checkpoint.open_checkpoint`, under :func:`tengsim.design.keep.identity`), so a killed
   run resumes.
5. **Maps.**  Each grid after the first keeps the pressure and gap maps at the D where the grid before it reached
   the asked pressures nearest 10 %, 50 % and 100 % of p_max (:func:`tengsim.design.walk.grid_path`): the finest
   grid's maps come from its own walk, at the coarser grid's prediction of those D (the figure titles say the
   pressure each map is at and the one asked).  ``maps = false``: none.
"""
from __future__ import annotations

from dataclasses import dataclass, field

from tengsim.design.plan import constrained_solver
from tengsim.design.keep import identity, kept_path
from tengsim.design.walk import map_pressures, maps_asked, observers
from tengsim.progress import say_to as _say


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
    written (:func:`tengsim.run.refine.preflight`: the solver, the first grid, the memory, the shortest path's time
    against the budget); the checked :class:`tengsim.run.refine.RefinementPlan` the run will use
    (:func:`run_design`'s ``refinement``)."""
    from tengsim.run import refine

    refinement = plan_refinement(plan, choose_solver(plan, plan.contact_plan, progress))
    refine.preflight(refinement)
    return refinement


def plan_refinement(plan, cplan):
    """The design's :class:`tengsim.run.refine.RefinementPlan` of ``cplan``: what it asks, its observers
    (:func:`tengsim.design.walk.observers`) and its maps' pressures (none with ``maps = false``)."""
    from tengsim.run.refine import plan_refinement as planned

    at = map_pressures(plan) if plan.maps else ()
    observe, watch = observers(plan)
    return planned(cplan, plan, observe, watch, at)


def choose_solver(plan, cplan, progress=None):
    """The contact plan a design runs: :func:`tengsim.design.plan.plan_design` put a cohesive law with a wall
    (``md``, ``exp``) on the constrained solver 'pk' (tengsim.solvers.pk) unless the design names its solver;
    said here in one line."""
    own = None if plan.solver_given else constrained_solver(cplan.law)
    if own == "pk" and cplan.solver == "pk":
        _say(progress, "solver: pk (Polonsky–Keer constrained CG with a cohesive zone: the law's hard-wall "
                       "limit; give solver = 'fast' or 'homotopy' for the penalty wall)")
    elif own == "ram" and cplan.solver == "ram":
        _say(progress, "solver: ram (constrained CG on the gap: the hard-wall limit the law declares; give "
                       "solver = 'fast' or 'homotopy' for the penalty wall)")
    return cplan


def run_design(plan, progress=None, keep=None, refinement=None) -> DesignResult:
    """Run one design (module doc).  ``progress``: a :class:`tengsim.progress.Progress`-like callable (the
    path's progress) and/or an object with ``say(text)``, which gets the lines said before and during the run
    (the Tabor number, the solver, the grids, memory and expected time).  ``keep`` (a file path, or None): where each
    finished grid is kept (:func:`tengsim.design.keep.checkpoint`), so a killed run of the same design resumes from it.
    ``refinement``: the design's plan already checked by :func:`preflight` (None: planned and checked here), so a
    design is checked once."""
    from tengsim.design.curves import summarize
    from tengsim.design.write import to_dataset
    from tengsim.run.budget import RunClock
    from tengsim.run.refine import Observer, preflight as check, refine

    started = RunClock.now()  # the budget counts the run's own CPU time from here (tengsim.run.budget)
    # the design's own floor first (the kept grids' identity, the maps' pressures, the solver, the first grid,
    # the observers); then one call to the run layer; then the design's numbers
    base = identity(plan)
    cplan = choose_solver(plan, plan.contact_plan, progress)
    if refinement is None:
        refinement = plan_refinement(plan, cplan)
        check(refinement)
    res = refine(refinement, Observer(progress, keep, base, kept_path(keep, base), started))
    maps, depths = (res, maps_asked(res, plan)) if plan.maps and res.maps else (None, {})
    summary, conv, notes = summarize(res, plan)
    summary["map_pressures_asked"] = tuple(depths.items())
    from tengsim.design.nearfield import design_nearfield  # issue 51: the charged pattern's near field

    summary["nearfield"] = design_nearfield(maps, plan)
    return DesignResult(plan, to_dataset(res, plan, summary), summary, conv, res, tuple(notes), maps)
