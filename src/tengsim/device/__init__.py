"""Device model: voltage from contact area (Section 4) and the dynamic TENG model (Section 5)."""
from tengsim.device.dynamics import simulate
from tengsim.device.params import EPS0, AreaTable, ConstantArea, DeviceParams, SolverOptions
from tengsim.device.paper import (fig7_params, fig7_summary, fig7_waveform, fig8_params, fig8_summary,
                                  fig8_waveform, run_fig7, run_fig8)
from tengsim.device.result import DeviceResult
from tengsim.device.waveforms import Sine, SquareWave, Staircase, TableWaveform, waveform_from_dict
from tengsim.device.formulas import (CMEOCycle, cmeo_cycle, eq20_force, electrostatic_energy, field_force,
                                     fom_structural, isc_apart, qsc_apart, voc_apart, voc_from_contact_length,
                                     voc_polymer, voltage)
from tengsim.device.analysis import (FigureOfMerit, ResistanceSweep, StaticVoltageCurve, VQCycle, figure_of_merit,
                                     resistance_sweep, steady_charge, voc_from_area, vq_cycle)
