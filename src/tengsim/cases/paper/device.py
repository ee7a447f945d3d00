"""The paper's two dynamic cases: the flat device of Fig. 7 and the group-A device of Fig. 8.

Built on the core device model (:mod:`tengsim.device`); Fig. 8's area model is the A(P) table of the
paper's group-A contact run (:func:`tengsim.cases.paper.contact.area_table`), built here.
"""
from __future__ import annotations

from tengsim.device.analysis import staircase_summary
from tengsim.device.dynamics import simulate
from tengsim.device.params import ConstantArea, DeviceParams, SolverOptions, area_model
from tengsim.device.result import DeviceResult
from tengsim.device.waveforms import SquareWave, Staircase
from tengsim.errors import positive, require
from tengsim.io import jsonable

FIG7_FORCE_N = 10.0
FIG7_FREQUENCY_HZ = 5.0
FIG8_FREQUENCY_HZ = 2.0
FIG8_PRESSURES_PA = tuple(1e4 * k for k in range(1, 16))  # 10 -> 150 kPa by 10 kPa
FIG8_DT_OUT = 1e-4


def fig7_params(**changes) -> DeviceParams:
    """Flat device of Fig. 7 (paper Section 5): A = S, sigma d0/eps0 = 200 V."""
    base = DeviceParams(mass_kg=13.45e-3, stiffness_N_per_m=4 * 1278.88, area_m2=38.71e-4, thickness_m=10e-6,
                        gap_m=1e-3, eps_r=2.40, sigma_C_per_m2=1.77e-6, load_ohm=1e6, area=ConstantArea(1.0))
    return base.replace(**changes) if changes else base


def fig7_waveform(frequency_Hz: float = FIG7_FREQUENCY_HZ, force_N: float = FIG7_FORCE_N,
                  area_m2: float = 38.71e-4) -> SquareWave:
    """10 N over S as a 5 Hz square wave (pressed first)."""
    return SquareWave(force_N / area_m2, frequency_Hz)


def fig8_params(area_table, **changes) -> DeviceParams:
    """Group-A device of Fig. 8 with the charged-area model ``area_table`` (an AreaTable, any object with
    pressure_Pa and area_fraction, or a callable pressure -> A/S)."""
    base = DeviceParams(mass_kg=13.45e-3, stiffness_N_per_m=5.12e3, area_m2=4.00e-4, thickness_m=400e-6,
                        gap_m=0.1e-3, eps_r=2.40, sigma_C_per_m2=5.84e-6, load_ohm=1e6, area=area_model(area_table))
    return base.replace(**changes) if changes else base


def fig8_waveform(pressures_Pa=FIG8_PRESSURES_PA, frequency_Hz: float = FIG8_FREQUENCY_HZ) -> Staircase:
    """The 10 -> 150 kPa staircase at 2 Hz (one pulse per step)."""
    return Staircase(tuple(pressures_Pa), frequency_Hz)


def run_fig7(cycles: int = 5, *, params: DeviceParams | None = None, waveform=None, dt_out: float | None = None,
             options: SolverOptions | None = None, progress: bool = False) -> DeviceResult:
    """Fig. 7: the flat device under a 10 N, 5 Hz square wave (or ``waveform``) for ``cycles`` periods."""
    cycles = int(positive("cycles", cycles))
    p = params or fig7_params()
    wf = waveform or fig7_waveform(area_m2=p.area_m2)
    require(getattr(wf, "period", None) is not None, "run_fig7 needs a periodic waveform")
    return simulate(p, wf, cycles * wf.period, dt_out=dt_out, options=options, progress=progress)


def fig8_area_table(quick: bool = False, progress=None):
    """A(P) of the paper's group A from the contact engine (the Fig. 8 area model)."""
    from tengsim.cases.paper.contact import area_table

    return area_table("A", quick=quick, progress=progress)


def run_fig8(area_table=None, *, params: DeviceParams | None = None, waveform: Staircase | None = None,
             quick: bool = False, dt_out: float | None = None, options: SolverOptions | None = None,
             progress: bool = False) -> DeviceResult:
    """Fig. 8: group A under the 10 -> 150 kPa staircase at 2 Hz, A(P) from ``area_table``.

    Without a table (and without ``params``) the group-A contact run gives it (:func:`fig8_area_table`).
    """
    if params is None:
        params = fig8_params(area_table if area_table is not None else fig8_area_table(quick))
    wf = waveform or fig8_waveform()
    require(isinstance(wf, Staircase), f"Fig. 8 needs a staircase waveform, got {type(wf).__name__}")
    return simulate(params, wf, wf.duration, dt_out=dt_out or FIG8_DT_OUT, options=options, progress=progress)


def fig7_summary(result: DeviceResult, skip_cycles: int = 1) -> dict:
    """Peak V, peak I, V_OC and I_SC over settled cycles (the first ``skip_cycles`` dropped); None if missing."""
    s = result.summary(skip_cycles)
    keys = ("peak_voltage_V", "peak_current_A", "voc_V", "isc_A", "peak_power_W", "energy_per_cycle_J",
            "average_power_W", "net_charge_per_cycle_C", "settled_cycles")
    return jsonable({k: s[k] for k in keys})


def fig8_summary(result: DeviceResult) -> dict:
    """V_OC per pressure step: the largest Eq. (17) voltage after that step's release (Fig. 8b)."""
    return jsonable(staircase_summary(result))


__all__ = ["FIG7_FORCE_N", "FIG7_FREQUENCY_HZ", "FIG8_FREQUENCY_HZ", "FIG8_PRESSURES_PA", "fig7_params",
           "fig7_waveform", "fig8_params", "fig8_waveform", "fig8_area_table", "run_fig7", "run_fig8",
           "fig7_summary", "fig8_summary"]
