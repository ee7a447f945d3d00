"""The field's lines of a device run's summary: the field model, V_OC at the largest gap under both models, the
breakdown-limited σ (Paschen), and the warning when σ A/S exceeds it.

:func:`field_summary` gives the summary's keys (:func:`tengsim.cases.device_run.run_device` adds them to every
single run's summary), :func:`warning` its one warning line.
"""
from __future__ import annotations


def field_summary(params, result, pressure_Pa: float | None = None) -> dict:
    """The field's keys of a run's summary: model, electrode, V_OC at the largest gap under both models,
    sigma_breakdown_C_m2 (open-circuit cap on σ A/S), the short-circuit and the load's, and whether σ A/S exceeds."""
    import numpy as np

    from tengsim.device.breakdown import breakdown_cycle, sigma_breakdown, sigma_breakdown_run
    from tengsim.device.field import electrode_size, gap_coefficients
    from tengsim.device.paschen import ATM_PA, SOURCE
    from tengsim.constants import EPS0

    p = params
    pa = ATM_PA if pressure_Pa is None else pressure_Pa
    s = result.series
    x_max = float(np.max(s["gap"]))
    charged = float(np.max(s["area"])) / p.area_m2  # A/S held in flight
    sa = p.sigma_C_per_m2 * charged * p.area_m2
    size = electrode_size(p.electrode_shape, p.area_m2)
    ci, v = gap_coefficients(p.electrode_shape, size, p.thickness_m, p.eps_r, [x_max])[:2]
    b = sigma_breakdown(p, x_max_m=x_max, pressure_Pa=pa)
    eff = p.sigma_C_per_m2 * charged
    cyc = breakdown_cycle(p, x_max, pa, sigma_area_C_m2=eff) if eff > 0 and x_max > 0 else None
    return {
        "field_model": p.field,
        "electrode": {"shape": p.electrode_shape, "size_m": size, "area_m2": p.area_m2},
        "voc_at_max_gap_V": {"parallel": float(sa * x_max / (EPS0 * p.area_m2)), "finite": float(sa * v[0]),
                             "gap_m": x_max},
        "sigma_breakdown_C_m2": b.sigma_breakdown_C_m2,
        "sigma_breakdown_gap_m": b.gap_at_limit_m,
        "sigma_breakdown_short_C_m2": b.sigma_short_C_m2,
        "sigma_breakdown_load_C_m2": sigma_breakdown_run(result, pa),
        "sigma_times_area_fraction_C_m2": eff,
        "breakdown_exceeded": bool(eff > b.sigma_breakdown_C_m2),
        "air_pressure_Pa": pa,
        "paschen": SOURCE,
        # the CMEO to the run's largest gap after the first stroke's breakdown (quasi-static; docs/device.md)
        "breakdown_cycle": None if cyc is None else {
            "x_max_m": cyc.x_max_m, "sigma_held_C_m2": cyc.sigma_held_C_m2, "energy_J": cyc.energy_J,
            "energy_unlimited_J": cyc.energy_unlimited_J, "fom_structural": cyc.fom_structural},
    }


def warning(summary: dict) -> str:
    """One warning line when σ A/S exceeds the breakdown cap ('' otherwise)."""
    if not summary.get("breakdown_exceeded"):
        return ""
    from tengsim.units import format_si

    return (f"tengsim: warning: σ A/S = {format_si(summary['sigma_times_area_fraction_C_m2'], 'C/m²')} exceeds the "
            f"air-breakdown cap {format_si(summary['sigma_breakdown_C_m2'], 'C/m²')} (Paschen, open circuit, at gap "
            f"{format_si(summary['sigma_breakdown_gap_m'], 'm')}): the gap discharges; the device cannot hold it")
