"""Device model: voltage from contact area (Section 4) and the dynamic TENG model (Section 5).

The core of the device: it takes an area model (a fraction, an :class:`AreaTable`, or any callable
pressure -> A/S) and a waveform (:data:`WAVEFORMS`), and knows nothing of the paper's cases, which
live in :mod:`tengsim.cases.paper`.
"""
from tengsim.device.dynamics import simulate
from tengsim.constants import EPS0
from tengsim.device.params import (AreaCycle, AreaFunction, AreaTable, ConstantArea, DeviceParams, SolverOptions,
                                   area_model)
from tengsim.device.result import DeviceResult
from tengsim.device.waveforms import WAVEFORMS, Sine, SquareWave, Staircase, TableWaveform
from tengsim.device.areas import area_table_from_design
from tengsim.device.config import parse_device, parse_waveform
from tengsim.device.formulas import (CMEOCycle, cmeo_cycle, eq20_force, electrostatic_energy, field_force,
                                     fom_structural, isc_apart, qsc_apart, voc_apart,
                                     voc_from_contact_length, voc_polymer, voltage)
from tengsim.device.analysis import (FigureOfMerit, ResistanceSweep, StaticVoltageCurve, VQCycle, figure_of_merit,
                                     resistance_sweep, staircase_summary, steady_charge, steady_start, voc_from_area,
                                     vq_cycle)

__all__ = ["simulate", "EPS0", "AreaCycle", "AreaFunction", "AreaTable", "ConstantArea", "DeviceParams",
           "SolverOptions", "area_model", "DeviceResult", "WAVEFORMS", "Sine", "SquareWave", "Staircase",
           "TableWaveform", "area_table_from_design", "parse_device", "parse_waveform", "CMEOCycle", "cmeo_cycle",
           "eq20_force", "electrostatic_energy", "field_force", "fom_structural", "isc_apart", "qsc_apart",
           "voc_apart", "voc_from_contact_length", "voc_polymer", "voltage", "FigureOfMerit", "ResistanceSweep",
           "StaticVoltageCurve", "VQCycle", "figure_of_merit", "resistance_sweep", "staircase_summary",
           "steady_charge", "steady_start", "voc_from_area", "vq_cycle"]

_MOVED = {"fig7_params", "fig7_summary", "fig7_waveform", "fig8_params", "fig8_summary", "fig8_waveform",
          "run_fig7", "run_fig8"}
_RENAMED = {"waveform_from_dict": "tengsim.device.parse_waveform (tengsim.device.config, the one parser)",
            "trapezoid": "scipy.integrate.trapezoid"}


def __getattr__(name):
    if name in _MOVED:
        raise AttributeError(f"tengsim.device.{name} moved to tengsim.cases.paper (the paper's cases are a layer "
                             f"on top of the device model): from tengsim.cases.paper import {name}")
    if name in _RENAMED:
        raise AttributeError(f"tengsim.device.{name} was removed: use {_RENAMED[name]}")
    raise AttributeError(f"module 'tengsim.device' has no attribute {name!r}")
