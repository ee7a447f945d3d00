"""Run a design: the grid chosen and said, the path extended to the pressures asked for, the grid refined to tol.

:func:`run_design` (a :class:`tengsim.design.plan.DesignPlan` → :class:`DesignResult`):

1. **Grid.**  The first dx is the user's (a length) or :func:`start_dx`: the finer of
   :func:`tengsim.run.resolve.default_dx` (the law's process zone over the pixels the status asks for, and the
   pixel-snap limit) and the process zone over :data:`START_ZONE_PIXELS`.  After the coarse pre-run of step 2
   (the path's range and the solver's iterations per row, on a cheap grid) and before the refinement,
   :func:`estimate` prints the grids (first, and the next two of √2 refinement), the memory of the finest,
   the solver ``auto`` chose and the expected time: the first two grids and half the third, each rows ×
   iterations × the backend's cost per iteration (:class:`Cost`, :mod:`tengsim.resources`: the CPU's or the
   GPU's model, named in the line); :func:`cap_line` the worst case up to the budget's largest grid.  An
   expected time above the plan's budget is refused (a :class:`tengsim.errors.TengsimError` naming max_pixels
   and tol) before the refinement is solved or anything written.
2. **Path.**  An adaptive D walk (:class:`tengsim.continuation.path.PathSpec`) from D = -1 ε to a d_max found on a grid
   twice as coarse as the default first grid: from 1.2 × the structure's height (+2 ε), extended in chunks (the
   last rows' dP/dD, extrapolated to 1.3 × the pressure still missing) until the approach reaches p_max, at
   most :data:`EXTEND_TRIES` times; else an error naming the highest pressure reached, in kPa.  A finer grid's
   walk ends a little past the D at which the grid before it reached p_max (:func:`grid_path`).
3. **Refinement.**  :func:`tengsim.run.resolve.resolve_contact` on dx, dx/√2, ... until the charged-area
   fraction A/S on the approach at every asked pressure, the pull-off force and the jump D values change by
   at most tol between the last two grids (and their Richardson error is within tol).  If the finest grid
   does not reach p_max (a finer grid is softer), d_max grows and the refinement runs again (once).  The
   retraction's numbers (A/S on the retraction, the hysteresis energy) are recorded per grid with their
   change and Richardson error but not judged (:func:`_watcher`); the pull-off force is judged.
4. **Maps.**  Each grid after the first keeps the pressure and gap maps at the D where the grid before it
   reached the asked pressures nearest 10 %, 50 % and 100 % of p_max (:func:`grid_path`): the finest grid's
   maps come from its own walk, at the coarser grid's prediction of those D (the figure titles say the
   pressure each map is at and the one asked).  ``maps = false``: none.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np

from tengsim.errors import TengsimError
from tengsim.resources import CostModel, cost_model

D_MIN = -1.0
D_STEP = 0.4
"""Largest D step (ε) of the adaptive walk (refine_levels 4: smallest 0.025 ε)."""
ROWS_PER_STEP = 2.0
"""Path rows per d_step of D range on each grid, approach and retraction together (the first grid walks to d_max,
each finer one to a little past where the grid before reached p_max; docs/benchmarks.md, "Design estimates")."""
ITERATIONS_PER_COARSE = 4.0
"""A refinement grid's solver iterations per path row over the coarse pre-run's mean (:func:`find_d_max`;
docs/benchmarks.md, "Design estimates")."""
THIRD_GRID_SHARE = 0.5
"""The expected run counts the third grid at this weight: some designs converge on two grids, others need a third
(docs/benchmarks.md, "Design estimates")."""
LEVELS_ESTIMATED = 3
EXTEND_TRIES = 6
SOLVER_TOL_PER_TOL = 0.01
"""Each equilibrium of a design is solved to max|r| <= this × the design's tol (ε; 1e-4 at the default 1 %): the
solver's share of a reported number is then far below tol (docs/validation.md, "A design's solver tolerance")."""


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


def _say(progress, text):
    if progress is not None and hasattr(progress, "say"):
        progress.say(text)


def _blocks(shape, grid) -> int:
    """Pixels of the solved block (a quarter of the grid for a shape mirrored in x and y on an odd grid)."""
    axes = [a for a in getattr(shape, "mirror_axes", ()) or () if grid.shape[a] % 2 == 1]
    n = grid.nx * grid.ny
    return n // (2 ** len(axes)) if axes else n


