"""What TENG users expect beyond the paper: static V_OC(pressure) (Eq. 12), load sweep, V-Q cycles, FOM_S."""
from __future__ import annotations

import math
import sys
from dataclasses import dataclass

import numpy as np
from scipy.integrate import trapezoid

from tengsim.constants import EPS0
from tengsim.device import formulas as fm
from tengsim.device.dynamics import simulate
from tengsim.device.params import DeviceParams, SolverOptions
from tengsim.device.result import DeviceResult
from tengsim.errors import TengsimError, positive, require


# --- Section 4: static voltage-pressure curve (Eq. 12) ---

@dataclass(frozen=True, eq=False)
class StaticVoltageCurve:
    """V_OC against applied pressure from Eq. (12), with the inputs it came from."""

    pressure_Pa: np.ndarray
    area_fraction: np.ndarray
    voc_V: np.ndarray
    sigma_C_per_m2: float
    eps_r: float
    thickness_m: float

    def to_dataset(self):
        import xarray as xr

        return xr.Dataset(
            {"area_fraction": ("pressure", self.area_fraction, {"units": "1"}),
             "V_oc": ("pressure", self.voc_V, {"units": "V", "long_name": "Eq. (12) open-circuit voltage"})},
            coords={"pressure": ("pressure", self.pressure_Pa, {"units": "Pa"})},
            attrs={"sigma_C_per_m2": self.sigma_C_per_m2, "eps_r": self.eps_r, "thickness_m": self.thickness_m,
                   "model": "Eq. (12): V_OC = sigma (A/S) T / (eps_r eps0)"})


def voc_from_area(*, sigma: float, eps_r: float, thickness: float, pressure_Pa=None, area_fraction=None,
                  force_N=None, lambda_c=None, cell_length=None) -> StaticVoltageCurve:
    """Eq. (12) V_OC(pressure) from either (pressure_Pa, area_fraction) or the engine's (f, lambda_c, L).

    With (force_N, lambda_c, cell_length): pressure = f / L^2 and A/S = lambda_c^2 / L^2.
    """
    sigma, eps_r, thickness = (positive("sigma", sigma), positive("eps_r", eps_r), positive("thickness", thickness))
    if force_N is not None or lambda_c is not None:
        require(force_N is not None and lambda_c is not None and cell_length is not None,
                "give force_N, lambda_c and cell_length together")
        L = positive("cell_length", cell_length)
        p = np.asarray(force_N, dtype=float) / L ** 2
        a = (np.asarray(lambda_c, dtype=float) / L) ** 2
    else:
        require(pressure_Pa is not None and area_fraction is not None, "give pressure_Pa and area_fraction")
        p = np.asarray(pressure_Pa, dtype=float)
        a = np.asarray(area_fraction, dtype=float)
    require(p.shape == a.shape and p.ndim == 1, f"pressure and area must be equal 1-D arrays, got {p.shape}, {a.shape}")
    require(bool(np.all(np.isfinite(p)) and np.all(np.isfinite(a))), "pressure/area table holds non-finite values")
    require(bool(np.all((a >= 0) & (a <= 1 + 1e-12))), f"area fraction must be in [0, 1], got max {a.max()!r}")
    return StaticVoltageCurve(p, a, fm.voc_polymer(a, sigma, eps_r, thickness), sigma, eps_r, thickness)


# --- load-resistance sweep ---

@dataclass(frozen=True, eq=False)
class ResistanceSweep:
    """Settled-cycle outputs against load resistance; ``optimum_ohm`` maximises the mean power."""

    load_ohm: np.ndarray
    energy_per_cycle_J: np.ndarray
    average_power_W: np.ndarray
    peak_voltage_V: np.ndarray
    peak_current_A: np.ndarray
    peak_power_W: np.ndarray
    optimum_ohm: float
    optimum_power_W: float
    optimum_at_edge: bool = False
    """True when the largest power is at the first or last load: the optimum may lie outside the range."""

    def to_dataset(self):
        import xarray as xr

        v = {"energy_per_cycle": ("R", self.energy_per_cycle_J, {"units": "J"}),
             "average_power": ("R", self.average_power_W, {"units": "W"}),
             "peak_voltage": ("R", self.peak_voltage_V, {"units": "V"}),
             "peak_current": ("R", self.peak_current_A, {"units": "A"}),
             "peak_power": ("R", self.peak_power_W, {"units": "W"})}
        return xr.Dataset(v, coords={"R": ("R", self.load_ohm, {"units": "ohm"})},
                          attrs={"optimum_ohm": self.optimum_ohm, "optimum_power_W": self.optimum_power_W,
                                 "optimum_at_edge": int(self.optimum_at_edge)})


