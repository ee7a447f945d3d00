"""A refinement asked to reach a pressure: checked, estimated, budgeted and solved, on the run layer.

``ask`` is what was asked: any object with ``name``, ``pressures`` (Pa, increasing; the path must reach the last),
``tol``, ``max_pixels`` (or None), ``budget_s`` (s), ``dx`` (the first grid's spacing, m, or None: :func:`first_dx`)
and ``retraction`` (false: the approach only) — a :class:`tengsim.design.plan.DesignPlan`.  ``cplan`` is the :class:`tengsim.run.plan.ContactPlan` it solves.

1. The refinement's own numbers come first (:func:`sizes`: the first grid's dx, the grid sequence, the shortest
   path's time, the finest grid the estimate counts); then :func:`preflight` checks every bound from them, in one
   place, before any array is allocated: the first grid's size (within ``max_pixels`` and the memory,
   :mod:`tengsim.run.memory`; in the user's units) and counts the memory of the finest grid estimated; then the
   solver (a machine without it, a law it cannot solve), the film's pixels and the shortest path's time against
   the budget.
2. :func:`refine` then finds the path's D range on a coarse grid (:func:`tengsim.run.reach.find_d_max`), says the
   grids, the memory and the expected time (:func:`tengsim.run.budget.estimate`) and the worst case up to the
   budget's largest grid, refuses an expected time over the budget, and refines (:func:`tengsim.run.reach.resolve_to`)
   with each finished grid said with its time and the next grid's.
"""
from __future__ import annotations

from dataclasses import dataclass

from tengsim.errors import TengsimError


START_ZONE_PIXELS = 12.0
"""Pixels across the law's a-priori process zone ℓ_D on the first grid (by default).  The grid status asks for
:data:`tengsim.status.RESOLUTION` (1.2); a design's numbers (A/S at the smallest contact of the curve, the
pull-off) ask for far more, and the refinement judges from the last three grids only, so coarser first grids are
walked and thrown away (the measurements behind the 12: docs/benchmarks.md, "A design's walk").  A design that
would converge on a coarser grid pays for one or two grids finer than it needs."""


def first_dx(cplan, ask) -> float:
    """The first grid's dx in X units: ``ask.dx`` (a length, m) where given, else the refinement's first grid
    whose dx is at most the law's process zone over :data:`START_ZONE_PIXELS` (:func:`tengsim.run.grids.start_dx`);
    a size that does not fit the cell is said in the user's units."""
    from tengsim.errors import GeometryError
    from tengsim.run.plan import _metres

    try:
        return _first_dx(cplan, ask)
    except GeometryError as exc:
        raise exc.in_metres(cplan.scaling.lateral, _metres) from None


def _first_dx(cplan, ask) -> float:
    """:func:`first_dx` in X units, a size that does not fit the cell raised as it is (in X units)."""
    from tengsim.run.grids import start_dx

    if ask.dx is not None:
        return ask.dx / cplan.scaling.lateral
    return start_dx(cplan.shape, cplan.law, cplan.coupling, cplan.boundary, START_ZONE_PIXELS)


def say_to(progress, text: str) -> None:
    """``text`` to ``progress.say`` where it has one (a :class:`tengsim.progress.Progress`-like object)."""
    if progress is not None and hasattr(progress, "say"):
        progress.say(text)


@dataclass(frozen=True)
class Hooks:
    """What a refinement reports to and keeps: ``progress`` (called per path row; its ``say(text)`` gets the
    lines), ``observe`` / ``watch`` (result -> {name: value}: judged / recorded per grid), ``maps_at`` (asked
    pressures, Pa, where maps are kept), ``keep`` (the checkpoint file or None) under ``base`` (its identity),
    ``later`` (the D range of a kept second pass, or None) and ``started`` (a :class:`tengsim.run.budget.RunClock`
    made at the start, or a ``time.monotonic()`` value: the budget counts from it)."""

    progress: object = None
    observe: object = None
    watch: object = None
    maps_at: tuple = ()
    keep: object = None
    base: str = ""
    later: float | None = None
    started: float = 0.0


@dataclass(frozen=True)
class Sizes:
    """A refinement's sizes, known before anything is solved: the first grid's spacing ``dx`` (X units), the
    refinement's ``grids`` (:class:`tengsim.run.grids.GridSequence`), the shortest path's time on the first grid
    (``shortest_s``, s) and the finest grid the estimate counts (``finest``,
    :func:`tengsim.run.budget.estimated_grids`)."""

    dx: float
    grids: object
    shortest_s: float
    finest: object


def sizes(cplan, ask) -> Sizes:
    """The refinement's :class:`Sizes` (in X units; a size that does not fit the cell raised in X units)."""
    from tengsim.run.budget import estimated_grids, run_cost
    from tengsim.run.grids import GridSequence

    dx = _first_dx(cplan, ask)
    grids = GridSequence(cplan.shape, dx)  # the refinement's grids: its estimate, its budget, its lines
    shortest = run_cost(cplan, 2.0, None, ask.retraction).grid_seconds(cplan.shape, grids[0])
    return Sizes(dx, grids, shortest, estimated_grids(ask, grids)[-1])


