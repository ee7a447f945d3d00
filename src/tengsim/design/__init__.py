"""A designer's question in one call: a micro-structure and its materials in physical units → A/S, V_OC and
dV_OC/dP per pressure on approach and retraction, and per design the jump-in, pull-off, full-contact pressure,
linear range and hysteresis, on a grid chosen and refined to a stated tolerance::

    from tengsim.design import plan_design, run_design, write_design
    plan = plan_design({"shape": "pyramid", "pitch": "10um", "base": "5um", "height": "3.5um",
                        "E_star": "1MPa", "W": "50mJ/m2", "eps": "100nm", "p_max": "100kPa", "p_step": "5kPa"})
    result = run_design(plan)          # a frozen DesignResult: .dataset (xarray), .summary, .status
    write_design(result, "d1")         # d1/design.nc, design.csv, design.png, maps.png, report.md

A design file becomes a design's table through :func:`read_design` (tables already read: :func:`design_table`); a
fitted material (``tengsim calibrate``'s material.toml) through :func:`read_material` (:func:`material_table`), and
``plan_design(table, material=material)`` plans the design at it and its uncertainty points, whose band
:func:`predict_bands` runs after the design (:func:`write_bands`: bands.csv, bands.png)::

    mat = read_material("fit/material.toml")
    plan = plan_design(read_design("new.toml"), material=mat)
    result = run_design(plan)
    write_bands(predict_bands(result), "new")
"""
from tengsim.design.bands import predict_bands, write_bands
from tengsim.design.compare import compare_table, write_comparison
from tengsim.design.material import Material, material_table, read_material
from tengsim.design.plan import PAPER_DEVICE, DesignPlan, plan_design
from tengsim.design.run import DesignResult, run_design
from tengsim.design.tables import design_table, read_design
from tengsim.design.write import write_design

__all__ = ["PAPER_DEVICE", "DesignPlan", "DesignResult", "Material", "compare_table", "design_table",
           "material_table", "plan_design", "predict_bands", "read_design", "read_material", "run_design",
           "write_bands", "write_comparison", "write_design"]
