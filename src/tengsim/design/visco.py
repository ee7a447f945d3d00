"""A design on a time axis (``tengsim design … --relaxation FILE``): the design's contact pressed and released
at 2–3 frequencies on a viscoelastic material (:mod:`tengsim.visco`), with A/S(t), V_OC(t) (Eq. 12) and the
nominal pressure over a cycle, and the sensor's numbers at each frequency:

* a triangle cycle 0 → p_max → 0 in one period (load control): the V_OC(P) loop gives the sensitivity, the
  linear range and the hysteresis (:func:`tengsim.device.sensor.sensor_numbers`, as the static design);
* a square cycle (press to p_max in 5 % of the period, hold, release, hold): the response and the recovery time
  to 90 % of V_OC's change, from the start of the press and of the release.

* the presses the device is driven by, repeated from one period to the next with the material's memory carried
  (:func:`tengsim.visco.simulate_periodic`): the square cycle and, asked (``presses``; ``tengsim design
  --visco-sine``), a sine press P = (p_max/2)(1 − cos 2π f t), each
  as its first :data:`tengsim.visco.periodic.PLAIN` periods from rest and its periodic steady state (the cycle
  repeating to :data:`tengsim.visco.periodic.TOL` of its largest A/S).

The relaxed elastic solid (E∞, no branch) runs the triangle and the square cycle once, as the static reference.  The cycles run on
one coarse grid of ``pixels`` × ``pixels`` (stated in the report): they show the rate effects, the static design gives the
converged numbers.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from tengsim.device.formulas import voc_polymer
from tengsim.device.sensor import sensor_numbers
from tengsim.relaxation import Prony
from tengsim.visco import SegmentSteps, History, simulate_history, simulate_periodic, square_wave

FREQUENCIES = (0.5, 2.0, 10.0)
"""Hz: the stated frequencies of a design's viscoelastic cycles (a TENG pressed by hand … a fast actuator)."""
RISE = 0.05
"""The square cycle's press and release ramps, a fraction of the period (pressed for half the period)."""
PRESSES = ("square", "sine")
"""The device's waveforms whose presses a design records with their memory (:func:`press_history`)."""
SINE_SEGMENTS = 4
"""The sine press: ``SINE_SEGMENTS`` × steps linear segments per period (as many steps as the square cycle)."""


@dataclass(frozen=True)
class Cycle:
    """One cycle at ``frequency`` (Hz; 0: the relaxed elastic reference): t (s), nominal pressure (Pa), A/S, V_OC (V)."""

    frequency: float
    kind: str
    t: np.ndarray
    pressure_Pa: np.ndarray
    area: np.ndarray
    voc: np.ndarray
    force_N: np.ndarray
    press: int = 1
    """Which press of a repeated waveform (1, 2, …; 0: the periodic steady state); t from the press's start."""


@dataclass(frozen=True)
class ViscoDesign:
    """The cycles and the frequency table ({'frequency_Hz', 'sensitivity_V_per_Pa', 'linear_range_Pa',
    'voc_hysteresis_fraction', 'response_s', 'recovery_s', 'area_max'} per row); ``p_max_Pa``: the pressure every
    cycle presses to."""

    material: Prony
    grid: str
    cycles: tuple
    table: tuple = field(default_factory=tuple)
    p_max_Pa: float = float("nan")
    steady: tuple = field(default_factory=tuple)
    """Per frequency and press: {'frequency_Hz', 'cycle', 'change', 'tol', 'converged', 'evaluations'}."""


def _t90(t, v, t_start, t_end) -> float:
    """Time from ``t_start`` until v has made 90 % of its change over [t_start, t_end]."""
    m = (t >= t_start) & (t <= t_end)
    tt, vv = t[m], v[m]
    if tt.size < 2 or vv[-1] == vv[0]:
        return float("nan")
    frac = (vv - vv[0]) / (vv[-1] - vv[0])
    i = int(np.argmax(frac >= 0.9))
    if i == 0:
        return float(tt[0] - t_start)
    t_cross = np.interp(0.9, [frac[i - 1], frac[i]], [tt[i - 1], tt[i]]) if frac[i] != frac[i - 1] else tt[i]
    return float(t_cross - t_start)


