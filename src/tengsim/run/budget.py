"""What a refinement costs: its expected time, the worst case up to its budget, the budget's checks.

``ask`` (below) is what was asked of the refinement: any object with ``name``, ``budget_s`` (s), ``tol`` and
``max_pixels`` (a :class:`tengsim.design.plan.DesignPlan`).  After the coarse pre-run
(:func:`tengsim.run.reach.find_d_max`: the path's range and the solver's iterations per
row, on a cheap grid) and before the refinement, :func:`estimate` gives the grids (the refinement's first ones,
:func:`estimated_grids`), the memory of the finest (counted by :func:`tengsim.run.refine.preflight`), the solver
``auto`` chose and the expected time, each grid rows × iterations × the backend's cost per iteration (:class:`Cost`,
:mod:`tengsim.resources`: the CPU's or the GPU's model, named in the line); :func:`cap_line` the worst case up to
the budget's largest grid (:func:`budget_pixels`).  An expected time above the budget asked is refused
(:func:`check_budget`, a :class:`tengsim.errors.TengsimError` naming max_pixels and tol) before the refinement is
solved or anything written; a run past its budget is stopped between two rows (:func:`deadline`, :class:`BudgetSpent`).
"""
from __future__ import annotations

import itertools
import os
import time
from dataclasses import dataclass

import numpy as np

from tengsim.run.reach import D_MIN, D_STEP
from tengsim.errors import BudgetExceeded
from tengsim.resources import CostModel, cost_model

ROWS_PER_STEP = 2.0
"""Path rows per d_step of D range on each grid, approach and retraction together (the first grid walks to d_max,
each finer one to a little past where the grid before reached p_max; docs/benchmarks.md, "Design estimates")."""
ITERATIONS_PER_COARSE = 4.0
"""A refinement grid's solver iterations per path row over the coarse pre-run's mean (:func:`find_d_max`;
docs/benchmarks.md, "Design estimates")."""
LEVELS_ESTIMATED = 4
"""Grids of the refinement the expected run counts: most designs converge on their fourth grid, some on their
second (docs/benchmarks.md, "Design estimates")."""
LAST_GRID_SHARE = 0.5
"""The weight of the last grid counted (:data:`LEVELS_ESTIMATED`) in the expected run: designs that converge
earlier do not walk it (docs/benchmarks.md, "Design estimates")."""


def _blocks(shape, grid) -> int:
    """Pixels of the solved block (a quarter of the grid for a shape mirrored in x and y on an odd grid)."""
    axes = [a for a in getattr(shape, "mirror_axes", ()) or () if grid.shape[a] % 2 == 1]
    n = grid.nx * grid.ny
    return n // (2 ** len(axes)) if axes else n

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


def on_gpu(cplan, grid=None) -> bool:
    """Whether the plan's solver runs on a GPU on ``grid`` (None: the plan's own): 'gpu', 'jax' where JAX sees
    one, or 'auto' where it chooses the GPU on that grid (:func:`tengsim.run.plan.chosen_solver`)."""
    from tengsim.run.plan import chosen_solver
    from tengsim.solvers.choice import gpu_visible

    name = cplan.solver if isinstance(cplan.solver, str) else getattr(cplan.solver, "name", "")
    if name.strip().lower() == "auto":
        name = chosen_solver(cplan, grid)[0]
    return name == "gpu" or (name == "jax" and gpu_visible()) or getattr(cplan.solver, "device", "") == "gpu"


def run_cost(cplan, d_max: float, coarse=None, retract: bool = True, grid=None) -> Cost:
    """The :class:`Cost` of a design's grids: rows from the path's D range (:data:`ROWS_PER_STEP`; half of them
    without the retraction, ``retract`` false), iterations per row from the coarse pre-run ``coarse``
    (× :data:`ITERATIONS_PER_COARSE`; 20 per row without one)."""
    its = 20.0
    if coarse is not None:
        it = np.asarray(coarse.table.get("iterations", ()), dtype=float)
        if it.size and np.isfinite(it).all():
            its = float(np.mean(it))
    gpu = on_gpu(cplan, grid)  # on the finest grid a refinement expects (``grid``), which its time is mostly
    rows = ROWS_PER_STEP * (d_max - D_MIN) / D_STEP * (1.0 if retract else 0.5)
    return Cost(cost_model(gpu), rows, ITERATIONS_PER_COARSE * its, gpu)


