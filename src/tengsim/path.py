"""Continuation in the rigid approach D: approach (D up) then retraction (D down), paper Section 2.

Each equilibrium is warm-started from the previous one on its branch (with a secant predictor), so
the path follows the stable branch and shows jump-in, jump-out and hysteresis as the paper's VSR
does.  Step control: when the gap field changes by more than ``jump_h`` (in ε, beyond the rigid
shift |ΔD|) across a step, the step is bisected, up to ``refine_levels`` times; a change that
survives the finest step is recorded as a jump.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from tengsim.analysis import apex_index
from tengsim.errors import TengsimError, finite, positive
from tengsim.solvers import Problem, State
from tengsim.status import process_zone_width


@dataclass(frozen=True)
class PathSpec:
    """Approach from ``d_min`` to ``d_max`` then retraction back, in steps of ``d_step``.

    Every branch has a row at each D = d_min + k·d_step; step refinement only adds rows between.
    ``maps_at`` lists D values whose pressure and gap maps are kept (on both branches).
    """

    d_min: float
    d_max: float
    d_step: float
    refine_levels: int = 4
    jump_h: float = 0.3
    predictor: bool = True
    retract: bool = True
    maps_at: tuple = ()

    def __post_init__(self):
        finite("d_min", self.d_min)
        finite("d_max", self.d_max)
        positive("d_step", self.d_step)
        if not self.d_max > self.d_min:
            raise TengsimError(f"d_max ({self.d_max}) must be greater than d_min ({self.d_min})")
        n = (self.d_max - self.d_min) / self.d_step
        if n > 200000:
            raise TengsimError(f"d_step={self.d_step} gives {n:.0f} steps; choose a larger step")
        if int(self.refine_levels) < 0:
            raise TengsimError(f"refine_levels must be >= 0, got {self.refine_levels!r}")
        object.__setattr__(self, "maps_at", tuple(float(d) for d in self.maps_at))

    def targets(self) -> np.ndarray:
        k = int(np.floor((self.d_max - self.d_min) / self.d_step + 1e-9))
        return self.d_min + self.d_step * np.arange(k + 1)


@dataclass
class _Row:
    branch: str
    D: float
    on_grid: bool
    jump: bool
    eq: object


class _Branch:
    """Walks one branch, refining steps and predicting starts."""

    def __init__(self, U0, law, kernel, solver, spec, on_row):
        self.U0, self.law, self.kernel, self.solver, self.spec = U0, law, kernel, solver, spec
        self.on_row = on_row
        self.hist: list = []  # accepted (D, state) on this branch, newest last

    def solve(self, D, start):
        return self.solver.solve(Problem(self.U0 - D + 1.0, self.law, self.kernel), start)

    def _start(self, D):
        (D1, s1) = self.hist[-1]
        if self.spec.predictor and len(self.hist) >= 2:
            D0, s0 = self.hist[-2]
            if D1 != D0:
                c = (D - D1) / (D1 - D0)
                if 0 < c <= 1.5:
                    return State(s1.q + c * (s1.q - s0.q), s1.w + c * (s1.w - s0.w)), True
        return s1, False

    def _jumped(self, eqa, eqb, dD):
        return float(np.max(np.abs(eqb.H - eqa.H))) - abs(dD) > self.spec.jump_h

    def advance(self, Da, eqa, Db, level, on_grid):
        start, predicted = self._start(Db)
        eqb = self.solve(Db, start)
        if predicted and self._jumped(eqa, eqb, Db - Da):
            eqb = self.solve(Db, eqa.state)  # confirm without the predictor
        if self._jumped(eqa, eqb, Db - Da):
            if level < self.spec.refine_levels:
                mid = 0.5 * (Da + Db)
                eqm = self.advance(Da, eqa, mid, level + 1, False)
                return self.advance(mid, eqm, Db, level + 1, on_grid)
            jump = True
        else:
            jump = False
        self.hist = (self.hist + [(Db, eqb.state)])[-2:]
        if jump:
            self.hist = self.hist[-1:]
        self.on_row(Db, eqb, on_grid, jump)
        return eqb


def run_path(U0, law, kernel, solver, spec: PathSpec, start: State | None = None,
             progress=None, keep_states: bool = False, observers=()):
    """Solve the approach–retraction path; returns a :class:`tengsim.results.ContactResult`.

    ``progress(branch, D, done, total)`` is called after each row on the D grid.  ``observers``
    (registered names or objects, see :mod:`tengsim.observers`) add their columns to every row.
    """
    from tengsim import observers as obs
    from tengsim.results import CURVE_COLUMNS, PHYSICAL_COLUMNS, ContactResult

    grid = kernel.grid
    U0 = np.asarray(U0, dtype=float)
    if U0.shape != grid.shape:
        raise TengsimError(f"U0 shape {U0.shape} does not match the grid {grid.shape}")
    if not np.all(np.isfinite(U0)):
        raise TengsimError("the initial gap U0 contains NaN or infinite values")
    apex = apex_index(U0)
    summary = obs.Summary()
    extra = obs.resolve(observers)
    extra_cols = obs.check_columns(extra, CURVE_COLUMNS + PHYSICAL_COLUMNS)
    ctx = obs.Context(grid, apex, U0, law, kernel)
    targets = spec.targets()
    total = len(targets) * (2 if spec.retract else 1)
    rows, maps, done = [], [], [0]
    map_keys = set()
    t_start = time.perf_counter()

    def make_on_row(branch):
        def on_row(D, eq, on_grid, jump):
            s = summary(eq, ctx)
            # a state whose gap enters the law's safe extension (g < g_safe) is outside the physical law
            in_range = bool(s["min_gap"] + 1.0 >= getattr(law, "g_safe", -np.inf))
            more = {}
            for o in extra:
                more.update(obs.observe(o, eq, ctx))
            rows.append(dict(branch=branch, D=D, on_grid=on_grid, jump=jump, converged=eq.converged,
                             in_law_range=in_range,
                             process_zone=process_zone_width(eq.H, grid.dx, apex, law),
                             residual=eq.residual, iterations=eq.iterations, n_conv=eq.n_conv,
                             seconds=eq.seconds, energy=eq.energy, **s, **more))
            for Dm in spec.maps_at:
                if on_grid and abs(D - Dm) < 1e-9 * max(1.0, abs(Dm)) + 1e-9 and (branch, Dm) not in map_keys:
                    map_keys.add((branch, Dm))
                    maps.append(dict(branch=branch, D=D, P=eq.P.copy(), H=eq.H.copy()))
            if on_grid:
                done[0] += 1
                if progress:
                    progress(branch, D, done[0], total)
        return on_row

    state = start if start is not None else State.zero(grid.shape)
    walker = _Branch(U0, law, kernel, solver, spec, make_on_row("approach"))
    eq = walker.solve(targets[0], state)
    walker.hist = [(targets[0], eq.state)]
    walker.on_row(targets[0], eq, True, False)
    for Da, Db in zip(targets[:-1], targets[1:]):
        eq = walker.advance(Da, eq, Db, 0, True)
    if spec.retract:
        back = _Branch(U0, law, kernel, solver, spec, make_on_row("retraction"))
        back.hist = [(targets[-1], eq.state)]
        back.on_row(targets[-1], eq, True, False)
        rev = targets[::-1]
        for Da, Db in zip(rev[:-1], rev[1:]):
            eq = back.advance(Da, eq, Db, 0, True)
    res = ContactResult.from_rows(rows, maps, grid, seconds=time.perf_counter() - t_start,
                                  final_state=eq.state if keep_states else None, extra_columns=extra_cols)
    for o in extra:
        res.units.update(getattr(o, "units", None) or {})
    return res