def visco_cycles(plan, material: Prony, frequencies=FREQUENCIES, pixels: int = 48, steps: int = 12,
                 progress=None, presses=("square",)) -> ViscoDesign:
    """The design ``plan`` (:class:`tengsim.design.plan.DesignPlan`) cycled at ``frequencies`` (module doc);
    ``steps`` time steps per segment of each cycle; ``presses``: the repeated presses recorded, of
    :data:`PRESSES` (the square one always: the sensor's response and recovery are read off its first press; the
    sine as many periods again: ``tengsim design --visco-sine``)."""
    presses = ("square",) + tuple(k for k in presses if k != "square")
    bad = [k for k in presses if k not in PRESSES]
    if bad:
        raise ValueError(f"no press {bad[0]!r} (presses: {', '.join(PRESSES)})")
    cp = plan.contact_plan
    shape = cp.shape
    cell = float(getattr(shape, "cell", cp.grid.nx * cp.grid.dx))
    dx = cell / int(pixels)
    grid = shape.grid(dx)
    scale = plan.eps / plan.W                                   # Pa → W/ε
    lat = plan.contact_plan.scaling.lateral if cp.scaling is not None else 1.0
    p_max = plan.pressures[-1]
    cycles, table, steady = [], [], []
    kw = dict(boundary=cp.boundary, law=cp.law, solver=cp.solver, tol=cp.solver_tol, kernel_params=cp.kernel_params,
              grid=grid)

    def cycle(f, kind, r, press=1):
        P = r["mean_pressure"] / scale
        A = r["area_fraction"]
        V = voc_polymer(A, plan.sigma, plan.eps_r, plan.T)
        F = r["F"] * 3 * np.pi * plan.W * lat**2 / plan.eps
        return Cycle(f, kind, r.t, P, A, V, F, press)

    for f, mat in [(0.0, Prony(material.E_inf))] + [(float(f), material) for f in frequencies]:
        period = 1.0 / f if f > 0 else 1.0
        out = {}
        for kind in ("triangle", "square") if f == 0 else ("triangle",) + presses:
            h = (History((0.0, period / 2, period), (0.0, p_max * scale, 0.0), "pressure") if kind == "triangle"
                 else press_history(kind, p_max * scale, period, int(steps)))
            st = SegmentSteps(int(steps)) if kind != "sine" else SegmentSteps(1)
            if progress is not None:
                progress(f"viscoelastic cycle: {kind} at {f:g} Hz" if f else f"elastic (E∞) cycle: {kind}")
            if kind == "triangle" or f == 0:
                r = simulate_history(shape, cp.tabor, dx, mat, h, st, E_ref=mat.E_inf, **kw)
                out[kind] = cycle(f, kind, r)
                cycles.append(out[kind])
                continue
            pc = simulate_periodic(shape, cp.tabor, dx, mat, h, st, E_ref=mat.E_inf, **kw)
            for i, r in enumerate(pc.periods):
                cycles.append(cycle(f, kind, r, i + 1))
            cycles.append(cycle(f, kind, pc.steady, 0))
            out[kind] = cycles[-1 - len(pc.periods)]  # the first press: the sensor's numbers are of it
            steady.append({"frequency_Hz": f, "cycle": kind, **{k.removeprefix("steady_"): v
                                                                 for k, v in pc.params().items()}})
        tri = out["triangle"]
        up = tri.t <= period / 2 + 1e-12
        down = ~up
        nums = sensor_numbers(tri.pressure_Pa[up], tri.voc[up],
                              retraction=(tri.pressure_Pa[down][::-1], tri.voc[down][::-1])).flat()
        sq = out["square"]
        sq_steady = next((c for c in cycles if c.frequency == f and c.kind == "square" and c.press == 0), sq)
        table.append({"frequency_Hz": f, "sensitivity_V_per_Pa": nums["sensitivity_V_per_Pa"],
                      "linear_range_Pa": nums["linear_range_Pa"],
                      "voc_hysteresis_fraction": nums["voc_hysteresis_fraction"],
                      "response_s": _t90(sq.t, sq.voc, 0.0, period / 2) if f else float("nan"),
                      "recovery_s": _t90(sq.t, sq.voc, period / 2, period) if f else float("nan"),
                      "area_max": float(np.max(sq.area)), "area_max_steady": float(np.max(sq_steady.area))})
    return ViscoDesign(material, f"{grid.nx}×{grid.ny} (dx = {dx * lat * 1e9:.0f} nm)", tuple(cycles), tuple(table),
                       float(p_max), tuple(steady))


def press_history(kind: str, p_max: float, period: float, steps: int = 12) -> History:
    """One period of the press ``kind`` (:data:`PRESSES`) to ``p_max`` (the drive's units, W/ε), load control: the
    square cycle (ramps of :data:`RISE` × period, pressed for half the period) or the sine press
    (p_max/2)(1 − cos 2π t/period), linear between :data:`SINE_SEGMENTS` × ``steps`` + 1 points."""
    if kind == "square":
        return square_wave(0.0, p_max, period, 1, rise=RISE, kind="pressure")
    if kind == "sine":
        t = np.linspace(0.0, period, SINE_SEGMENTS * int(steps) + 1)
        return History(tuple(t), tuple(0.5 * p_max * (1 - np.cos(2 * np.pi * t / period))), "pressure")
    raise ValueError(f"no press {kind!r} (presses: {', '.join(PRESSES)})")
