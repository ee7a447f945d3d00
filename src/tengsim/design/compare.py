"""Several designs side by side: one table (compare.csv) and one figure (compare.png)."""
from __future__ import annotations

from pathlib import Path

import numpy as np

COLUMNS = ("status", "tabor", "jump_in_Pa", "pull_off_N", "pull_off_Pa", "full_contact_Pa",
           "sensitivity_V_per_Pa", "sensitivity_to_Pa", "sensitivity_rel_per_Pa", "knee_Pa",
           "sensitivity_above_knee_V_per_Pa", "saturation_Pa", "linear_range_Pa", "linear_r2",
           "voc_hysteresis_fraction",
           "hysteresis_J_m2", "area_at_p_max", "voc_eq12_at_p_max_V",
           "voc_eq17_at_p_max_V", "voc_finite_at_p_max_V", "grids", "tolerance")


def _area(r) -> float:
    a = r.summary.get("area_at_p_max")
    return float(a) if a is not None and np.isfinite(float(a)) else np.nan


def held(r) -> tuple:
    """(σ A/S at p_max, the air-breakdown cap, the charge density the device holds: the smaller; C/m²)."""
    from tengsim.design.breakdown import breakdown_cap

    p = r.plan
    cap = breakdown_cap(float(p.eps_r), float(p.T), float(p.gap))
    q = float(p.sigma) * _area(r)
    return q, cap, min(q, cap) if np.isfinite(q) else np.nan


def ranked(results) -> list:
    """The designs ranked by their charged area A/S at p_max (largest first; NaN last): V_OC (Eq. 12 and 17) goes
    as A/S, a device's power as its square. When a design's σ A/S exceeds its air-breakdown cap (issue 51;
    tengsim.design.breakdown), by the charge density each device can hold, min(σ A/S, cap), then by A/S."""
    rows = [(r, *held(r)) for r in results]
    capped = any(np.isfinite(q) and q > cap for _, q, cap, _ in rows)

    def key(row):
        r, _, _, h = row
        a = _area(r)
        by_area = -a if np.isfinite(a) else np.inf
        return ((-h if np.isfinite(h) else np.inf), by_area) if capped else (by_area,)
    return [row[0] for row in sorted(rows, key=key)]


def compare_table(results) -> dict:
    """{column: array}: one row per design, ranked by A/S at p_max (:func:`ranked`; its name, shape, boundary,
    charged-area definition and the per-design numbers, SI)."""
    results = ranked(results)
    cols = {"rank": np.arange(1, len(results) + 1),
            "design": np.array([r.plan.name for r in results]), "shape": np.array([r.plan.shape for r in results]),
            "boundary": np.array([getattr(r.plan, "boundary", "") for r in results]),
            "area_definition": np.array([getattr(r.plan, "area", "contact") for r in results])}
    for c in COLUMNS:
        vals = [r.summary.get(c) for r in results]
        cols[c] = np.array(vals, dtype=object if any(isinstance(v, str) for v in vals) else float)
    h = np.array([held(r) for r in results], float).reshape(-1, 3)
    cols["sigma_area_at_p_max_C_m2"], cols["sigma_breakdown_C_m2"], cols["held_charge_C_m2"] = h.T
    return cols


def write_comparison(results, out_dir) -> list:
    """compare.csv and compare.png in ``out_dir`` (each design's own files in a folder of its own)."""
    from tengsim.design.plots import compare_figure
    from tengsim.plots import pyplot
    from tengsim.io import csv_text, write_text

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    write_text(out / "compare.csv", csv_text(compare_table(results), missing=""))
    from tengsim.io import save_figure

    fig = compare_figure(results)
    try:
        save_figure(fig, out / "compare.png", dpi=110)  # atomic, as every figure
    finally:
        pyplot().close(fig)
    return [out / "compare.csv", out / "compare.png"]