START_ZONE_PIXELS = 12.0
"""Pixels across the law's a-priori process zone ℓ_D on a design's first grid (by default).  The grid status asks
for :data:`tengsim.status.RESOLUTION` (1.2); a design's numbers (A/S at the smallest contact of the curve, the
pull-off) ask for far more, and the refinement judges from the last three grids only, so coarser first grids are
walked and thrown away (the measurements behind the 12: docs/benchmarks.md, "A design's walk").  A design that
would converge on a coarser grid pays for one or two grids finer than it needs."""


def refinement_grids(shape, dx: float, count: int = 12) -> list:
    """The grids :func:`tengsim.run.resolve.resolve_contact` walks from a first grid of spacing ``dx`` (each the
    plain √2 step, moved to keep the shape's edges in place), at most ``count``, none over the budget limit."""
    from tengsim.run.resolve import FACTOR, _aligned, edge_phases

    out, seen, phases = [], set(), ()
    while len(out) < count:
        g = shape.grid(dx)
        if out:
            g = _aligned(shape, g, phases, 2**40)
        else:
            phases = edge_phases(shape, g)
        if (g.nx, g.ny) in seen:
            dx /= FACTOR
            continue
        seen.add((g.nx, g.ny))
        out.append(g)
        dx = g.dx / FACTOR
    return out


def start_dx(plan, cplan) -> float:
    """The first grid's dx in X units: the plan's (a length), or the first grid of the refinement that
    :func:`tengsim.run.resolve.default_dx` would start (the cell over 9 pixels, the status's process-zone
    resolution, the pixel-snap limit: :func:`refinement_grids`) whose dx is at most the law's process zone over
    :data:`START_ZONE_PIXELS`: the same grids as from the default start, less those too coarse to be the last."""
    from tengsim import status
    from tengsim.run.resolve import default_dx

    if plan.dx is not None:
        return plan.dx / cplan.scaling.lateral
    dx = default_dx(cplan.shape, cplan.law, cplan.coupling, cplan.boundary)
    zone = status.process_zone_estimate(cplan.law, cplan.coupling)
    if not (math.isfinite(zone) and zone > 0) or dx <= zone / START_ZONE_PIXELS:
        return dx
    for g in refinement_grids(cplan.shape, dx):
        if g.dx <= zone / START_ZONE_PIXELS:
            return g.dx
    return zone / START_ZONE_PIXELS


def height_eps(cplan, dx) -> float:
    """The structure's height in ε (the range of its gap U0 on the grid)."""
    U0 = cplan.shape.gap(cplan.shape.grid(dx))
    return float(np.nanmax(U0) - np.nanmin(U0))


@dataclass(frozen=True)
class Cost:
    """What a design's run costs per grid, known after the coarse pre-run (:func:`find_d_max`): the backend's
    :class:`tengsim.resources.CostModel`, the path rows per grid and the solver iterations per row."""

    model: CostModel
    rows: float
    iterations: float
    gpu: bool = False

    def grid_seconds(self, shape, grid) -> float:
        """Seconds of one grid's walk (the GPU solves the whole grid: the JAX solver has no mirror symmetry)."""
        points = grid.nx * grid.ny if self.gpu else _blocks(shape, grid)
        return self.rows * self.iterations * self.model.iteration_seconds(points)


def on_gpu(cplan) -> bool:
    """Whether the plan's solver runs on a GPU ('gpu', or 'jax' where JAX sees one)."""
    from tengsim.solvers.choice import gpu_visible

    name = cplan.solver if isinstance(cplan.solver, str) else getattr(cplan.solver, "name", "")
    return name == "gpu" or (name == "jax" and gpu_visible()) or getattr(cplan.solver, "device", "") == "gpu"


