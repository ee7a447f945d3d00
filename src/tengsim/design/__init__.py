"""A designer's question in one call: a micro-structure and its materials in physical units → A/S, V_OC and
dV_OC/dP per pressure on approach and retraction, and per design the jump-in, pull-off, full-contact pressure,
linear range and hysteresis, on a grid chosen and refined to a stated tolerance::

    from tengsim.design import plan_design, run_design, write_design
    plan = plan_design({"shape": "pyramid", "pitch": "10um", "base": "5um", "height": "3.5um",
                        "E_star": "1MPa", "W": "50mJ/m2", "eps": "100nm", "p_max": "100kPa", "p_step": "5kPa"})
    result = run_design(plan)          # a frozen DesignResult: .dataset (xarray), .summary, .status
    write_design(result, "d1")         # d1/design.nc, design.csv, design.png, maps.png, report.md
"""
from tengsim.design.compare import compare_table, write_comparison
from tengsim.design.plan import PAPER_DEVICE, DesignPlan, plan_design
from tengsim.design.run import DesignResult, run_design
from tengsim.design.write import write_design

__all__ = ["PAPER_DEVICE", "DesignPlan", "DesignResult", "compare_table", "plan_design", "run_design",
           "write_comparison", "write_design"]