STEADY_RTOL = 1e-9
""":func:`steady_charge` stops when one cycle from its Q0 returns to Q0 within this × the charge scale σS."""
STEADY_STEPS = 8
STEADY_NOISE = 1e3
"""... or within this × the integrator's tolerance on Q (rtol |Q0| + atol σS): below that a secant step meets the
integrator's own error (the paper's Fig. 7 device at 3.16 GΩ stalls at 2.4e-17 C, 1e-9 σS being 1.1e-17 C)."""


def steady_start(params: DeviceParams, waveform, options: SolverOptions | None = None) -> tuple[float, float]:
    """(Q0 in C, A/S held) at the start of a periodic steady cycle: the fixed point of the one-cycle map
    Q0 -> Q(T), by secant steps (at large R the contact RC time is many periods, so plain time-stepping would
    need hundreds of cycles).

    The charged area a cycle starts with is the one a first cycle from the run's own start leaves (with
    ``area_memory = 'max'`` the largest the pressure reached: every later cycle starts with it).  With it the
    map is affine in Q0 when the plate starts each cycle at rest and F_e is small (both hold for the paper's
    devices), so the first step from Q0 = 0 and Q0 = the rest charge (where that is 0, the charge one cycle
    from 0 leaves) lands on it; each step is checked by the next cycle and the secant goes on, up to
    :data:`STEADY_STEPS` steps, until |Q(T) − Q0| <= :data:`STEADY_RTOL` σS (or the integrator's accuracy,
    :data:`STEADY_NOISE`).  Raises a
    :class:`tengsim.errors.TengsimError` where no steady cycle is found.
    """
    per = waveform.period
    dt = per / 20
    first = simulate(params, waveform, per, dt_out=dt, options=options)
    area0 = float(first.area[-1] / params.area_m2)

    def gap(q0):  # Q(T) − Q0 of one cycle from Q0
        return simulate(params, waveform, per, dt_out=dt, options=options, q0_C=q0, area0=area0).Q[-1] - q0

    opts = options or SolverOptions()
    scale = abs(params.charge_scale)

    def small(f, x):  # one cycle returns to Q0: within STEADY_RTOL σS, or within the integrator's own accuracy
        return abs(f) <= max(STEADY_RTOL * scale, STEADY_NOISE * (opts.rtol * abs(x) + opts.atol * scale))

    x0, f0 = 0.0, gap(0.0)
    if small(f0, 0.0):
        return 0.0, area0
    q_rest = params.charge_scale * params.area.initial_fraction / (params.gamma3 + 1.0)
    x1 = q_rest if q_rest else f0
    f1 = gap(x1)
    for _ in range(STEADY_STEPS):
        if small(f1, x1) or f1 == f0:
            break
        x0, f0, x1 = x1, f1, x1 - f1 * (x1 - x0) / (f1 - f0)
        f1 = gap(x1)
    if small(f1, x1):
        return float(x1), area0
    raise TengsimError(f"no periodic steady cycle found at R = {params.load_ohm:.3g} ohm (one cycle still moves "
                       f"the charge by {abs(f1):.3g} C after {STEADY_STEPS} secant steps): run it without the "
                       "steady start and with more cycles")


def steady_charge(params: DeviceParams, waveform, options: SolverOptions | None = None) -> float:
    """Q at the start of a periodic steady cycle (C): :func:`steady_start`'s charge."""
    return steady_start(params, waveform, options)[0]


def resistance_sweep(params: DeviceParams, waveform, loads_ohm, *, cycles: int = 3, skip_cycles: int = 1,
                     steady: bool = True, dt_out: float | None = None, options: SolverOptions | None = None,
                     progress: bool = False) -> ResistanceSweep:
    """Run ``cycles`` periods per load; energy per cycle = heat in R over the settled cycles.

    With ``steady`` each run starts from :func:`steady_charge`, so the numbers are periodic-steady-state
    values even where R C exceeds the run. ``optimum_at_edge`` is set when the largest power is at the
    smallest or largest load (then it is the best of the range, not an optimum).
    """
    loads = np.asarray(loads_ohm, dtype=float).ravel()
    require(loads.size >= 1, "loads_ohm is empty")
    require(bool(np.all(np.isfinite(loads) & (loads > 0))), f"loads must be finite and > 0, got {loads.tolist()}")
    per = getattr(waveform, "period", None)
    require(per is not None, "resistance_sweep needs a periodic waveform")
    require(int(cycles) > int(skip_cycles), f"cycles ({cycles}) must exceed skip_cycles ({skip_cycles})")
    rows = []
    for i, r in enumerate(loads):
        pr = params.replace(load_ohm=float(r))
        q0, area0 = steady_start(pr, waveform, options) if steady else (None, None)
        res = simulate(pr, waveform, int(cycles) * per, dt_out=dt_out, options=options, q0_C=q0, area0=area0)
        s = res.summary(skip_cycles)
        rows.append(tuple(math.nan if s[k] is None else s[k]
                          for k in ("energy_per_cycle_J", "average_power_W", "peak_voltage_V", "peak_current_A",
                                    "peak_power_W")))
        if progress:
            print(f"tengsim device: R = {r:.3g} ohm ({i + 1}/{loads.size}), P = {s['average_power_W']:.3g} W",
                  file=sys.stderr, flush=True)
    e, p, v, c, pk = (np.array(col, dtype=float) for col in zip(*rows))
    require(bool(np.any(np.isfinite(p))), "no load gave a settled cycle: raise cycles")
    k = int(np.nanargmax(p))
    edge = loads.size > 1 and k in (int(np.argmin(loads)), int(np.argmax(loads)))
    return ResistanceSweep(loads, e, p, v, c, pk, float(loads[k]), float(p[k]), bool(edge))


