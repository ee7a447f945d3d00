"""Run a design: the grid chosen and said, the path extended to the pressures asked for, the grid refined to tol.

:func:`run_design` (a :class:`tengsim.design.plan.DesignPlan` → :class:`DesignResult`):

1. **Grid.**  The first dx is the user's (a length) or :func:`tengsim.resolve.default_dx` (the law's
   process zone over the pixels the status asks for, and the pixel-snap limit).  Before anything runs,
   :func:`estimate` prints the grids (first, and the next two of √2 refinement), the memory of the finest
   and an estimated time: :data:`SECONDS_PER_PIXEL_ROW` × pixels × rows per grid (docs/benchmarks.md, "Design
   time constant"); an estimate above the plan's budget is refused (a :class:`tengsim.errors.TengsimError`
   naming max_pixels and tol) before anything is solved or written.
2. **Path.**  An adaptive D walk (:class:`tengsim.path.PathSpec`) from D = -1 ε to a d_max found on a grid
   twice as coarse as the first: from 1.2 × the structure's height (+2 ε), extended in chunks (the last
   rows' dP/dD, extrapolated to 1.3 × the pressure still missing) until the approach reaches p_max, at most
   :data:`EXTEND_TRIES` times; else an error naming the highest pressure reached, in kPa.
3. **Refinement.**  :func:`tengsim.resolve.resolve_contact` on dx, dx/√2, ... until the charged-area
   fraction A/S on the approach at every asked pressure, the pull-off force and the jump D values change by
   at most tol between the last two grids (and their Richardson error is within tol).  If the finest grid
   does not reach p_max (a finer grid is softer), d_max grows and the refinement runs again (once).
4. **Maps.**  The finest grid's approach is walked again (approach only, the same path lattice) up to the D at
   which it reaches the asked pressures nearest 10 %, 50 % and 100 % of p_max, keeping the pressure and gap
   maps exactly there (``maps = false``: skipped; about half the finest grid's time).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from tengsim.errors import TengsimError

SECONDS_PER_PIXEL_ROW = 1.1e-5
"""Wall seconds per (pixel of the solved block) × (path row), one core: measured on the 2-core build machine
(docs/benchmarks.md, 'Design time constant'); used for the printed estimate only."""
D_MIN = -1.0
D_STEP = 0.4
"""Largest D step (ε) of the adaptive walk (refine_levels 4: smallest 0.025 ε)."""
ROWS_PER_STEP = 2.9
"""Path rows per d_step of D range, approach and retraction together (measured: adaptive steps)."""
LEVELS_ESTIMATED = 3
EXTEND_TRIES = 6


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


def start_dx(plan, cplan) -> float:
    """The first grid's dx in X units: the plan's (a length) or the default from the law's process zone."""
    from tengsim.resolve import default_dx

    if plan.dx is not None:
        return plan.dx / cplan.scaling.lateral
    return default_dx(cplan.shape, cplan.law, cplan.tabor**1.5, cplan.boundary)


def height_eps(cplan, dx) -> float:
    """The structure's height in ε (the range of its gap U0 on the grid)."""
    U0 = cplan.shape.gap(cplan.shape.grid(dx))
    return float(np.nanmax(U0) - np.nanmin(U0))


@dataclass(frozen=True)
class Estimate:
    grids: tuple  # ((nx, ny, dx_m), ...)
    memory_bytes: int
    seconds: float
    d_max: float

    def lines(self) -> list:
        from tengsim.design.units import bytes_text, length_text, time_text

        g = ", ".join(f"{nx}×{ny} (dx {length_text(d)})" for nx, ny, d in self.grids)
        return [f"grids: {g} (refined by √2 until converged; the last two are used only if needed)",
                f"memory: {bytes_text(self.memory_bytes)} on the finest; estimated time: {time_text(self.seconds)} "
                f"(all {len(self.grids)} grids, D path to about {self.d_max:.0f} ε)"]


def estimate(plan, cplan, dx: float, d_max: float) -> Estimate:
    """Grids, memory and time of the refinement (module doc, step 1)."""
    from tengsim.resources import estimate_bytes

    grids, secs = [], 0.0
    rows = ROWS_PER_STEP * (d_max - D_MIN) / D_STEP
    for k in range(LEVELS_ESTIMATED):
        g = cplan.shape.grid(dx / math.sqrt(2.0) ** k)
        if plan.max_pixels is not None and g.nx * g.ny > plan.max_pixels and grids:
            break
        grids.append((g.nx, g.ny, g.dx * cplan.scaling.lateral))
        secs += SECONDS_PER_PIXEL_ROW * _blocks(cplan.shape, g) * rows
    nx, ny, _ = grids[-1]
    return Estimate(tuple(grids), estimate_bytes(nx, ny, cplan.boundary, cplan.solver), secs, d_max)


