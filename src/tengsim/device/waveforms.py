"""Applied pressure P_a(t) of Eq. (13): square wave, staircase (Fig. 8), sine, user table.

Every waveform is right-continuous, vectorised (``wf(t)`` in Pa) and lists the times where it
jumps or kinks (``breakpoints``) so that the integrator never steps across one.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np

from tengsim.errors import TengsimError, finite, positive, require
from tengsim.registry import Registry
from tengsim.schema import REQUIRED

WAVEFORMS: Registry = Registry("waveform")
"""Waveform kinds by name (``kind`` in a [waveform] table); the config fields are the dataclass fields."""


def _f(help_text: str, default=REQUIRED, **meta):
    """A dataclass field whose help (and optional ``dim``, ``choices``) the config schema reads;
    without ``default`` (:data:`tengsim.schema.REQUIRED`) the field is required."""
    meta = {"help": help_text, **meta}
    return field(metadata=meta) if default is REQUIRED else field(default=default, metadata=meta)


def _duty(duty):
    d = finite("duty", duty)
    require(0 < d < 1, f"duty must be in (0, 1), got {duty!r}")
    return d


def _grid_breaks(period, duty, t0, t1):
    k0 = max(0, math.floor(t0 / period) - 1)
    k1 = math.ceil(t1 / period) + 1
    ks = np.arange(k0, k1 + 1)
    b = np.concatenate([ks * period, (ks + duty) * period])
    return np.unique(b[(b > t0) & (b < t1)])


class _Waveform:
    """What every waveform shares: ``to_dict`` (``kind`` plus the dataclass fields, for saved parameters)."""

    def to_dict(self) -> dict:
        d = {"kind": WAVEFORMS.name_of(self)}
        for f in dataclasses.fields(self):
            v = getattr(self, f.name)
            d[f.name] = v.tolist() if isinstance(v, np.ndarray) else list(v) if isinstance(v, tuple) else v
        return d


class _Periodic(_Waveform):
    """A waveform repeating at ``frequency_Hz`` (endless unless the class sets a duration)."""

    duration = None

    @property
    def period(self) -> float:
        return 1.0 / self.frequency_Hz


@WAVEFORMS.register("square")
@dataclass(frozen=True)
class SquareWave(_Periodic):
    """P = amplitude for the first ``duty`` of each period, ``low_Pa`` otherwise (Fig. 7)."""

    amplitude_Pa: float = _f("pressure while pressed")
    frequency_Hz: float = _f("repetition frequency")
    duty: float = _f("pressed fraction of each period, in (0, 1)", 0.5)
    low_Pa: float = _f("pressure while released", 0.0)

    def __post_init__(self):
        object.__setattr__(self, "amplitude_Pa", finite("amplitude_Pa", self.amplitude_Pa))
        object.__setattr__(self, "frequency_Hz", positive("frequency_Hz", self.frequency_Hz))
        object.__setattr__(self, "duty", _duty(self.duty))
        object.__setattr__(self, "low_Pa", finite("low_Pa", self.low_Pa))

    def __call__(self, t):
        t = np.asarray(t, dtype=float)
        phase = np.mod(t, self.period) / self.period
        return np.where(phase < self.duty, self.amplitude_Pa, self.low_Pa)

    def breakpoints(self, t0: float, t1: float) -> np.ndarray:
        return _grid_breaks(self.period, self.duty, t0, t1)



@WAVEFORMS.register("staircase")
@dataclass(frozen=True)
class Staircase(_Periodic):
    """Square wave whose k-th pulse has amplitude ``amplitudes_Pa[k]`` (Fig. 8); zero afterwards."""

    amplitudes_Pa: tuple = _f("pressure of each pulse, in order (one pulse per period)")
    frequency_Hz: float = _f("repetition frequency")
    duty: float = _f("pressed fraction of each period, in (0, 1)", 0.5)

    def __post_init__(self):
        try:
            amps = tuple(float(a) for a in self.amplitudes_Pa)
        except (TypeError, ValueError):
            raise TengsimError(f"amplitudes_Pa must be numbers, got {self.amplitudes_Pa!r}") from None
        require(len(amps) >= 1, "amplitudes_Pa must hold at least one amplitude")
        require(all(math.isfinite(a) for a in amps), f"amplitudes_Pa must be finite, got {amps}")
        object.__setattr__(self, "amplitudes_Pa", amps)
        object.__setattr__(self, "frequency_Hz", positive("frequency_Hz", self.frequency_Hz))
        object.__setattr__(self, "duty", _duty(self.duty))

    @classmethod
    def linear(cls, start_Pa: float, stop_Pa: float, step_Pa: float, frequency_Hz: float, duty: float = 0.5):
        """Amplitudes start, start + step, ..., stop (inclusive), e.g. 10 -> 150 kPa by 10 kPa."""
        step = positive("step_Pa", step_Pa)
        n = int(round((float(stop_Pa) - float(start_Pa)) / step))
        require(n >= 0, f"stop_Pa {stop_Pa!r} is below start_Pa {start_Pa!r}")
        return cls(tuple(float(start_Pa) + k * step for k in range(n + 1)), frequency_Hz, duty)

    @property
    def duration(self) -> float:
        return len(self.amplitudes_Pa) * self.period

    def __call__(self, t):
        t = np.asarray(t, dtype=float)
        k = np.floor(t / self.period).astype(int)
        phase = t / self.period - k
        amps = np.asarray(self.amplitudes_Pa)
        inside = (k >= 0) & (k < amps.size)
        a = amps[np.clip(k, 0, amps.size - 1)]
        return np.where(inside & (phase < self.duty), a, 0.0)

    def breakpoints(self, t0: float, t1: float) -> np.ndarray:
        return _grid_breaks(self.period, self.duty, t0, t1)



@WAVEFORMS.register("sine")
@dataclass(frozen=True)
class Sine(_Periodic):
    """P = offset + amplitude sin(2 pi f t + phase); offset = amplitude, phase = -pi/2 gives 0 -> 2A."""

    amplitude_Pa: float = _f("amplitude")
    frequency_Hz: float = _f("frequency")
    offset_Pa: float = _f("mean pressure", 0.0)
    phase_rad: float = _f("phase at t = 0 (radians)", 0.0)

    def __post_init__(self):
        for name in ("amplitude_Pa", "offset_Pa", "phase_rad"):
            object.__setattr__(self, name, finite(name, getattr(self, name)))
        object.__setattr__(self, "frequency_Hz", positive("frequency_Hz", self.frequency_Hz))

    def __call__(self, t):
        t = np.asarray(t, dtype=float)
        return self.offset_Pa + self.amplitude_Pa * np.sin(2 * np.pi * self.frequency_Hz * t + self.phase_rad)

    def breakpoints(self, t0: float, t1: float) -> np.ndarray:
        return np.empty(0)



@WAVEFORMS.register("table")
@dataclass(frozen=True, eq=False)
class TableWaveform(_Waveform):
    """User table (t_s, pressure_Pa); ``interp`` "linear" or "step" (hold previous); end value held.

    With ``periodic`` the table repeats with period t_s[-1] (t_s[0] must be 0).
    """

    t_s: np.ndarray = _f("times, strictly increasing")
    pressure_Pa: np.ndarray = _f("pressure at each time")
    interp: str = _f("between rows: linear, or step (hold the previous value)", "linear",
                     choices=("linear", "step"))
    periodic: bool = _f("repeat the table with period t_s[-1] (t_s[0] must be 0)", False)

    def __post_init__(self):
        try:
            t = np.array(self.t_s, dtype=float).ravel()
            p = np.array(self.pressure_Pa, dtype=float).ravel()
        except (TypeError, ValueError):
            raise TengsimError("waveform table must hold numbers") from None
        require(t.size >= 2 and t.size == p.size,
                f"waveform table needs >= 2 equal-length columns, got {t.size} times and {p.size} pressures")
        require(bool(np.all(np.isfinite(t)) and np.all(np.isfinite(p))), "waveform table holds non-finite values")
        require(bool(np.all(np.diff(t) > 0)), "waveform table times must be strictly increasing")
        require(self.interp in ("linear", "step"), f"interp must be 'linear' or 'step', got {self.interp!r}")
        if self.periodic:
            require(t[0] == 0.0, f"a periodic table must start at t = 0, got {t[0]!r}")
        t.setflags(write=False)
        p.setflags(write=False)
        object.__setattr__(self, "t_s", t)
        object.__setattr__(self, "pressure_Pa", p)

    @property
    def period(self):
        return float(self.t_s[-1]) if self.periodic else None

    @property
    def duration(self):
        return None if self.periodic else float(self.t_s[-1])

    def __call__(self, t):
        t = np.asarray(t, dtype=float)
        if self.periodic:
            t = np.mod(t, self.t_s[-1])
        if self.interp == "linear":
            return np.interp(t, self.t_s, self.pressure_Pa)
        i = np.clip(np.searchsorted(self.t_s, t, side="right") - 1, 0, self.t_s.size - 1)
        return self.pressure_Pa[i]

    def breakpoints(self, t0: float, t1: float) -> np.ndarray:
        if self.periodic:
            per = self.t_s[-1]
            ks = np.arange(max(0, math.floor(t0 / per) - 1), math.ceil(t1 / per) + 2)
            b = (ks[:, None] * per + self.t_s[None, :]).ravel()
        else:
            b = self.t_s
        return np.unique(b[(b > t0) & (b < t1)])
