"""DIR/report.md: a design's status, grids, tolerance, how converged each number is, its numbers and figures."""
from __future__ import annotations

import math

from tengsim.design.plan import BOUNDARY_WHY
from tengsim.units import length_text, pressure_text

ROWS = (
    ("jump_in_Pa", "jump-in pressure (approach under load, just before the first snap into contact in the asked "
                   "range)", "kPa"),
    ("pull_off_N", "pull-off force per cell (most tensile load on the retraction)", "N"),
    ("pull_off_Pa", "pull-off pressure", "kPa"),
    ("full_contact_Pa", "full-contact pressure (A/S reaches 95 % of the footprint's; interpolated)", "kPa"),
    ("hysteresis_J_m2", "hysteresis: energy lost per cycle per unit nominal area (∮F dD over the D range both "
                        "branches cover; 0 where within its uncertainty below)", "J/m²"),
    ("hysteresis_bound_J_m2", "hysteresis uncertainty (± : quadrature rule change, solver residual, jump location)",
     "J/m²"),
    ("area_hysteresis", "hysteresis: largest difference between A/S on the retraction and on the approach at an "
                        "asked pressure (absolute)", ""),
    ("area_at_p_max", "charged area A/S at p_max (approach)", ""),
    ("voc_eq12_at_p_max_V", "V_OC at p_max, Eq. 12 (polymer)", "V"),
    ("voc_eq17_at_p_max_V", "V_OC at p_max, Eq. 17 (rest gap; field: parallel plates)", "V"),
    ("voc_finite_at_p_max_V", "V_OC at p_max, rest gap, field: finite (4 cm² square electrode, the device's)", "V"),
)


def value_text(v, unit: str, why: str = "") -> str:
    if v is None or not math.isfinite(float(v)):
        return f"n/a ({why})" if why else "n/a"
    v = float(v)
    if unit == "kPa":
        return f"{v / 1e3:.4g} kPa"
    if unit == "V/kPa":
        return f"{v * 1e3:.4g} V/kPa"
    return f"{v:.4g} {unit}".strip()


def _pct(x) -> str:
    return "n/a (one grid, or not present on both)" if not math.isfinite(x) else f"{100 * x:.2g} %"


def sensor_lines(numbers) -> list:
    """The '## As a pressure sensor' section: V_OC (Eq. 12) per pressure region, knee, saturation, linear range
    and hysteresis (:mod:`tengsim.device.sensor`), every n/a with its reason."""
    if numbers is None:
        return []
    from tengsim.device.sensor import R2_LINEAR, SATURATION_BAND, describe

    return ["", "## As a pressure sensor (V_OC of Eq. 12 on the approach)", "",
            f"Regions found from the curve (one line where it fits with R² ≥ {R2_LINEAR:g}, else split at the knee; "
            "above "
            f"the saturation pressure, where V_OC stays within {100 * SATURATION_BAND:g} % of its full-scale change, "
            "the saturated region); relative sensitivity = (dV_OC/dP)/V₀, V₀ = V_OC at p_min.", "",
            *describe(numbers)]


def _breakdown_line(result) -> str:
    """The air-breakdown cap on σ A/S and whether the design's exceeds it (tengsim.design.breakdown)."""
    import math

    import numpy as np

    from tengsim.design.breakdown import design_breakdown, report_line
    from tengsim.design.curves import branch_curves

    p = result.plan
    a = np.asarray(branch_curves(result.finest, p)["approach"].get("area", []), float) \
        if hasattr(result, "finest") else np.array([])
    a_max = float(np.nanmax(a)) if a.size and np.any(np.isfinite(a)) else math.nan
    return report_line(design_breakdown(p.sigma, p.eps_r, p.T, p.gap, a_max))


def _nearfield_line(result) -> str:
    """The charged pattern's near field against the uniform σ A/S (tengsim.design.nearfield)."""
    from tengsim.design.nearfield import report_line

    return report_line(result.summary.get("nearfield"))


def report_text(result, figures) -> str:
    p, s = result.plan, result.summary
    lines = [f"# Design: {p.name}", "",
             f"**Status: {s['status']}**, grids: {s['grids']}; tolerance {100 * p.rel_tol:g} % "
             f"(the grid is refined by √2 until the numbers below change by at most that between the last two "
             f"grids); {s['seconds']:.0f} s of solving.", "",
             f"Shape {p.shape} ({p.shape_text()}); "
             f"E* = {p.E_star / 1e6:.4g} MPa, W = {p.W * 1e3:.4g} mJ/m², ε = {length_text(p.eps)}, Tabor number "
             f"μ = {s['tabor']:.3g}.",
             f"Device (Eq. 12 and Eq. 17): σ = {p.sigma * 1e6:.4g} µC/m², ε_r = {p.eps_r:.4g}, "
             f"T = {length_text(p.T)}, "
             f"rest gap d0 = {length_text(p.gap)} (defaults: the paper's 5.84 µC/m², 2.40, 400 µm, 0.1 mm).",
             _breakdown_line(result),
             _nearfield_line(result),
             f"Pressures: {pressure_text(p.pressures[0])} to {pressure_text(p.pressures[-1])}, "
             f"{len(p.pressures)} values.",
             "", f"Charged area ({'the default' if p.area == 'contact' else 'area = paper'}): "
                 f"{s['charged_area_definition']}; the repulsive area (P > 0) is given beside it"
                 f"{'; the contour on the maps is its edge' if p.area == 'contact' else ''}.",
             "", f"Boundary: {p.boundary} ({'given' if p.boundary_given else 'the default for a pattern'}): "
                 f"{BOUNDARY_WHY.get(p.boundary, 'as given')}.", "",
             "## How converged", "", "| number | change between the last two grids |", "|---|---|"]
    lines += [f"| {k} | {_pct(v)} |" for k, v in result.convergence.items()]
    tab = result.finest.params.get("resolution") or {}
    if tab:
        lat = result.finest.scaling.lateral
        lines += ["", "| grid | dx | solve time | status |", "|---|---|---|---|"]
        lines += [f"| {nx}×{ny} | {length_text(dx * lat)} | {sec:.1f} s | {st} |" for nx, ny, dx, sec, st in
                  zip(tab["nx"], tab["ny"], tab["dx"], tab["seconds"], tab["status"])]
        copied = int(result.finest.params.get("retraction_rows_copied", 0))
        same = (f"; {copied} of the retraction's are the approach's, where it retraces the approach's branch "
                "(taken, not solved again)" if copied else "")
        lines += ["", f"The finest grid's path: {len(result.finest.table['D'])} equilibria ("
                  f"{'approach and retraction' if result.plan.retraction else 'the approach only'}), "
                  f"each solved to max|r| ≤ {result.finest.params.get('tol', float('nan')):.2g} ε (the gap's "
                  f"residual; 0.01 × the tolerance){same}."]
    lines += ["", "The per-design numbers below are read from the finest grid's curves; those from A/S (full "
              "contact, sensitivity, linear range, V_OC) move as A/S does.", "",
              "## Numbers", "", "| number | value |", "|---|---|"]
    why = s.get("reasons") or {}
    lines += [f"| {label} | {value_text(s.get(k), u, why.get(k, ''))} |" for k, label, u in ROWS]
    lines += sensor_lines(s.get("sensor"))
    if result.notes:
        lines += ["", "Notes:", *[f"- {n}" for n in result.notes]]
    lines += ["", "## Figures", ""] + [f"![{f}]({f})" for f in figures]
    lines += ["", "Files: design.nc (CF-1.10, SI), design.csv (one row per branch and pressure)."]
    return "\n".join(lines) + "\n"
