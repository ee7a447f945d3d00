"""The paper (Section 3 contact groups, Section 4 Eq. 12, Section 5 Figs. 7-8) as a layer on the core.

* :mod:`~tengsim.cases.paper.contact`: pyramid groups A, B, C, their runs, summaries and A(P) tables;
* :mod:`~tengsim.cases.paper.device`: the Fig. 7 and Fig. 8 devices, waveforms, runs and summaries;
* :mod:`~tengsim.cases.paper.reproduce`: Figs. 3, 4, 5, 7, 8 with data and summary.json.
"""
from tengsim.cases.paper.contact import (FIG3_D, GROUPS, PAPER_TRANSITION_D, RunSettings, area_table,
                                         area_table_from_load_result, area_table_from_result,
                                         area_table_load_controlled, compare_area_tables, contact_summary,
                                         group_shape, run_group, run_group_load)
from tengsim.cases.paper.device import (FIG7_FORCE_N, FIG7_FREQUENCY_HZ, FIG8_FREQUENCY_HZ, FIG8_PRESSURES_PA,
                                        fig7_params, fig7_summary, fig7_waveform, fig8_area_table, fig8_params,
                                        fig8_summary, fig8_waveform, run_fig7, run_fig8)
from tengsim.cases.paper.reproduce import FIG5_EPS_R, FIG5_SIGMA, FIG5_T, reproduce, summary_text
from tengsim.cases.paper.units import PAPER_GROUPS, PaperScaling, paper_scaling

__all__ = ["FIG3_D", "GROUPS", "PAPER_GROUPS", "PAPER_TRANSITION_D", "RunSettings", "area_table",
           "area_table_from_result", "area_table_from_load_result", "area_table_load_controlled",
           "compare_area_tables", "contact_summary", "group_shape", "run_group", "run_group_load", "paper_scaling", "PaperScaling",
           "FIG7_FORCE_N", "FIG7_FREQUENCY_HZ", "FIG8_FREQUENCY_HZ", "FIG8_PRESSURES_PA", "fig7_params",
           "fig7_summary", "fig7_waveform", "fig8_area_table", "fig8_params", "fig8_summary", "fig8_waveform",
           "run_fig7", "run_fig8", "FIG5_EPS_R", "FIG5_SIGMA", "FIG5_T", "reproduce", "summary_text"]
