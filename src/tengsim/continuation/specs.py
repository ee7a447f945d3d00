"""Path specifications: :class:`PathSpec` (the rigid approach D is the control) and :class:`LoadPathSpec`
(the total force F is the control, D an unknown of each equilibrium).  Frozen, validated at construction.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tengsim.errors import TengsimError, finite, positive


BRANCHES = ("approach", "retraction")
"""The branches of a path, in path order: the load (D or F) going up, then back down."""

_D_TOL = 1e-9
"""Relative tolerance (of max(1, |D|)) within which a row's D is a requested ``maps_at`` D."""


@dataclass(frozen=True)
class PathSpec:
    """Approach from ``d_min`` to ``d_max`` then retraction back, in steps of ``d_step``.

    Every branch has a row at each D = d_min + k·d_step; step refinement only adds rows between.
    ``maps_at`` lists D values whose pressure and gap maps are kept, on both branches, each exactly at
    its D: a value off the rows the walk visits gets an extra row there (``on_grid`` False: ``on_grid``
    keeps meaning "on the d_step lattice"), solved from the two rows around it on the branch (their
    states interpolated; across a jump, from the state before it), without entering the continuation,
    so every other row is the one the run has without ``maps_at``.  A value outside [d_min, the last D
    of the lattice] is refused.

    ``adaptive=True``: the step h takes the values d_step/2^k (k = 0 … ``refine_levels``) and stays on
    the lattice D = d_min + j·d_step/2^k, so every row lies on the finest lattice and every
    D = d_min + k·d_step is still visited (those rows keep ``on_grid`` True: they are the rows a
    fixed-step run with the same ``d_step`` has; the others are the adaptive run's own).  After each
    step the solved state is compared with the linear extrapolation of the two before it (the
    secant predictor): the force error e_F = |F − F_pred| against ``adapt_tol`` × max(|F|, the most
    tensile |F| met so far on the path), and the gap error max|H − H_pred| (ε) against
    ``adapt_h``.  A step whose larger ratio ρ exceeds 1 keeps its (exact) end state and is refined by
    midpoints (recursively, each half judged by the midpoint's deviation from the chord), and the
    next step is divided by 2^⌈log₄ ρ⌉ (the error goes as h²); ρ < 1/4 lets the next step double
    (where the lattice allows).  The same second difference, centred on the step's start, also
    judges the step before it (look-back), which is refined the same way; each branch starts with
    d_step (its second step's look-back judges it).  Jumps are bisected to the smallest step as in
    the fixed scheme (a step that jumps is retried at half its length).  With refine_levels three
    above a fixed run's and d_step eight times its d_step, the smallest steps (and so the jump
    resolution) agree.  How closely the defaults (adapt_tol = 0.15, adapt_h = 0.5) reproduce the fixed
    curve, and with how many fewer solves: docs/validation.md, "Continuation".

    ``stop_force`` (F's units, None: none): the approach ends at the step after its first row whose F reaches
    it (once past every ``maps_at`` D), short of d_max; the retraction walks back from there (its first row is
    off the lattice unless that D is on it).  A design's grids stop there at p_max (tengsim.run.reach).
    """

    d_min: float
    d_max: float
    d_step: float
    refine_levels: int = 4
    jump_h: float = 0.3
    predictor: bool = True
    retract: bool = True
    maps_at: tuple = ()
    adaptive: bool = False
    adapt_tol: float = 0.15
    adapt_h: float = 0.5
    stop_force: float | None = None

    def __post_init__(self):
        finite("d_min", self.d_min)
        if self.stop_force is not None:
            finite("stop_force", self.stop_force)
        finite("d_max", self.d_max)
        positive("d_step", self.d_step)
        if not self.d_max > self.d_min:
            raise TengsimError(f"d_max ({self.d_max}) must be greater than d_min ({self.d_min})")
        n = (self.d_max - self.d_min) / self.d_step
        if n > 200000:
            raise TengsimError(f"d_step={self.d_step} gives {n:.0f} steps; choose a larger step")
        if int(self.refine_levels) < 0:
            raise TengsimError(f"refine_levels must be >= 0, got {self.refine_levels!r}")
        object.__setattr__(self, "maps_at", tuple(finite("maps_at", d) for d in self.maps_at))
        last = float(self.targets()[-1])
        for d in self.maps_at:
            if not self.d_min - _D_TOL * max(1.0, abs(d)) <= d <= last + _D_TOL * max(1.0, abs(d)):
                raise TengsimError(f"maps_at D = {d:g} is outside the path's D range [{self.d_min:g}, {last:g}]"
                                   + (f" (the last D of the d_step lattice below d_max = {self.d_max:g})"
                                      if last < self.d_max - 1e-9 else ""))
        positive("adapt_tol", self.adapt_tol)
        positive("adapt_h", self.adapt_h)
        if self.adaptive and int(self.refine_levels) > 30:
            raise TengsimError(f"refine_levels must be <= 30 with adaptive steps, got {self.refine_levels!r}")

    def extra_params(self) -> dict:
        """Path parameters beyond d_min, d_max, d_step, refine_levels, jump_h (none for fixed steps)."""
        out = {"stop_force": float(self.stop_force)} if self.stop_force is not None else {}
        if not self.adaptive:
            return out
        return {"adaptive": True, "adapt_tol": self.adapt_tol, "adapt_h": self.adapt_h, **out}

    def targets(self) -> np.ndarray:
        k = int(np.floor((self.d_max - self.d_min) / self.d_step + 1e-9))
        return self.d_min + self.d_step * np.arange(k + 1)