def run_cost(cplan, d_max: float, coarse=None) -> Cost:
    """The :class:`Cost` of a design's grids: rows from the path's D range (:data:`ROWS_PER_STEP`), iterations per
    row from the coarse pre-run ``coarse`` (× :data:`ITERATIONS_PER_COARSE`; 20 per row without one)."""
    its = 20.0
    if coarse is not None:
        it = np.asarray(coarse.table.get("iterations", ()), dtype=float)
        if it.size and np.isfinite(it).all():
            its = float(np.mean(it))
    gpu = on_gpu(cplan)
    return Cost(cost_model(gpu), ROWS_PER_STEP * (d_max - D_MIN) / D_STEP, ITERATIONS_PER_COARSE * its, gpu)


@dataclass(frozen=True)
class Estimate:
    grids: tuple  # ((nx, ny, dx_m), ...)
    memory_bytes: int
    seconds: float
    d_max: float
    backend: str = ""
    cost: Cost | None = None

    def lines(self) -> list:
        from tengsim.design.units import bytes_text, length_text, time_text

        g = ", ".join(f"{nx}×{ny} (dx {length_text(d)})" for nx, ny, d in self.grids)
        rows = (f", {self.cost.rows:.0f} rows of about {self.cost.iterations:.0f} iterations per grid"
                if self.cost else "")
        return [f"grids: {g} (refined by √2 until converged; the last two are used only if needed)",
                f"memory: {bytes_text(self.memory_bytes)} on the finest; expected time: {time_text(self.seconds)} "
                f"(the first two grids and half the third, D path to about {self.d_max:.0f} ε{rows}) on "
                f"{self.backend}"]


def estimate(plan, cplan, dx: float, d_max: float, coarse=None) -> Estimate:
    """Grids, memory and expected time of the refinement (module doc, step 1): the first two grids and
    :data:`THIRD_GRID_SHARE` of the third, at the cost :func:`run_cost` of the backend the plan solves on."""
    from tengsim.resources import estimate_bytes

    cost = run_cost(cplan, d_max, coarse)
    grids, secs = [], 0.0
    for k, g in enumerate(refinement_grids(cplan.shape, dx, LEVELS_ESTIMATED)):  # the grids the refinement walks
        if plan.max_pixels is not None and g.nx * g.ny > plan.max_pixels and grids:
            break
        grids.append((g.nx, g.ny, g.dx * cplan.scaling.lateral))
        secs += cost.grid_seconds(cplan.shape, g) * (THIRD_GRID_SHARE if k >= 2 else 1.0)
    nx, ny, _ = grids[-1]
    return Estimate(tuple(grids), estimate_bytes(nx, ny, cplan.boundary, cplan.solver), secs, d_max,
                    cost.model.backend, cost)


def budget_pixels(plan, cplan, dx: float, d_max: float, coarse=None) -> int:
    """The largest grid (nx·ny) the refinement may reach within the plan's time budget (the cost summed
    over the grids dx, dx/√2, ... up to it): the default max_pixels, so no default run runs past its budget."""
    cost = run_cost(cplan, d_max, coarse)
    secs, top = 0.0, 9
    for k in range(12):
        g = cplan.shape.grid(dx / math.sqrt(2.0) ** k)
        step = cost.grid_seconds(cplan.shape, g)
        if secs + step > plan.budget_s and k > 0:  # the grid between the last that fits and this one that the
            # budget still pays for (a grid's time goes as its pixels): the refinement's grids keep a shape's
            # edges in place and so are up to resolve.PHASE_SPAN larger than the plain √2 sequence
            return max(top, int(g.nx * g.ny * (plan.budget_s - secs) / step))
        secs += step
        top = g.nx * g.ny
    return top


def cap_line(plan, cplan, dx: float, d_max: float, cap: int, coarse=None) -> str:
    """The worst case: the grids dx, dx/√2, ... up to ``cap`` pixels, and their summed cost."""
    from tengsim.design.units import time_text

    cost = run_cost(cplan, d_max, coarse)
    secs, last = 0.0, None
    for k in range(16):
        g = cplan.shape.grid(dx / math.sqrt(2.0) ** k)
        if g.nx * g.ny > cap and last is not None:
            break
        secs += cost.grid_seconds(cplan.shape, g)
        last = g
    side = max(last.nx, math.isqrt(int(cap)))
    if side > last.nx:  # one more grid, beyond the plain sequence's last (budget_pixels): its time as its pixels
        secs += cost.grid_seconds(cplan.shape, last) * side * side / (last.nx * last.ny)
    return (f"at most: refinement up to {side}×{side} (the budget's largest grid; --max-pixels sets it), "
            f"about {time_text(secs)} in all")