@dataclass(frozen=True)
class Estimate:
    grids: tuple  # ((nx, ny, dx_m), ...)
    memory_bytes: int
    seconds: float
    d_max: float
    backend: str = ""
    cost: Cost | None = None
    least: float = 0.0
    """Seconds of the first two grids alone (a design that converges on its second grid)."""
    busy: tuple = (1.0, 0.0, 1)
    """(factor, 1-minute load, cores) of the machine when the estimate was made (:func:`machine_busy`)."""

    def lines(self) -> list:
        from tengsim.units import bytes_text, length_text, time_text

        g = ", ".join(f"{nx}×{ny} (dx {length_text(d)})" for nx, ny, d in self.grids)
        rows = (f", {self.cost.rows:.0f} rows of about {self.cost.iterations:.0f} iterations per grid"
                if self.cost else "")
        return [f"grids: {g} (refined by √2 until converged; the last two are used only if needed)",
                f"memory: {bytes_text(self.memory_bytes)} on the finest; expected time: {time_text(self.seconds)} "
                f"(the first three grids and half the fourth; {time_text(self.least)} if it converges on the "
                f"second; D path to about {self.d_max:.0f} ε{rows}) on {self.backend}" + self.busy_text()]

    def busy_text(self) -> str:
        """The expected time on this machine as busy as it is now (nothing on a machine that is not)."""
        from tengsim.units import time_text

        factor, load, cores = self.busy
        if factor < BUSY_SAID:
            return ""
        return (f"; this machine is busy (load {load:.1f} on {cores} core{'s' if cores > 1 else ''}): expect about "
                f"{time_text(self.seconds * factor)}")


BUSY_SAID = 1.25
"""The busy factor (:func:`machine_busy`) from which the estimate's line gives the time on the busy machine too."""


def machine_busy() -> tuple:
    """(factor, 1-minute load average, cores this process may use): how much longer a CPU-bound run takes now
    than on an idle machine, ``max(1, load / cores)`` (every runnable process gets an equal share of the cores;
    the design's own pre-run is part of the load).  (1, 0, cores) where the OS gives no load average."""
    import os

    try:
        cores = len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        cores = os.cpu_count() or 1
    try:
        load = os.getloadavg()[0]
    except (AttributeError, OSError):
        return 1.0, 0.0, cores
    return max(1.0, load / cores), load, cores

def estimated_grids(ask, grids) -> list:
    """The grids the expected run counts: the first :data:`LEVELS_ESTIMATED` of ``grids`` (the refinement's
    sequence, :class:`tengsim.run.grids.GridSequence`) within ``ask.max_pixels`` (at least the first)."""
    chosen = []
    for g in itertools.islice(grids, LEVELS_ESTIMATED):  # the grids the refinement walks
        if ask.max_pixels is not None and g.nx * g.ny > ask.max_pixels and chosen:
            break
        chosen.append(g)
    return chosen


def estimate(ask, cplan, grids, d_max: float, cost: Cost, memory_bytes: int = 0) -> Estimate:
    """Grids, memory and expected time of the refinement (module doc): the grids counted (:func:`estimated_grids`),
    the last at :data:`LAST_GRID_SHARE`, at ``cost`` (:func:`run_cost` of the backend the plan solves on, for the D
    range ``d_max``); ``memory_bytes`` the finest's memory, counted with the refinement's other bounds before it
    (:func:`tengsim.run.refine.preflight`)."""
    chosen, secs, least = [], 0.0, 0.0
    for k, g in enumerate(estimated_grids(ask, grids)):
        chosen.append((g.nx, g.ny, g.dx * cplan.scaling.lateral))
        step = cost.grid_seconds(cplan.shape, g)
        secs += step * (LAST_GRID_SHARE if k == LEVELS_ESTIMATED - 1 else 1.0)
        least += step if k < 2 else 0.0
    return Estimate(tuple(chosen), int(memory_bytes), secs, d_max, cost.model.backend, cost, least,
                    (1.0, 0.0, 1) if cost.gpu else machine_busy())


def next_grid_line(shape, grids, seconds: float, lateral: float) -> str:
    """The progress line after a finished grid (the last of ``grids``, the refinement's sequence so far plus the
    next): its measured time and the next grid's, scaled from it by the pixels (a grid's time goes as its pixels),
    which the refinement walks if the last two grids have not converged."""
    from tengsim.units import length_text, time_text

    done, nxt = grids[-2], grids[-1]
    scale = (nxt.nx * nxt.ny) / (done.nx * done.ny)
    return (f"grid {len(grids) - 1} ({done.nx}×{done.ny}, dx {length_text(done.dx * lateral)}) took "
            f"{time_text(seconds)}; the next ({nxt.nx}×{nxt.ny}), if not converged yet: about "
            f"{time_text(seconds * scale)}")


SEQUENCE_COUNTED = 12
"""Grids of the refinement's sequence the budget and the worst case look at (the refinement never walks more)."""