@dataclass(frozen=True)
class LoadPathSpec:
    """Load from ``f_min`` up to ``f_max`` then back, in steps of ``f_step`` (F of Eq. 10).

    The approach starts at rest at D = ``d_min``; D is searched within [``d_min``, ``d_max``] by a
    walk of step ``d_step`` (jumps bisected ``refine_levels`` times, gap criterion ``jump_h`` as
    in :class:`tengsim.continuation.PathSpec`).  ``f_tol``: accepted |F − target| (default 1e-4 f_step).
    Rows at the targets have ``on_grid`` True; fold, landing and separation rows have it False.
    ``maps_at`` lists loads whose maps are kept: a load off the f_step lattice becomes an extra target
    on both branches (its row has ``on_grid`` False), so its map is of the state at that load; a load
    outside [f_min, the last load of the lattice] is refused.  A load with no state on a branch (on the
    approach below the load at rest, on the retraction past the pull-off) has no map there.
    A target whose regula falsi ends (``max_root_steps`` steps, or a D bracket narrower than 1e-12)
    with |F − target| > ``f_tol`` is recorded with ``converged`` False (status not_converged), and the
    result's ``params['load_not_met']`` names each such load, its branch and D bracket.
    """

    f_min: float
    f_max: float
    f_step: float
    d_min: float = -1.0
    d_max: float = 20.0
    d_step: float = 0.05
    refine_levels: int = 4
    jump_h: float = 0.3
    f_tol: float | None = None
    retract: bool = True
    maps_at: tuple = ()
    extend: bool = False
    pa_per_F: float | None = None
    eps_m: float | None = None
    to_max: bool = False
    """``to_max``: f_max is a load of the path even where f_max - f_min is no multiple of f_step (the last
    step is then shorter), so the path ends at the load asked for.  ``extend``: the approach's search in D goes on past ``d_max`` (the span d_max - d_min doubled at each
    reach, up to :data:`EXTEND_LIMIT` times the first span) until the load is met, so no d_max is to be
    guessed.  ``pa_per_F`` (Pa per unit of F) and ``eps_m`` (m per ε): a physical run's units, in which
    its errors name the loads and D."""

    def __post_init__(self):
        finite("f_min", self.f_min)
        finite("f_max", self.f_max)
        positive("f_step", self.f_step)
        finite("d_min", self.d_min)
        finite("d_max", self.d_max)
        positive("d_step", self.d_step)
        if not self.f_max > self.f_min:
            raise TengsimError(f"f_max ({self.f_max}) must be greater than f_min ({self.f_min})")
        if not self.d_max > self.d_min:
            raise TengsimError(f"d_max ({self.d_max}) must be greater than d_min ({self.d_min})")
        if (self.f_max - self.f_min) / self.f_step > 100000:
            raise TengsimError(f"f_step={self.f_step} gives too many load steps; choose a larger step")
        if int(self.refine_levels) < 0:
            raise TengsimError(f"refine_levels must be >= 0, got {self.refine_levels!r}")
        if self.f_tol is not None:
            positive("f_tol", self.f_tol)
        object.__setattr__(self, "maps_at", tuple(finite("maps_at", f) for f in self.maps_at))
        last = float(self.targets()[-1])
        tol = 1e-9 * self.f_step
        for f in self.maps_at:
            if not self.f_min - tol <= f <= last + tol:
                raise TengsimError(f"maps_at load F = {f:g} is outside the path's load range [{self.f_min:g}, "
                                   f"{last:g}]" + (f" (the last load of the f_step lattice below f_max = "
                                                   f"{self.f_max:g})" if last < self.f_max - tol else ""))

    @property
    def tol_F(self) -> float:
        return self.f_tol if self.f_tol is not None else 1e-4 * self.f_step

    def targets(self) -> np.ndarray:
        k = int(np.floor((self.f_max - self.f_min) / self.f_step + 1e-9))
        t = self.f_min + self.f_step * np.arange(k + 1)
        if self.to_max and t[-1] < self.f_max - 1e-9 * self.f_step:
            t = np.append(t, self.f_max)
        return t

    def path_targets(self) -> list:
        """The loads the path visits, in increasing order: [(F, on the f_step lattice)], the lattice and the
        ``maps_at`` loads off it."""
        lattice = [(float(f), True) for f in self.targets()]
        tol = 1e-9 * self.f_step
        extra = [(f, False) for f in sorted(set(self.maps_at)) if all(abs(f - g) > tol for g, _ in lattice)]
        return sorted(lattice + extra)

    def load_text(self, F: float) -> str:
        """A load as the user gave it: 'p kPa (F = f)' in a physical run, 'F = f' otherwise."""
        if self.pa_per_F is None:
            return f"F = {F:.6g}"
        from tengsim.units import format_si

        return f"{format_si(F * self.pa_per_F, 'Pa', 4)} (F = {F:.6g})"

    def d_text(self, D: float) -> str:
        """D in ε, with its length in a physical run."""
        if self.eps_m is None:
            return f"{D:.6g}"
        from tengsim.units import format_si

        return f"{D:.6g} ε ({format_si(D * self.eps_m, 'm', 4)})"

    def extra_params(self) -> dict:
        return {"control": "load", "f_min": self.f_min, "f_max": self.f_max, "f_step": self.f_step,
                "f_tol": self.tol_F}


EXTEND_LIMIT = 64
"""With ``extend``, the D search of a load stops at d_min + EXTEND_LIMIT (d_max - d_min)."""