def budget_pixels(plan, cplan, dx: float, d_max: float) -> int:
    """The largest grid (nx·ny) the refinement may reach within the plan's time budget (the estimate summed
    over the grids dx, dx/√2, ... up to it): the default max_pixels, so no default run runs past its budget."""
    rows = ROWS_PER_STEP * (d_max - D_MIN) / D_STEP
    secs, k, top = 0.0, 0, 9
    while k < 12:
        g = cplan.shape.grid(dx / math.sqrt(2.0) ** k)
        secs += SECONDS_PER_PIXEL_ROW * _blocks(cplan.shape, g) * rows
        if secs > plan.budget_s and k > 0:
            break
        top = g.nx * g.ny
        k += 1
    return top


def cap_line(plan, cplan, dx: float, d_max: float, cap: int) -> str:
    """What the refinement costs at most: the grids dx, dx/√2, ... up to ``cap`` pixels, and their summed estimate."""
    from tengsim.design.units import time_text

    rows = ROWS_PER_STEP * (d_max - D_MIN) / D_STEP
    secs, last = 0.0, None
    for k in range(16):
        g = cplan.shape.grid(dx / math.sqrt(2.0) ** k)
        if g.nx * g.ny > cap and last is not None:
            break
        secs += SECONDS_PER_PIXEL_ROW * _blocks(cplan.shape, g) * rows
        last = g
    return (f"at most: refinement up to {last.nx}×{last.ny} (the budget's largest grid; --max-pixels sets it), "
            f"about {time_text(secs)} in all")


def check_budget(plan, est: Estimate, fit_pixels: int | None = None) -> None:
    """Refuse an estimate over the plan's budget, naming what to change: a max_pixels that fits (when the
    first two grids do) or a coarser dx."""
    from tengsim.design.units import length_text, time_text

    if est.seconds <= plan.budget_s:
        return
    two = est.grids[1][0] * est.grids[1][1] if len(est.grids) > 1 else None
    what = f"a coarser --dx (the first grid's is {length_text(est.grids[0][2])})"
    if fit_pixels and two and fit_pixels >= two:
        what = f"--max-pixels {fit_pixels} (the grids that fit the budget), {what}"
    raise TengsimError(f"this design is estimated at {time_text(est.seconds)}, over the budget of "
                       f"{time_text(plan.budget_s)}: give {what}, a coarser --tol (now {plan.tol:g}) or a larger "
                       "--budget")


def _simulate(cplan, dx, d_max, **kw):
    from tengsim.contact import simulate
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


def find_d_max(plan, cplan, dx, progress=None):
    """(d_max, the coarse result): the D range that reaches p_max on a grid twice as coarse as the first
    (module doc, step 2)."""
    from tengsim.design.units import pressure_text

    p_max = plan.pressures[-1]
    coarse = 2 * dx
    d_max = 1.2 * height_eps(cplan, dx) + 2.0
    for _ in range(EXTEND_TRIES):
        res = _simulate(cplan, coarse, d_max)
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
    from tengsim.study.observe import load_control

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


def maps_run(res, cplan, plan):
    """The finest grid's approach walked again up to the map depths (:func:`map_depths`), its pressure and gap
    maps kept exactly there (the same path lattice: the same states); None if no depth is known."""
    from tengsim.contact import simulate
    from tengsim.continuation import PathSpec

    depths = map_depths(res, plan)
    if not depths:
        return None, {}
    top = max(depths) + D_STEP
    path = PathSpec(D_MIN, top, D_STEP, adaptive=True, retract=False, maps_at=tuple(sorted(depths)))
    out = simulate(cplan.shape, cplan.tabor, res.grid.dx, path, boundary=cplan.boundary, solver=cplan.solver,
                   tol=cplan.tol, law=cplan.law, extra_params=cplan.extra, scaling=cplan.scaling, grid=res.grid,
                   kernel_params=cplan.kernel_params, symmetry=cplan.symmetry)
    return out, depths