def check_budget(plan, est: Estimate, fit_pixels: int | None = None) -> None:
    """Refuse an expected time over the plan's budget, naming what to change: a max_pixels that fits (when the
    first two grids do) or a coarser dx."""
    from tengsim.design.units import length_text, time_text

    if est.seconds <= plan.budget_s:
        return
    two = est.grids[1][0] * est.grids[1][1] if len(est.grids) > 1 else None
    what = f"a coarser --dx (the first grid's is {length_text(est.grids[0][2])})"
    if fit_pixels and two and fit_pixels >= two:
        what = f"--max-pixels {fit_pixels} (the grids that fit the budget), {what}"
    raise TengsimError(f"this design is expected to take {time_text(est.seconds)} on {est.backend.split(' (')[0]}, "
                       f"over the budget of {time_text(plan.budget_s)}: give {what}, a coarser --tol (now "
                       f"{plan.tol:g}) or a larger --budget")


def preflight(plan) -> None:
    """Every bound of a design checked from its sizes alone, before any array is allocated or anything is
    written: the first grid fits the cell (in the user's units), is within ``max_pixels`` and the memory, and
    its shortest path (D to 2 ε: no structure at all) fits the budget.  The full estimate, with the structure's
    height, follows in :func:`run_design`; this one needs no gap array (a --dx of 0.02 nm was killed for its
    memory before any check)."""
    from tengsim.design.units import length_text, time_text
    from tengsim.errors import GeometryError
    from tengsim.resources import check_memory
    from tengsim.run.plan import _metres, as_plan
    from tengsim.solvers import make_solver

    cplan = as_plan(plan.contact_table if plan.contact_plan is None else plan.contact_plan)
    cplan = choose_solver(plan, cplan)  # the solver the run will use (a cohesive law: pk)
    solver = make_solver(cplan.solver, tol=solver_tol(plan))  # a solver this machine lacks (gpu): refused now
    if hasattr(solver, "solves") and not solver.solves(cplan.law):  # a law it cannot solve: refused now
        from tengsim.solvers.pk import PKSolver, wall_model

        if isinstance(solver, PKSolver):
            wall_model(cplan.law)  # raises the solver's own line, naming the solvers that can
        raise TengsimError(f"solver {cplan.solver!r} cannot solve law {type(cplan.law).__name__}")
    lateral = cplan.scaling.lateral
    try:
        dx = start_dx(plan, cplan)
        g = cplan.shape.grid(dx)
    except GeometryError as exc:
        raise exc.in_metres(lateral, _metres) from None
    first = f"the first grid {g.nx}×{g.ny} (dx {length_text(g.dx * lateral)})"
    if plan.max_pixels is not None and g.nx * g.ny > plan.max_pixels:
        raise TengsimError(f"{plan.name[:80]}: {first} has {g.nx * g.ny} pixels, over max_pixels = "
                           f"{plan.max_pixels}: give a larger --max-pixels or a coarser --dx")
    check_memory(g.nx, g.ny, cplan.boundary, cplan.solver)
    if (cplan.kernel_params or {}).get("thickness") is not None:
        from tengsim.kernels.film import check_film_pixels

        check_film_pixels(cplan.kernel_params["thickness"], max(g.dx, g.dy), lateral)
    secs = run_cost(cplan, 2.0).grid_seconds(cplan.shape, g)  # the shortest path, on the backend's cost model
    if secs > plan.budget_s:
        raise TengsimError(f"{plan.name[:80]}: {first} alone is estimated at {time_text(secs)}, over the budget "
                           f"of {time_text(plan.budget_s)}: give a coarser --dx, a coarser --tol (now "
                           f"{plan.tol:g}) or a larger --budget")


class BudgetSpent(TengsimError):
    """A design stopped at its time budget (what finished is kept; the message says how to go on)."""


