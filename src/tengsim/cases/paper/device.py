"""The paper's two dynamic cases: the flat device of Fig. 7 and the group-A device of Fig. 8."""
from __future__ import annotations

import math

import numpy as np

from tengsim.device.dynamics import simulate
from tengsim.device.params import AreaTable, ConstantArea, DeviceParams, SolverOptions
from tengsim.device.result import DeviceResult
from tengsim.device.waveforms import SquareWave, Staircase
from tengsim.errors import positive, require

FIG7_FORCE_N = 10.0
FIG7_FREQUENCY_HZ = 5.0
FIG8_FREQUENCY_HZ = 2.0
FIG8_PRESSURES_PA = tuple(1e4 * k for k in range(1, 16))  # 10 -> 150 kPa by 10 kPa


def fig7_params(**changes) -> DeviceParams:
    """Flat device of Fig. 7 (NOTES.md): A = S, sigma d0/eps0 = 200 V."""
    base = DeviceParams(mass_kg=13.45e-3, stiffness_N_per_m=4 * 1278.88, area_m2=38.71e-4, thickness_m=10e-6,
                        gap_m=1e-3, eps_r=2.40, sigma_C_per_m2=1.77e-6, load_ohm=1e6, area=ConstantArea(1.0))
    return base.replace(**changes) if changes else base


def fig7_waveform(frequency_Hz: float = FIG7_FREQUENCY_HZ, force_N: float = FIG7_FORCE_N,
                  area_m2: float = 38.71e-4) -> SquareWave:
    """10 N over S as a 5 Hz square wave (pressed first)."""
    return SquareWave(force_N / area_m2, frequency_Hz)


def fig8_params(area_table, **changes) -> DeviceParams:
    """Group-A device of Fig. 8 with the charged area A(P) from ``area_table`` (pressure_Pa, area_fraction)."""
    area = area_table if isinstance(area_table, (AreaTable, ConstantArea)) else AreaTable.from_table(area_table)
    base = DeviceParams(mass_kg=13.45e-3, stiffness_N_per_m=5.12e3, area_m2=4.00e-4, thickness_m=400e-6,
                        gap_m=0.1e-3, eps_r=2.40, sigma_C_per_m2=5.84e-6, load_ohm=1e6, area=area)
    return base.replace(**changes) if changes else base


def fig8_waveform(pressures_Pa=FIG8_PRESSURES_PA, frequency_Hz: float = FIG8_FREQUENCY_HZ) -> Staircase:
    return Staircase(tuple(pressures_Pa), frequency_Hz)


def run_fig7(cycles: int = 5, *, params: DeviceParams | None = None, dt_out: float | None = None,
             options: SolverOptions | None = None, progress: bool = False) -> DeviceResult:
    """Fig. 7: the flat device under a 10 N, 5 Hz square wave for ``cycles`` periods."""
    cycles = int(positive("cycles", cycles))
    p = params or fig7_params()
    wf = fig7_waveform(area_m2=p.area_m2)
    return simulate(p, wf, cycles * wf.period, dt_out=dt_out, options=options, progress=progress)


def run_fig8(area_table=None, *, params: DeviceParams | None = None, quick: bool = False,
             dt_out: float | None = None, options: SolverOptions | None = None,
             progress: bool = False) -> DeviceResult:
    """Fig. 8: group A under the 10 -> 150 kPa staircase at 2 Hz, A(P) from ``area_table``.

    Without a table, ``tengsim.paper.area_table("A", quick=quick)`` (the contact engine) is called.
    """
    if params is None:
        if area_table is None:
            from tengsim.paper import area_table as engine_table

            area_table = engine_table("A", quick=quick)
        params = fig8_params(area_table)
    wf = fig8_waveform()
    return simulate(params, wf, wf.duration, dt_out=dt_out or 1e-4, options=options, progress=progress)


def fig7_summary(result: DeviceResult, skip_cycles: int = 1) -> dict:
    """Peak V, peak I, V_OC and I_SC over settled cycles (the first ``skip_cycles`` dropped)."""
    s = result.summary(skip_cycles)
    keys = ("peak_voltage_V", "peak_current_A", "voc_V", "isc_A", "energy_per_cycle_J", "average_power_W",
            "net_charge_per_cycle_C", "settled_cycles")
    return {k: s[k] for k in keys}


def fig8_summary(result: DeviceResult) -> dict:
    """V_OC per pressure step: the largest Eq. (17) voltage after that step's release (Fig. 8b)."""
    wf = result.waveform
    require(hasattr(wf, "amplitudes_Pa"), "fig8_summary needs a Staircase run")
    per = wf.period
    steps, vocs = [], []
    for k, amp in enumerate(wf.amplitudes_Pa):
        m = (result.t >= (k + wf.duty) * per) & (result.t < (k + 1) * per)
        vocs.append(float(np.max(result.V_oc[m])) if np.any(m) else math.nan)
        steps.append(float(amp))
    peak_v = [float(np.max(np.abs(result.V[(result.t >= k * per) & (result.t < (k + 1) * per)])))
              if np.any((result.t >= k * per) & (result.t < (k + 1) * per)) else math.nan
              for k in range(len(steps))]
    return {"pressure_steps_Pa": steps, "voc_steps_V": vocs, "peak_voltage_steps_V": peak_v,
            "area_fraction_steps": [float(result.params.area(p)) for p in steps]}
