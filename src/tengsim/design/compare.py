"""Several designs side by side: one table (compare.csv) and one figure (compare.png)."""
from __future__ import annotations

from pathlib import Path

import numpy as np

COLUMNS = ("status", "tabor", "jump_in_Pa", "pull_off_N", "pull_off_Pa", "full_contact_Pa",
           "sensitivity_V_per_Pa", "sensitivity_to_Pa", "sensitivity_rel_per_Pa", "knee_Pa",
           "sensitivity_above_knee_V_per_Pa", "saturation_Pa", "linear_range_Pa", "linear_r2",
           "voc_hysteresis_fraction",
           "hysteresis_J_m2", "area_at_p_max", "voc_eq12_at_p_max_V",
           "voc_eq17_at_p_max_V", "grids", "tolerance")


def compare_table(results) -> dict:
    """{column: array}: one row per design (its name, shape and the per-design numbers, SI)."""
    cols = {"design": np.array([r.plan.name for r in results]), "shape": np.array([r.plan.shape for r in results])}
    for c in COLUMNS:
        vals = [r.summary.get(c) for r in results]
        cols[c] = np.array(vals, dtype=object if any(isinstance(v, str) for v in vals) else float)
    return cols


def write_comparison(results, out_dir) -> list:
    """compare.csv and compare.png in ``out_dir`` (each design's own files in a folder of its own)."""
    from tengsim.design.plots import _plt, compare_figure
    from tengsim.io import csv_text, write_text

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    write_text(out / "compare.csv", csv_text(compare_table(results), missing=""))
    from tengsim.io import save_figure

    fig = compare_figure(results)
    try:
        save_figure(fig, out / "compare.png", dpi=110)  # atomic, as every figure
    finally:
        _plt().close(fig)
    return [out / "compare.csv", out / "compare.png"]
