"""A refinement asked to reach a pressure: planned, checked, estimated, budgeted and solved, on the run layer.

``ask`` is what was asked: any object with ``name``, ``pressures`` (Pa, increasing; the path must reach the last),
``rel_tol`` (the refinement's), ``max_pixels`` (or None), ``budget_s`` (s), ``dx_m`` (the first grid's spacing, m, or
None: :func:`first_dx`) and ``retraction`` (false: the approach only) — a :class:`tengsim.design.plan.DesignPlan`.
``cplan`` is the :class:`tengsim.run.plan.ContactPlan` it solves (its ``solver_tol`` the solver's).

1. :func:`plan_refinement` builds the frozen :class:`RefinementPlan` once: what was asked and the refinement's own
   numbers (the first grid's dx in cell units, the grid sequence, the shortest path's time, the finest grid the
   estimate counts and its memory).  Its three entry points follow.
2. :func:`preflight` checks every bound from them, in one place, before any array is allocated: the first grid's
   size (within ``max_pixels`` and the memory, :mod:`tengsim.run.memory`; in the user's units), the solver (a
   machine without it, a law it cannot solve), the film's pixels and the shortest path's time against the budget.
3. :func:`refine` then finds the path's D range on a coarse grid (:func:`find_range`, the d-range rule of
   :func:`tengsim.run.reach.find_d_max`), says the grids, the memory and the expected time (:func:`estimate`) and
   the worst case up to the budget's largest grid, refuses an expected time over the budget, and refines
   (:func:`tengsim.run.reach.resolve_to`) with each finished grid said with its time and the next grid's.
"""
from __future__ import annotations

from dataclasses import dataclass

from tengsim.errors import TengsimError
from tengsim.progress import say_to


START_ZONE_PIXELS = 12.0
"""Pixels across the law's a-priori process zone ℓ_D on the first grid (by default).  The grid status asks for
:data:`tengsim.status.RESOLUTION` (1.2); a design's numbers (A/S at the smallest contact of the curve, the
pull-off) ask for far more, and the refinement judges from the last three grids only, so coarser first grids are
walked and thrown away (the measurements behind the 12: docs/benchmarks.md, "A design's walk").  A design that
would converge on a coarser grid pays for one or two grids finer than it needs."""


