"""The periodic steady state of a press repeated: one period's history driven again and again, each period from the
memory the one before left, until the cycle repeats (docs/viscoelastic.md, "Memory from one press to the next").

A material whose τ_i is comparable to or longer than the period does not recover between presses: press n ≥ 2
starts from the relaxation state press n − 1 left, and the cycle drifts towards a periodic one over ~τ_i E0/E∞.
Driving that many periods one after another costs τ/T periods; the fixed point of the period map
G (the memory at the start of a period → the memory at its end) is found instead by Anderson acceleration on the
memory fields (q_i, w), each evaluation of G one period driven exactly.  The first ``plain`` periods are the
device's own presses from rest (G applied to the last end); after them the evaluations are accelerated, and an
accelerated cycle counts as steady only once a plain period from its end repeats it: the stated ``change`` is
always that of two periods driven one after the other.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tengsim.solvers.mixing import Anderson
from tengsim.visco.drive import DriveEnd, TimeDrive
from tengsim.visco.history import History
from tengsim.visco.memory import MaxwellMemory
from tengsim.visco.result import TimeResult

TOL = 1e-3
"""The cycle repeats when its A/S changes from one period to the next by at most this fraction of its largest A/S
(at every time of the cycle)."""
MAX_PERIODS = 30
"""Periods driven at most (plain and accelerated) before the cycle is taken as it is, marked not converged."""
PLAIN = 3
"""Periods driven from rest one after another, kept as the device's presses 1, 2, 3."""
DEPTH = 4
"""Anderson's depth: the last evaluations whose differences it combines."""


@dataclass(frozen=True)
class PeriodicCycles:
    """The presses of a periodic history: ``periods`` (the first :data:`PLAIN` periods from rest, each a
    :class:`TimeResult` with t from 0 to the period), ``steady`` (the periodic cycle), ``change`` (max |ΔA/S| of
    the last two periods driven one after the other, over the largest A/S), ``tol``, ``converged`` and
    ``evaluations`` (the periods driven in all).  Two periods are compared at the times both visit
    (:func:`schedule`)."""

    periods: tuple
    steady: TimeResult
    change: float
    tol: float
    converged: bool
    evaluations: int

    @property
    def first(self) -> TimeResult:
        return self.periods[0]

    def params(self) -> dict:
        return {"steady_change": self.change, "steady_tol": self.tol, "steady_converged": bool(self.converged),
                "steady_evaluations": int(self.evaluations), "plain_periods": len(self.periods)}


def _pack(mem: MaxwellMemory) -> np.ndarray:
    return np.concatenate([np.ravel(q) for q in mem.q] + [np.ravel(mem.w)])


def _unpack(x: np.ndarray, like: MaxwellMemory) -> MaxwellMemory:
    n = like.w.size
    q = tuple(np.array(x[i * n:(i + 1) * n]).reshape(like.w.shape) for i in range(len(like.q)))
    return MaxwellMemory(q, np.array(x[len(like.q) * n:]).reshape(like.w.shape))


def schedule(history: History, steps) -> np.ndarray:
    """The times every run of ``history`` with ``steps`` visits (a jump's bisection adds its own, which differ
    from one period to the next): where two periods' cycles are compared."""
    out = [float(history.t[0])]
    for ta, tb in zip(history.t, history.t[1:]):
        out += [float(tb)] if tb == ta else [float(x) for x in steps.times(float(ta), float(tb))]
    return np.asarray(out)


def _area_on(res: TimeResult, t: np.ndarray) -> np.ndarray:
    """A/S of ``res`` at the times ``t`` it visited (at a repeated time, the last row: after the jump)."""
    i = np.clip(np.searchsorted(res.t, t * (1 + 1e-12) + 1e-300, side="right") - 1, 0, res.t.size - 1)
    return np.asarray(res["area_fraction"])[i]


def periodic_cycles(drive: TimeDrive, history: History, steps, tol: float = TOL, max_periods: int = MAX_PERIODS,
                    plain: int = PLAIN, depth: int = DEPTH, progress=None) -> PeriodicCycles:
    """The presses of ``history`` (one period, t from 0 to the period, starting and ending at one control)
    repeated on ``drive`` (module doc)."""
    plain, max_periods = max(1, int(plain)), max(int(plain) + 1, int(max_periods))
    res, end = drive.run_from(history, steps)
    periods = [res]
    t_ref = schedule(history, steps)
    scale = max(float(np.max(res["area_fraction"])), 1e-12)
    like = end.memory
    x, g = np.zeros_like(_pack(like)), _pack(end.memory)  # x: a period's start memory, g = G(x) its end
    mix = Anderson(x.size, depth)  # every evaluation (x, G(x)) recorded, plain or accelerated
    prev, last_plain, change, n = res, True, np.inf, 1
    best = (np.inf, res)
    while n < max_periods:
        accelerate = len(periods) >= plain and not (np.isfinite(change) and change <= tol and not last_plain)
        mixed = np.array(x, dtype=float)
        mix.step(mixed, g)  # the next start memory mixed from the last ``depth`` + 1 evaluations
        x = mixed if accelerate else g
        start = DriveEnd(_unpack(x, like), end.state, end.ratio, end.D)
        res, end = drive.run_from(history, steps, start=start)
        n += 1
        change = float(np.max(np.abs(_area_on(res, t_ref) - _area_on(prev, t_ref)))) / scale
        if progress is not None:
            progress(f"period {n}: the cycle changed by {change:.2g} of its largest A/S"
                     + (" (accelerated)" if accelerate else ""))
        if len(periods) < plain and not accelerate:
            periods.append(res)
        if not accelerate and change < best[0]:
            best = (change, res)
        if not accelerate and change <= tol:  # two periods driven one after the other repeat
            return PeriodicCycles(tuple(periods), res, change, float(tol), True, n)
        g = _pack(end.memory)
        prev, last_plain = res, not accelerate
    return PeriodicCycles(tuple(periods), best[1], float(best[0]), float(tol), False, n)