def budget_pixels(ask, shape, grids, cost: Cost) -> int:
    """The largest grid (nx·ny) the refinement may reach within the time budget asked: the last of ``grids`` (the
    refinement's sequence, :func:`tengsim.run.grids.refinement_grids`) whose cost (``cost``, :func:`run_cost`)
    summed with the grids before it fits the budget (at least the first grid); the default max_pixels, so no
    default run runs past its budget."""
    secs, top = 0.0, None
    for g in itertools.islice(grids, SEQUENCE_COUNTED):
        secs += cost.grid_seconds(shape, g)
        if secs > ask.budget_s and top is not None:
            break
        top = g.nx * g.ny
    return top


def cap_line(shape, grids, cost: Cost, cap: int) -> str:
    """The worst case: the refinement's grids (``grids``) up to ``cap`` pixels, and their summed cost."""
    from tengsim.units import time_text

    secs, last = 0.0, None
    for g in itertools.islice(grids, SEQUENCE_COUNTED):
        if g.nx * g.ny > cap and last is not None:
            break
        secs += cost.grid_seconds(shape, g)
        last = g
    return (f"at most: refinement up to {last.nx}×{last.ny} (the budget's largest grid; --max-pixels sets it), "
            f"about {time_text(secs)} in all")


def check_budget(ask, est: Estimate, fit_pixels: int | None = None) -> None:
    """Refuse an expected time over the budget asked, naming what to change: a max_pixels that fits (when the
    first two grids do) or a coarser dx."""
    from tengsim.units import length_text, time_text

    if est.seconds <= ask.budget_s:
        return
    two = est.grids[1][0] * est.grids[1][1] if len(est.grids) > 1 else None
    what = f"a coarser --dx (the first grid's is {length_text(est.grids[0][2])})"
    if fit_pixels and two and fit_pixels >= two:
        what = f"--max-pixels {fit_pixels} (the grids that fit the budget), {what}"
    raise BudgetExceeded(f"this design is expected to take {time_text(est.seconds)} on {est.backend.split(' (')[0]}, "
                         f"over the budget of {time_text(ask.budget_s)}: give {what}, a coarser --tol (now "
                         f"{ask.rel_tol:g}) or a larger --budget", ask.budget_s)

class BudgetSpent(BudgetExceeded):
    """A design stopped at its time budget (what finished is kept; the message says how to go on)."""


@dataclass(frozen=True)
class RunClock:
    """When a run started, by the wall clock and by its own CPU time (this process, all its threads, and its
    children): :meth:`spent` is what its budget counts."""

    wall: float
    cpu: float

    @staticmethod
    def now() -> "RunClock":
        return RunClock(time.monotonic(), cpu_seconds())

    def spent(self, cpu: bool = True) -> float:
        """Seconds the run has spent: its own CPU time, never more than the wall time (a run on a busy machine
        is not charged the time other processes take; a run on several cores not charged more than the
        clock), or the wall time alone (``cpu`` false: a GPU run, whose host waits on the device)."""
        wall = time.monotonic() - self.wall
        return min(wall, cpu_seconds() - self.cpu) if cpu else wall


def cpu_seconds() -> float:
    """CPU seconds of this process (user and system, all threads) and of its children waited for."""
    t = os.times()
    return t.user + t.system + t.children_user + t.children_system


BUDGET_CLOCK = "the run's own CPU time, at most the wall time"
"""How the budget is counted (said in the messages and docs/design.md)."""


def deadline(progress, ask, keep, started, cpu: bool = True):
    """``progress`` (called per path row) that also stops the run, cleanly, once it has spent ``ask.budget_s``
    seconds since ``started`` (a :class:`RunClock`: its own CPU time, :meth:`RunClock.spent`; a bare
    ``time.monotonic()`` value: the wall time): the finished grids stay in ``keep`` and the message says how to
    go on."""
    def spent():
        return started.spent(cpu) if isinstance(started, RunClock) else time.monotonic() - started

    def call(*a, **k):
        if spent() > ask.budget_s:
            from tengsim.units import time_text

            where = (f"the finished grids are kept in {keep}: run the same command with a larger --budget to go "
                     "on from them") if keep is not None and keep.exists() else \
                "no grid had finished: give a larger --budget, a coarser --dx or a coarser --tol"
            clock = BUDGET_CLOCK if isinstance(started, RunClock) and cpu else "the wall time"
            raise BudgetSpent(f"{ask.name[:80]}: stopped at the budget of {time_text(ask.budget_s)} ({clock}); "
                              f"{where}", ask.budget_s)
        if callable(progress):
            return progress(*a, **k)
        return None

    return call