def area_name(branch: str, p: float) -> str:
    return f"A_S_{branch[:3]}_{p:.6g}Pa".replace("+", "").replace(".", "p")


def _observer(plan):
    from tengsim.design.curves import branch_curves

    def observe(res) -> dict:
        c = branch_curves(res, plan)
        return {area_name("approach", p): float(a) for p, a in zip(plan.pressures, c["approach"]["area"])}

    return observe


def _checkpoint(keep, plan, d_max, progress):
    """The refinement's checkpoint in the file ``keep`` for this plan and path (None without ``keep``): each
    finished grid is kept there, and a run of the same design and path takes its grids back instead of computing
    them again; one kept by another design is replaced (said)."""
    if keep is None:
        return None
    import hashlib

    from tengsim.errors import TengsimError as _Err
    from tengsim.resolve import Checkpoint

    ck = Checkpoint(keep, hashlib.sha256(f"{plan!r}|{d_max!r}".encode()).hexdigest()[:16])
    try:
        found = ck.load()
    except _Err:
        _say(progress, f"{keep} holds grids of another design or path: they are replaced")
        keep.unlink()
        found = None
    if found is not None:
        _say(progress, f"taking back {len(found[0])} finished grid(s) from {keep}")
    keep.parent.mkdir(parents=True, exist_ok=True)
    return ck, found


def run_design(plan, progress=None, keep=None) -> DesignResult:
    """Run one design (module doc).  ``progress``: a :class:`tengsim.progress.Progress`-like callable (the
    path's progress) and/or an object with ``say(text)``, which gets the lines said before and during the run
    (the Tabor number, the grids, memory and estimated time).  ``keep`` (a file path, or None): where each
    finished grid is kept (:func:`_checkpoint`), so a killed run of the same design resumes from it."""
    from tengsim.config import plan_contact
    from tengsim.design.curves import summarize
    from tengsim.design.write import to_dataset
    from tengsim.resolve import resolve_contact

    cplan = plan_contact(plan.contact_table)
    dx = start_dx(plan, cplan)
    est = estimate(plan, cplan, dx, 1.2 * height_eps(cplan, dx) + 2.0)
    _say(progress, f"{plan.name}: Tabor number {cplan.tabor:.3g} (from eps = {plan.eps * 1e9:.3g} nm), "
                   f"lateral unit {cplan.scaling.lateral * 1e9:.3g} nm")
    for line in est.lines():
        _say(progress, line)
    check_budget(plan, est, plan.max_pixels or budget_pixels(plan, cplan, dx, est.d_max))
    d_max, coarse = find_d_max(plan, cplan, dx, progress)
    max_pixels = plan.max_pixels or budget_pixels(plan, cplan, dx, d_max)
    _say(progress, cap_line(plan, cplan, dx, d_max, max_pixels))
    res = None
    for _ in range(2):
        from tengsim.continuation import PathSpec

        path = PathSpec(D_MIN, d_max, D_STEP, adaptive=True)
        ck, found = _checkpoint(keep, plan, d_max, progress) or (None, None)
        res = resolve_contact(cplan.shape, cplan.tabor, path, dx=dx, law=cplan.law, boundary=cplan.boundary,
                              resolve_tol=plan.tol, max_pixels=max_pixels, observe=_observer(plan),
                              progress=progress if callable(progress) else None, symmetry=cplan.symmetry,
                              solver=cplan.solver, tol=cplan.tol,
                              extra_params=cplan.extra, scaling=cplan.scaling, kernel_params=cplan.kernel_params,
                              checkpoint=None if ck is None else ck.save, start=found)
        if res.scaling is None:  # every grid taken back from the checkpoint file, which keeps the columns only
            res.scaling = cplan.scaling
        ok, D_hit, top, slope = _reach(res, plan.pressures[-1])
        if ok:
            break
        d_max = 1.2 * d_max + 2.0
    else:
        raise TengsimError(f"the approach reached only {top / 1e3:.4g} kPa of p_max = {plan.pressures[-1] / 1e3:.4g} "
                           f"kPa on the finest grid: give a lower p_max")
    summary, conv, notes = summarize(res, plan)
    maps, depths = maps_run(res, cplan, plan) if plan.maps else (None, {})
    summary["map_pressures_asked"] = tuple(depths.items())
    return DesignResult(plan, to_dataset(res, plan, summary), summary, conv, res, tuple(notes), maps)