# --- V-Q cycle and the structural figure of merit (Zi et al. 2015) ---

@dataclass(frozen=True, eq=False)
class VQCycle:
    """One settled cycle of a run in the V-Q plane, with its energy and the CMEO for the same x_max."""

    charge_C: np.ndarray
    voltage_V: np.ndarray
    energy_J: float
    x_max_m: float
    cmeo: fm.CMEOCycle


def vq_cycle(result: DeviceResult, cycle: int = -1) -> VQCycle:
    """Cycle ``cycle`` (default: last whole one) as a V-Q loop; energy = loop integral of V dQ."""
    per = result.period
    require(per is not None, "vq_cycle needs a periodic waveform")
    n = int(np.floor(result.t[-1] / per + 1e-9))
    require(n >= 1, "the run holds no whole cycle")
    k = cycle % n if cycle < 0 else cycle
    require(0 <= k < n, f"cycle must be in [0, {n}), got {cycle!r}")
    m = (result.t >= k * per) & (result.t <= (k + 1) * per)
    q, v = result.Q[m], result.V[m]
    p = result.params
    x_max = float(np.max(result.gap[m]))
    area = float(np.max(result.area[m]))
    cm = fm.cmeo_cycle(p.sigma_C_per_m2, p.area_m2, p.thickness_m, p.eps_r, x_max, area=area)
    return VQCycle(q, v, float(trapezoid(v, q)), x_max, cm)


@dataclass(frozen=True)
class FigureOfMerit:
    """Structural FOM of the contact-separation mode: closed form and from the traced CMEO."""

    fom_closed_form: float
    fom_from_cycle: float
    energy_max_J: float
    x_max_m: float


def figure_of_merit(params: DeviceParams, x_max: float | None = None) -> FigureOfMerit:
    """FOM_S = 2 eps0 E_m / (sigma^2 S x_max) (Zi et al. 2015); x_max defaults to d0."""
    x = params.gap_m if x_max is None else positive("x_max", x_max)
    cm = fm.cmeo_cycle(params.sigma_C_per_m2, params.area_m2, params.thickness_m, params.eps_r, x)
    fom_num = 2 * EPS0 * cm.energy_J / (params.sigma_C_per_m2 ** 2 * params.area_m2 * x)
    return FigureOfMerit(float(fm.fom_structural(x, params.thickness_m, params.eps_r)), float(fom_num),
                         cm.energy_J, float(x))


# --- staircase (one pressure per pulse) ---

def staircase_summary(result: DeviceResult) -> dict:
    """V_OC per pressure step of a :class:`Staircase` run: the largest Eq. (17) voltage after that step's
    release, the peak |V| during the step, and the area fraction A(P_k). A step with no rows is None."""
    wf = result.waveform
    require(hasattr(wf, "amplitudes_Pa"), "a staircase summary needs a Staircase run")
    per = wf.period
    steps, vocs, peak_v = [], [], []
    for k, amp in enumerate(wf.amplitudes_Pa):
        after = (result.t >= (k + wf.duty) * per) & (result.t < (k + 1) * per)
        step = (result.t >= k * per) & (result.t < (k + 1) * per)
        vocs.append(float(np.max(result.V_oc[after])) if np.any(after) else None)
        peak_v.append(float(np.max(np.abs(result.V[step]))) if np.any(step) else None)
        steps.append(float(amp))
    return {"pressure_steps_Pa": steps, "voc_steps_V": vocs, "peak_voltage_steps_V": peak_v,
            "area_fraction_steps": [float(result.params.area(p)) for p in steps]}


__all__ = ["StaticVoltageCurve", "voc_from_area", "ResistanceSweep", "resistance_sweep", "steady_charge",
           "steady_start", "VQCycle", "vq_cycle", "FigureOfMerit", "figure_of_merit", "staircase_summary"]