def _deadline(progress, plan, keep, started):
    """``progress`` (called per path row) that also stops the run, cleanly, once ``plan.budget_s`` seconds
    have passed since ``started``: the finished grids stay in ``keep`` and the message says how to go on."""
    import time

    def call(*a, **k):
        if time.monotonic() - started > plan.budget_s:
            from tengsim.design.units import time_text

            where = (f"the finished grids are kept in {keep}: run the same command with a larger --budget to go "
                     "on from them") if keep is not None and keep.exists() else \
                "no grid had finished: give a larger --budget, a coarser --dx or a coarser --tol"
            raise BudgetSpent(f"{plan.name[:80]}: stopped at the budget of {time_text(plan.budget_s)}; {where}")
        if callable(progress):
            return progress(*a, **k)
        return None

    return call


#: laws a design runs on the constrained solver 'pk' (their hard-wall limit) unless it names its solver
PK_LAWS = ("MaugisDugdale", "Exponential")


def choose_solver(plan, cplan, progress=None):
    """The contact plan a design runs: a cohesive law with a wall (``md``, ``exp``) on the constrained solver
    'pk' (tengsim.solvers.pk) unless the design's table names a solver; said in one line."""
    table = plan.contact_table if isinstance(plan.contact_table, dict) else {}
    if table.get("solver") in (None, "", "auto") and type(cplan.law).__name__ in PK_LAWS:
        cplan = dataclasses.replace(cplan, solver="pk", solver_note="")
        _say(progress, "solver: pk (Polonsky–Keer constrained CG with a cohesive zone: the law's hard-wall "
                       "limit; give solver = 'fast' or 'homotopy' for the penalty wall)")
    return cplan


def solver_tol(plan) -> float:
    """The solver's tolerance of a design (:data:`SOLVER_TOL_PER_TOL`)."""
    return SOLVER_TOL_PER_TOL * plan.tol