def preflight(cplan, ask) -> tuple:
    """Every bound checked from the sizes alone (module doc, 1), in one place: a :class:`tengsim.errors.TengsimError`
    naming the value to change, a size that does not fit in the user's units; (the refinement's :class:`Sizes`
    (:func:`sizes`), the memory of the finest grid its estimate counts, bytes)."""
    from tengsim.errors import BudgetExceeded, GeometryError
    from tengsim.run.memory import check_memory, estimate_bytes
    from tengsim.run.plan import _metres
    from tengsim.units import length_text, time_text

    lateral = cplan.scaling.lateral
    try:
        size = sizes(cplan, ask)
        g = size.grids[0]
        first = f"the first grid {g.nx}×{g.ny} (dx {length_text(g.dx * lateral)})"
        if ask.max_pixels is not None and g.nx * g.ny > ask.max_pixels:
            raise TengsimError(f"{ask.name[:80]}: {first} has {g.nx * g.ny} pixels, over max_pixels = "
                               f"{ask.max_pixels}: give a larger --max-pixels or a coarser --dx")
        check_memory(g.nx, g.ny, cplan.boundary, cplan.solver)
        memory = estimate_bytes(size.finest.nx, size.finest.ny, cplan.boundary, cplan.solver)
        check_solver(cplan)
        if (cplan.kernel_params or {}).get("thickness") is not None:
            from tengsim.kernels.film import check_film_pixels

            check_film_pixels(cplan.kernel_params["thickness"], max(g.dx, g.dy), lateral)
        if size.shortest_s > ask.budget_s:
            raise BudgetExceeded(f"{ask.name[:80]}: {first} alone is estimated at {time_text(size.shortest_s)}, "
                                 f"over the budget of {time_text(ask.budget_s)}: give a coarser --dx, a coarser --tol "
                                 f"(now {ask.tol:g}) or a larger --budget", ask.budget_s)
    except GeometryError as exc:  # a size that does not fit, said in the user's units
        raise exc.in_metres(lateral, _metres) from None
    return size, memory


def check_solver(cplan) -> None:
    """The plan's solver made once, before anything is solved: a solver this machine lacks (JAX, a GPU) raises
    :class:`tengsim.errors.SolverUnavailable`; a law it cannot solve, a :class:`tengsim.errors.TengsimError`
    naming the solvers that can."""
    from tengsim.solvers import make_solver

    solver = make_solver(cplan.solver, tol=cplan.tol)
    if hasattr(solver, "solves") and not solver.solves(cplan.law):
        from tengsim.solvers.pk import PKSolver, limit_of

        if isinstance(solver, PKSolver):
            limit_of(cplan.law, solver.name)  # raises the solver's own line, naming the solvers that can
        raise TengsimError(f"solver {cplan.solver!r} cannot solve law {type(cplan.law).__name__}")


def find_range(cplan, ask, dx: float, progress=None, guard=None):
    """(d_max, the coarse result): the D range whose approach reaches ``ask``'s last pressure, found on a grid
    twice as coarse as the first (:func:`tengsim.run.reach.find_d_max`), each extension said in one line;
    ``guard`` (called per path row, e.g. :func:`tengsim.run.budget.deadline`) may stop it."""
    from tengsim.run.reach import find_d_max, height_eps
    from tengsim.units import pressure_text

    def extending(top, d_max):
        say_to(progress, f"path: {pressure_text(top)} reached at D = {d_max:.3g} ε, extending")

    return find_d_max(cplan, dx, ask.pressures[-1], height_eps(cplan, dx), extending, guard)


def refine(cplan, ask, hooks: Hooks = Hooks()):
    """The refined :class:`tengsim.results.ContactResult` of ``cplan`` whose approach reaches ``ask``'s last
    pressure (module doc); a :class:`tengsim.errors.TengsimError` before anything is solved where a bound or the
    budget is exceeded."""
    from tengsim.run.budget import (budget_pixels, cap_line, check_budget, deadline, estimate, next_grid_line, on_gpu,
                                    run_cost)
    from tengsim.run.plan import ResolveSettings
    from tengsim.run.reach import resolve_to

    def said(text):
        say_to(hooks.progress, text)

    # the run layer's own numbers first (the sizes, the guards), then every bound checked in one place
    p_max = ask.pressures[-1]
    cpu = not on_gpu(cplan)  # the budget in the run's own CPU time (a GPU run's host waits: the wall time)
    coarse_guard = deadline(None, ask, hooks.keep, hooks.started, cpu)
    guard = deadline(hooks.progress, ask, hooks.keep, hooks.started, cpu)
    size, memory = preflight(cplan, ask)
    dx, grids = size.dx, size.grids
    said(f"{ask.name}: Tabor number {cplan.tabor:.3g} (from eps = {cplan.scaling.eps * 1e9:.3g} nm), "
         f"lateral unit {cplan.scaling.lateral * 1e9:.3g} nm")
    if cplan.solver_note:
        said(cplan.solver_note)

    d_max, coarse = find_range(cplan, ask, dx, hooks.progress, coarse_guard)  # the path's range, on a cheap grid
    est = estimate(ask, cplan, grids, d_max, run_cost(cplan, d_max, coarse, ask.retraction), memory)
    for line in est.lines():
        said(line)
    if hooks.later is not None and hooks.later > d_max:  # killed in its second pass: go on on that pass's path
        d_max = hooks.later
    cost = run_cost(cplan, d_max, coarse, ask.retraction)
    max_pixels = ask.max_pixels or budget_pixels(ask, cplan.shape, grids, cost)
    check_budget(ask, est, max_pixels)
    said(cap_line(cplan.shape, grids, cost, max_pixels))

    def done(levels):  # after each finished (and kept) grid: its measured time and the next grid's expected one
        said(next_grid_line(cplan.shape, grids[:len(levels) + 1], levels[-1]["seconds"], cplan.scaling.lateral))

    return resolve_to(cplan, p_max, d_max, ResolveSettings(ask.tol, max_pixels, dx), hooks.maps_at, hooks.observe,
                      hooks.watch, guard, hooks.keep, hooks.base, done, said, ask.retraction)