def first_dx(cplan, ask) -> float:
    """The first grid's dx in X units: ``ask.dx_m`` (a length, m) where given, else the refinement's first grid
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

    if ask.dx_m is not None:
        return ask.dx_m / cplan.scaling.lateral
    return start_dx(cplan.shape, cplan.law, cplan.coupling, cplan.boundary, START_ZONE_PIXELS)


@dataclass(frozen=True)
class Observer:
    """Who watches a refinement and where it keeps its grids, passed to :func:`refine`: ``progress`` (a
    :class:`tengsim.progress.Progress`-like object: called per path row; its ``say(text)`` gets the lines), the
    checkpoint file ``keep`` (or None) under the identity ``base``, ``later`` (the D range of a kept second pass,
    or None) and ``started`` (a :class:`tengsim.run.budget.RunClock` made at the start, or a ``time.monotonic()``
    value: the budget counts from it)."""

    progress: object = None
    keep: object = None
    base: str = ""
    later: float | None = None
    started: float = 0.0


@dataclass(frozen=True)
class RefinementPlan:
    """A refinement asked to reach a pressure, planned once (:func:`plan_refinement`) before anything is solved:
    the :class:`tengsim.run.plan.ContactPlan` it solves (``cplan``, whose ``solver_tol`` is the solver's,
    :attr:`solver_tol`) and what was asked of it, ``name``, ``pressures`` (Pa, increasing; the path must reach the
    last, :attr:`p_max`), ``rel_tol`` (the refinement's relative tolerance), ``max_pixels`` (or None), ``budget_s`` (s)
    and ``retraction`` (false: the approach only); and its own numbers: the first grid's spacing ``dx`` (X units,
    the cell's), the refinement's ``grids`` (:class:`tengsim.run.grids.GridSequence` from ``dx``), the shortest
    path's time on the first grid (``shortest_s``, s), the finest grid the estimate counts (``finest``,
    :func:`tengsim.run.budget.estimated_grids`) and its memory (``memory_bytes``); what is judged per grid,
    ``observe``, and recorded, ``watch`` (result -> {name: value}, or None), and the asked pressures where maps are
    kept (``maps_at``, Pa).  Its only entry points:
    :func:`preflight`, :func:`estimate` and :func:`refine`."""

    cplan: object
    name: str
    pressures: tuple
    rel_tol: float
    max_pixels: int | None
    budget_s: float
    retraction: bool
    dx: float
    grids: object
    shortest_s: float
    finest: object
    memory_bytes: int
    observe: object = None
    watch: object = None
    maps_at: tuple = ()

    def __post_init__(self):
        import math

        if not self.pressures or list(self.pressures) != sorted(self.pressures):
            raise TengsimError(f"{self.name[:80]}: a refinement's pressures must be given in increasing order")
        if not (math.isfinite(self.dx) and self.dx > 0) or self.grids.dx != self.dx:
            raise TengsimError(f"{self.name[:80]}: the first grid's dx must be > 0 and the grids' first")
        if not self.rel_tol > 0 or not self.budget_s > 0:
            raise TengsimError(f"{self.name[:80]}: a refinement's tol and budget must be > 0")
        if self.max_pixels is not None and self.max_pixels < 1:
            raise TengsimError(f"{self.name[:80]}: max_pixels must be at least 1")

    @property
    def p_max(self) -> float:
        """The pressure the path must reach (Pa): the last asked."""
        return self.pressures[-1]

    @property
    def solver_tol(self) -> float:
        """The solver's tolerance on each equilibrium (the contact plan's)."""
        return self.cplan.solver_tol


def plan_refinement(cplan, ask, observe=None, watch=None, maps_at=()) -> RefinementPlan:
    """The :class:`RefinementPlan` of ``cplan`` asked by ``ask`` (module doc; a size that does not fit the cell
    said in the user's units), judging ``observe`` and recording ``watch`` per grid, maps kept at ``maps_at``.
    Nothing is checked against the machine or the budget here: :func:`preflight`."""
    from tengsim.errors import GeometryError
    from tengsim.run.budget import estimated_grids, run_cost
    from tengsim.run.grids import GridSequence
    from tengsim.run.memory import estimate_bytes
    from tengsim.run.plan import _metres

    try:
        dx = _first_dx(cplan, ask)
        grids = GridSequence(cplan.shape, dx)  # the refinement's grids: its estimate, its budget, its lines
        finest = estimated_grids(ask, grids)[-1]
        shortest = run_cost(cplan, 2.0, None, ask.retraction, grids[0]).grid_seconds(cplan.shape, grids[0])
    except GeometryError as exc:  # a size that does not fit, said in the user's units
        raise exc.in_metres(cplan.scaling.lateral, _metres) from None
    memory = estimate_bytes(finest.nx, finest.ny, cplan.boundary, cplan.solver)
    return RefinementPlan(cplan, ask.name, tuple(ask.pressures), ask.rel_tol, ask.max_pixels, ask.budget_s,
                          ask.retraction, dx, grids, shortest, finest, memory, observe, watch, tuple(maps_at))


def preflight(plan: RefinementPlan) -> None:
    """Every bound of ``plan`` checked from its sizes alone (module doc, 1), in one place, before any array is
    allocated: a :class:`tengsim.errors.TengsimError` naming the value to change, a size that does not fit in the
    user's units."""
    from tengsim.errors import BudgetExceeded, GeometryError
    from tengsim.run.memory import check_memory
    from tengsim.run.plan import _metres
    from tengsim.units import length_text, time_text

    cplan = plan.cplan
    lateral = cplan.scaling.lateral
    try:
        g = plan.grids[0]
        first = f"the first grid {g.nx}×{g.ny} (dx {length_text(g.dx * lateral)})"
        if plan.max_pixels is not None and g.nx * g.ny > plan.max_pixels:
            raise TengsimError(f"{plan.name[:80]}: {first} has {g.nx * g.ny} pixels, over max_pixels = "
                               f"{plan.max_pixels}: give a larger --max-pixels or a coarser --dx")
        check_memory(g.nx, g.ny, cplan.boundary, cplan.solver)
        check_solver(cplan)
        if (cplan.kernel_params or {}).get("thickness") is not None:
            from tengsim.kernels.film import check_film_pixels

            check_film_pixels(cplan.kernel_params["thickness"], max(g.dx, g.dy), lateral)
        if plan.shortest_s > plan.budget_s:
            raise BudgetExceeded(f"{plan.name[:80]}: {first} alone is estimated at {time_text(plan.shortest_s)}, "
                                 f"over the budget of {time_text(plan.budget_s)}: give a coarser --dx, a coarser "
                                 f"--tol (now {plan.rel_tol:g}) or a larger --budget", plan.budget_s)
    except GeometryError as exc:  # a size that does not fit, said in the user's units
        raise exc.in_metres(lateral, _metres) from None


def estimate(plan: RefinementPlan, d_max: float, coarse=None):
    """The :class:`tengsim.run.budget.Estimate` of ``plan`` (its grids, the finest's memory, the expected time)
    for the path's D range ``d_max`` found on the coarse pre-run ``coarse`` (:func:`find_range`)."""
    from tengsim.run import budget

    cost = budget.run_cost(plan.cplan, d_max, coarse, plan.retraction, plan.finest)
    return budget.estimate(plan, plan.cplan, plan.grids, d_max, cost, plan.memory_bytes)


def check_solver(cplan) -> None:
    """The plan's solver made once, before anything is solved: a solver this machine lacks (JAX, a GPU) raises
    :class:`tengsim.errors.SolverUnavailable`; a law it cannot solve, a :class:`tengsim.errors.TengsimError`
    naming the solvers that can."""
    from tengsim.solvers import make_solver

    solver = make_solver(cplan.solver, tol=cplan.solver_tol)
    if hasattr(solver, "solves") and not solver.solves(cplan.law):
        from tengsim.solvers.pk import PKSolver, limit_of

        if isinstance(solver, PKSolver):
            limit_of(cplan.law, solver.name)  # raises the solver's own line, naming the solvers that can
        raise TengsimError(f"solver {cplan.solver!r} cannot solve law {type(cplan.law).__name__}")


def find_range(plan: RefinementPlan, progress=None, guard=None):
    """(d_max, the coarse result): the D range whose approach reaches ``plan``'s last pressure, found on a grid
    twice as coarse as the first (:func:`tengsim.run.reach.find_d_max`), each extension said in one line;
    ``guard`` (called per path row, e.g. :func:`tengsim.run.budget.deadline`) may stop it."""
    from tengsim.run.reach import find_d_max, height_eps
    from tengsim.units import pressure_text

    def extending(top, d_max):
        say_to(progress, f"path: {pressure_text(top)} reached at D = {d_max:.3g} ε, extending")

    return find_d_max(plan.cplan, plan.dx, plan.p_max, height_eps(plan.cplan, plan.dx), extending, guard)


def said_solver(cplan, first, finest, said) -> None:
    """Which solver 'auto' takes on the refinement's grids (each grid chooses its own when it is solved,
    :func:`tengsim.run.plan.chosen_solver`), said before the first: one line, or two where the first grid and
    the finest expected choose differently (a GPU above its break-even); nothing for a solver asked by name."""
    from tengsim.run.plan import chosen_solver

    (a, why), (b, why_fine) = chosen_solver(cplan, first), chosen_solver(cplan, finest)
    if why:
        said(why if a == b else f"{why}; from {finest.nx}×{finest.ny} on: {why_fine}")


def refine(plan: RefinementPlan, observer: Observer = Observer()):
    """The refined :class:`tengsim.results.ContactResult` of ``plan`` (checked by :func:`preflight`) whose approach
    reaches its last pressure (module doc); a :class:`tengsim.errors.TengsimError` before the refinement is solved
    where its expected time is over the budget."""
    from tengsim.run.budget import budget_pixels, cap_line, check_budget, deadline, next_grid_line, on_gpu, run_cost
    from tengsim.run.plan import ResolveSettings
    from tengsim.run.reach import resolve_to

    def said(text):
        say_to(observer.progress, text)

    cplan = plan.cplan
    cpu = not on_gpu(cplan, plan.finest)  # the budget in the run's own CPU time (a GPU run's host waits: the wall time)
    coarse_guard = deadline(None, plan, observer.keep, observer.started, cpu)
    guard = deadline(observer.progress, plan, observer.keep, observer.started, cpu)
    grids = plan.grids
    said(f"{plan.name}: Tabor number {cplan.tabor:.3g} (from eps = {cplan.scaling.eps * 1e9:.3g} nm), "
         f"lateral unit {cplan.scaling.lateral * 1e9:.3g} nm")
    said_solver(cplan, grids[0], plan.finest, said)

    d_max, coarse = find_range(plan, observer.progress, coarse_guard)  # the path's range, on a cheap grid
    est = estimate(plan, d_max, coarse)
    for line in est.lines():
        said(line)
    if observer.later is not None and observer.later > d_max:  # killed in its second pass: go on on that pass's path
        d_max = observer.later

    def done(levels):  # after each finished (and kept) grid: its measured time and the next grid's expected one
        said(next_grid_line(cplan.shape, grids[:len(levels) + 1], levels[-1].seconds, cplan.scaling.lateral))

    cost = run_cost(cplan, d_max, coarse, plan.retraction, plan.finest)
    max_pixels = plan.max_pixels or budget_pixels(plan, cplan.shape, grids, cost)
    worst = cap_line(cplan.shape, grids, cost, max_pixels)
    check_budget(plan, est, max_pixels)  # refused before the worst case is said or anything solved
    said(worst)
    return resolve_to(plan, d_max, ResolveSettings(plan.rel_tol, max_pixels, plan.dx), guard, observer.keep,
                      observer.base, done, said)