def _simulate(cplan, dx, d_max, **kw):
    from tengsim.run.simulate import simulate
    from tengsim.continuation import PathSpec

    path = PathSpec(D_MIN, d_max, D_STEP, adaptive=True)
    return simulate(cplan.shape, cplan.tabor, dx, path, boundary=cplan.boundary, solver=cplan.solver,
                    tol=cplan.tol, law=cplan.law, extra_params=cplan.extra, scaling=cplan.scaling,
                    kernel_params=cplan.kernel_params, symmetry=cplan.symmetry, **kw)


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
    (module doc, step 2); ``guard`` (called per path row, e.g. :func:`_deadline`) may stop it."""
    from tengsim.design.units import pressure_text

    p_max = plan.pressures[-1]
    from tengsim.run.resolve import default_dx

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


def identity(plan) -> str:
    """What a design's kept grids belong to: the plan (every key as given but the budget), the content of every
    input file it names (a topography's heights: the file's bytes, not its name), tengsim's version and the
    plugins loaded (a user's shape or law changed between runs gives other grids).  16 hex digits."""
    import hashlib
    from pathlib import Path

    from tengsim import plugins
    from tengsim._version import __version__

    same = dataclasses.replace(plan, budget_s=0.0)  # a larger --budget goes on from the grids a budget stopped
    h = hashlib.sha256(f"{same!r}|{__version__}|{sorted(plugins._LOADED)!r}".encode())
    for v in (plan.contact_table or {}).values():
        if isinstance(v, str) and len(v) < 4096 and Path(v).is_file():
            with open(v, "rb") as fh:
                for block in iter(lambda: fh.read(1 << 20), b""):
                    h.update(block)
    return h.hexdigest()[:16]


def _kept_path(keep, base: str) -> float | None:
    """The D range (ε) of the grids ``keep`` holds for this design (``base``: :func:`identity`), or None: a run
    killed in its second pass (a longer path) resumes on that path, not on the first pass's."""
    if keep is None:
        return None
    from tengsim.run.checkpoint import Checkpoint

    found = Checkpoint(keep, "").stored_digest() or ""
    head, _, d = found.partition("@")
    try:
        return float(d) if head == base else None
    except ValueError:
        return None


def _checkpoint(keep, base, d_max, progress):
    """The refinement's checkpoint in the file ``keep`` for this design (``base``, :func:`identity`) and path
    (None without ``keep``): each finished grid is kept there, and a run of the same design and path takes its
    grids back instead of computing them again; grids of the same design on a shorter path (its first pass)
    are replaced quietly, those of another design with a line saying so."""
    if keep is None:
        return None
    from tengsim.errors import TengsimError as _Err
    from tengsim.run.checkpoint import Checkpoint

    ck = Checkpoint(keep, f"{base}@{d_max!r}")
    try:
        found = ck.load()
    except _Err:
        if not (ck.stored_digest() or "").startswith(base + "@"):
            _say(progress, f"{keep} holds grids of another design or input: they are replaced")
        keep.unlink()
        found = None
    if found is not None:
        _say(progress, f"taking back {len(found[0])} finished grid(s) from {keep}")
    keep.parent.mkdir(parents=True, exist_ok=True)
    return ck, found


def run_design(plan, progress=None, keep=None) -> DesignResult:
    """Run one design (module doc).  ``progress``: a :class:`tengsim.progress.Progress`-like callable (the
    path's progress) and/or an object with ``say(text)``, which gets the lines said before and during the run
    (the Tabor number, the solver, the grids, memory and expected time).  ``keep`` (a file path, or None): where each
    finished grid is kept (:func:`_checkpoint`), so a killed run of the same design resumes from it."""
    from tengsim.run.plan import ResolveSettings, as_plan
    from tengsim.design.curves import summarize
    from tengsim.design.write import to_dataset
    from tengsim.run.resolve import resolve_plan

    import time

    started = time.monotonic()
    preflight(plan)
    cplan = dataclasses.replace(as_plan(plan.contact_table if plan.contact_plan is None else plan.contact_plan),
                                tol=solver_tol(plan))  # the plan plan_design built (planned once)
    cplan = choose_solver(plan, cplan, progress)
    dx = start_dx(plan, cplan)
    _say(progress, f"{plan.name}: Tabor number {cplan.tabor:.3g} (from eps = {plan.eps * 1e9:.3g} nm), "
                   f"lateral unit {cplan.scaling.lateral * 1e9:.3g} nm")
    if cplan.solver_note:
        _say(progress, cplan.solver_note)
    d_max, coarse = find_d_max(plan, cplan, dx, progress,  # the path's range and iterations, on a cheap grid
                               guard=_deadline(None, plan, keep, started))
    est = estimate(plan, cplan, dx, d_max, coarse)
    for line in est.lines():
        _say(progress, line)
    base = identity(plan)
    later = _kept_path(keep, base)
    if later is not None and later > d_max:  # killed in its second pass: go on on that pass's path
        d_max = later
    max_pixels = plan.max_pixels or budget_pixels(plan, cplan, dx, d_max, coarse)
    check_budget(plan, est, max_pixels)
    _say(progress, cap_line(plan, cplan, dx, d_max, max_pixels, coarse))
    res = None
    for attempt in range(2):
        from tengsim.continuation import PathSpec

        path = PathSpec(D_MIN, d_max, D_STEP, adaptive=True)
        ck, found = _checkpoint(keep, base, d_max, progress) or (None, None)
        res = resolve_plan(dataclasses.replace(cplan, path=path, resolve=ResolveSettings(plan.tol, max_pixels, dx)),
                           observe=_observer(plan), watch=_watcher(plan),
                           path_for=grid_path(plan, d_max, cut=attempt == 0),
                           progress=_deadline(progress, plan, keep, started),
                           checkpoint=None if ck is None else ck.save, start=found)
        if res.scaling is None:  # every grid taken back from the checkpoint file, which keeps the columns only
            res = dataclasses.replace(res, scaling=cplan.scaling)
        ok, D_hit, top, slope = _reach(res, plan.pressures[-1])
        if ok:
            break
        d_max = 1.2 * d_max + 2.0
    else:
        raise TengsimError(f"the approach reached only {top / 1e3:.4g} kPa of p_max = {plan.pressures[-1] / 1e3:.4g} "
                           f"kPa on the finest grid, walked to D = {d_max:.4g} ε "
                           f"({d_max * cplan.scaling.eps * 1e6:.3g} µm) on every grid: give a lower p_max")
    summary, conv, notes = summarize(res, plan)
    maps, depths = (res, maps_asked(res, plan)) if plan.maps and res.maps else (None, {})
    summary["map_pressures_asked"] = tuple(depths.items())
    return DesignResult(plan, to_dataset(res, plan, summary), summary, conv, res, tuple(notes), maps)
