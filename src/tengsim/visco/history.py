"""A path in time: a piecewise-linear control (the rigid approach D in ε, or the mean pressure in W/ε) and the
time-step controls a drive is given (as the walker is given its step control).

A repeated time is an instantaneous step (Δt = 0: the material answers with E0).  The builders give a ramp,
a ramp and hold, a step and hold, and a square or triangle wave; :func:`read_history` reads a CSV.
"""
from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from tengsim.errors import TengsimError

KINDS = ("approach", "pressure")


@dataclass(frozen=True)
class History:
    """The control ``value`` (D in ε for 'approach', the mean pressure in W/ε for 'pressure') at ``t`` (s),
    linear in between; ``t`` non-decreasing, a repeated time a jump of the control."""

    t: tuple
    value: tuple
    kind: str = "approach"

    def __post_init__(self):
        t, v = tuple(float(x) for x in self.t), tuple(float(x) for x in self.value)
        object.__setattr__(self, "t", t)
        object.__setattr__(self, "value", v)
        if self.kind not in KINDS:
            raise TengsimError(f"history kind must be one of {', '.join(KINDS)}, got {self.kind!r}")
        if len(t) != len(v) or len(t) < 2:
            raise TengsimError(f"a history needs >= 2 points of time and {self.kind}, got {len(t)}")
        if not all(math.isfinite(x) for x in t + v):
            raise TengsimError("a history's times and values must be finite")
        if any(b < a for a, b in zip(t, t[1:])):
            i = next(i for i, (a, b) in enumerate(zip(t, t[1:])) if b < a)
            raise TengsimError(f"history times must not decrease: t = {t[i + 1]:g} s after {t[i]:g} s")

    def at(self, time: float) -> float:
        """The control at ``time`` (the later value at a jump)."""
        t = np.asarray(self.t)
        i = int(np.searchsorted(t, time, side="right")) - 1
        i = min(max(i, 0), len(t) - 2)
        t0, t1 = t[i], t[i + 1]
        if t1 == t0:
            return self.value[i + 1]
        s = min(max((time - t0) / (t1 - t0), 0.0), 1.0)
        return self.value[i] + s * (self.value[i + 1] - self.value[i])

    def params(self) -> dict:
        return {"history_kind": self.kind, "history_t_end_s": self.t[-1], "history_points": len(self.t)}


def ramp_hold(v0: float, v1: float, t_ramp: float, t_hold: float, kind: str = "approach") -> History:
    """From v0 to v1 in ``t_ramp`` (0: a step), held for ``t_hold``."""
    return History((0.0, t_ramp, t_ramp + t_hold), (v0, v1, v1), kind)


def triangle(v0: float, v1: float, t_up: float, t_down: float, kind: str = "approach") -> History:
    """v0 → v1 in ``t_up``, back to v0 in ``t_down``."""
    return History((0.0, t_up, t_up + t_down), (v0, v1, v0), kind)


def square_wave(v0: float, v1: float, period: float, cycles: int = 1, rise: float = 0.05,
                kind: str = "approach") -> History:
    """``cycles`` periods of pressing (v1) and release (v0), each edge a ramp of ``rise`` × period."""
    if not (period > 0 and 0 < rise < 0.5 and int(cycles) >= 1):
        raise TengsimError(f"square wave: period > 0, 0 < rise < 0.5 and cycles >= 1, got {period}, {rise}, {cycles}")
    r = rise * period
    t, v = [0.0], [v0]
    for k in range(int(cycles)):
        s = k * period
        t += [s + r, s + period / 2, s + period / 2 + r, s + period]
        v += [v1, v1, v0, v0]
    return History(tuple(t), tuple(v), kind)


def read_history(path, kind: str | None = None) -> History:
    """A CSV of (time s, value): the header's second column names the kind ('approach'/'D' or 'pressure'),
    or ``kind`` says it."""
    p = Path(path)
    try:
        rows = [r for r in csv.reader(p.read_text().splitlines()) if r and not r[0].lstrip().startswith("#")]
    except OSError as e:
        raise TengsimError(f"cannot read history file {str(p)!r}: {e.strerror}") from None
    except (UnicodeDecodeError, csv.Error):
        raise TengsimError(f"history file {str(p)!r}: not a text (CSV) file") from None
    if rows and rows[0] and not _number(rows[0][0]):
        head = rows[0][1].strip().lower() if len(rows[0]) > 1 else ""
        kind = kind or ("pressure" if head.startswith("p") else "approach" if head.startswith(("a", "d")) else None)
        rows = rows[1:]
    try:
        data = [(float(r[0]), float(r[1])) for r in rows]
    except (ValueError, IndexError):
        raise TengsimError(f"history file {str(p)!r}: every row must be two numbers (time, value)") from None
    if kind is None:
        raise TengsimError(f"history file {str(p)!r}: name the second column 'approach' or 'pressure'")
    return History(tuple(a for a, _ in data), tuple(b for _, b in data), kind)


def _number(s) -> bool:
    try:
        float(s)
        return True
    except ValueError:
        return False


@dataclass(frozen=True)
class FixedTimeSteps:
    """Steps of ``dt`` (s), the last of a segment shortened to end on it."""

    dt: float

    def __post_init__(self):
        if not self.dt > 0:
            raise TengsimError(f"time step dt must be > 0, got {self.dt!r} s")

    def times(self, t0: float, t1: float) -> np.ndarray:
        n = max(1, int(math.ceil((t1 - t0) / self.dt - 1e-9)))
        return t0 + (t1 - t0) * np.arange(1, n + 1) / n

    def params(self) -> dict:
        return {"time_steps": "fixed", "dt_s": self.dt}


@dataclass(frozen=True)
class GeometricTimeSteps:
    """Steps growing from ``dt0`` by ``growth`` after each breakpoint, at most ``dt_max`` (s): fine where the
    control changed, coarse in a hold (a creep or relaxation resolved over decades of time)."""

    dt0: float
    growth: float = 1.2
    dt_max: float = math.inf

    def __post_init__(self):
        if not (self.dt0 > 0 and self.growth >= 1 and self.dt_max >= self.dt0):
            raise TengsimError(f"geometric steps need dt0 > 0, growth >= 1, dt_max >= dt0, got "
                               f"{self.dt0}, {self.growth}, {self.dt_max}")

    def times(self, t0: float, t1: float) -> np.ndarray:
        out, t, dt = [], t0, self.dt0
        while t + 1.5 * dt < t1:  # the last step at most 1.5 dt long
            t += dt
            out.append(t)
            dt = min(dt * self.growth, self.dt_max)
        out.append(t1)
        return np.asarray(out)

    def params(self) -> dict:
        return {"time_steps": "geometric", "dt0_s": self.dt0, "growth": self.growth, "dt_max_s": self.dt_max}


@dataclass(frozen=True)
class SegmentSteps:
    """``n`` equal steps on every segment of the history, whatever its length (a cycle whose parts run at
    different rates: a slow loading and a fast unloading get the same resolution each)."""

    n: int = 16

    def __post_init__(self):
        if isinstance(self.n, bool) or not isinstance(self.n, int) or self.n < 1:
            raise TengsimError(f"steps per segment must be an integer >= 1, got {self.n!r}")

    def times(self, t0: float, t1: float) -> np.ndarray:
        return t0 + (t1 - t0) * np.arange(1, self.n + 1) / self.n

    def params(self) -> dict:
        return {"time_steps": "per segment", "steps_per_segment": self.n}
