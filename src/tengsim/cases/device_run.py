"""A planned device run, run: :func:`run_device` of a :class:`~tengsim.cases.device_plan.DevicePlan` gives a
:class:`DeviceRun` (one run: its time series, summary and provenance) or a :class:`LoadSweepRun` (a load sweep: one
row per load, its header); :func:`write_device` writes either as ``tengsim device`` does (the plan's ``out``: a .csv
with its .json sidecar, or a .nc).  Nothing here reads argv or prints: the lines to say are the result's
``messages``.
"""
from __future__ import annotations

import json
from dataclasses import dataclass

from tengsim.cases.device_plan import DevicePlan


@dataclass(frozen=True)
class DeviceRun:
    """One device run: ``result`` (:class:`~tengsim.device.result.DeviceResult`, the time series), ``summary``
    (the numbers ``tengsim device`` prints and writes), ``provenance`` (case, config, config file), ``params`` the
    device run (fig8: with the contact engine's area table), ``messages`` the lines said after the run."""

    plan: DevicePlan
    params: object
    result: object
    summary: dict
    provenance: dict
    messages: tuple = ()


@dataclass(frozen=True)
class LoadSweepRun:
    """A load sweep: ``sweep`` (:class:`~tengsim.device.analysis.SweepResult`), ``columns`` (the .csv's, one row
    per load), ``header`` (the .json sidecar, also the .csv's header), ``optimum_row`` the row of the largest mean
    power, ``messages`` the lines said after the run."""

    plan: DevicePlan
    params: object
    sweep: object
    columns: dict
    header: dict
    optimum_row: int
    messages: tuple = ()


def run_device(plan: DevicePlan):
    """Run ``plan``: a :class:`LoadSweepRun` for a sweep, else a :class:`DeviceRun`."""
    if plan.sweep is not None:
        return _sweep(plan)
    from tengsim.cases.device_field import field_summary, warning
    from tengsim.device import simulate

    params, wf, progress = plan.params, plan.waveform, not plan.quiet
    if plan.area_engine_quick is not None:  # fig8 without an area: the slow contact engine, after every check
        from tengsim.cases.paper import fig8_area_table

        params = params.replace(area=fig8_area_table(plan.area_engine_quick))
    res = simulate(params, wf, plan.t_end, dt_out=plan.dt_out, options=plan.solver, progress=progress)
    field = field_summary(params, res, plan.air_pressure_Pa)  # the device's field, then the run's own numbers
    summary = {**_summary(plan, params, res), **field}
    said = (warning(summary),) if not plan.quiet and warning(summary) else ()
    return DeviceRun(plan, params, res, summary, {"case": plan.case, "config": plan.tables,
                                                  "config_file": plan.source}, said)


def _summary(plan: DevicePlan, params, res) -> dict:
    """The run's own numbers of ``res`` (the field's are added by :func:`tengsim.cases.device_field.field_summary`):
    the case's summary, strict JSON where the run writes it as such (every case but the paper's figures)."""
    from tengsim.io import jsonable

    area = _area_model(params)
    if plan.case == "fig8":
        from tengsim.cases.paper import fig8_summary

        return {"area_model": area, **fig8_summary(res)}
    skip = 1 if (plan.waveform.period and plan.t_end >= 2 * plan.waveform.period - 1e-12) else 0
    if plan.case == "fig7":
        from tengsim.cases.paper import fig7_summary

        return {"area_model": area, **fig7_summary(res, skip)}
    if plan.designed is not None:
        from tengsim.design.device import rest_gap_voltage

        d = plan.designed
        made = d.provenance()  # the design it came from, asked first (the design's floor, then the device's)
        return jsonable({"area_model": d.area_model, **res.summary(skip), **rest_gap_voltage(d, res),
                         "designed_device": made})
    return jsonable({"area_model": area, **res.summary(skip)})


def _area_model(params) -> str:
    """The summary's ``area_model``: which A the device used (:func:`tengsim.device.params.area_model_label`)."""
    from tengsim.device.params import area_model_label

    return area_model_label(params.area)


def _sweep(plan: DevicePlan) -> LoadSweepRun:
    import numpy as np

    from tengsim.device import resistance_sweep
    from tengsim.io import jsonable

    params, wf, s = plan.params, plan.waveform, plan.sweep
    sw = resistance_sweep(params, wf, np.asarray(s.loads_ohm, dtype=float), cycles=s.cycles, steady=s.steady,
                          dt_out=plan.dt_out, options=plan.solver, progress=not plan.quiet)
    k_opt = int(np.nanargmax(sw.average_power_W))  # the optimum's row
    area = _area_model(params)
    head = jsonable({"area_model": area, "params": params.to_dict(), "waveform": wf.to_dict(),
                     "optimum_ohm": sw.optimum_ohm, "optimum_power_W": sw.optimum_power_W,
                     "optimum_peak_power_W": float(sw.peak_power_W[k_opt]), "optimum_at_edge": sw.optimum_at_edge,
                     "run": {"case": "sweep", "cycles": s.cycles, "config": plan.tables,
                             "config_file": plan.source}})
    columns = {"R": sw.load_ohm, "energy_per_cycle": sw.energy_per_cycle_J, "average_power": sw.average_power_W,
               "peak_voltage": sw.peak_voltage_V, "peak_current": sw.peak_current_A, "peak_power": sw.peak_power_W}
    said = ()
    if sw.optimum_at_edge:
        said = (f"tengsim: warning: the mean power is largest at the edge of the swept range (R = "
                f"{sw.optimum_ohm:.4g} ohm): no optimum inside {s.r_min_ohm:.3g}..{s.r_max_ohm:.3g} ohm; widen the "
                "range",)
    return LoadSweepRun(plan, params, sw, columns, head, k_opt, said)


def write_device(run) -> str:
    """Write ``run`` (a :class:`DeviceRun` or :class:`LoadSweepRun`) to its plan's ``out``, as ``tengsim device``
    does; returns where ('dev.csv (+ dev.json)')."""
    from tengsim.io import write_csv, write_dataset, write_json

    out = run.plan.out
    if isinstance(run, LoadSweepRun):
        write_csv(out, run.columns, run.header)
        side = out.with_suffix(".json")
        write_json(side, run.header)
        return f"{out} (+ {side.name})"
    result = run.result
    if out.suffix.lower() == ".nc":
        ds = result.to_dataset()
        ds.attrs["summary"] = json.dumps(run.summary)
        ds.attrs["run"] = json.dumps(run.provenance, default=str)
        write_dataset(ds, out)
        return f"{out}"
    result.write_csv(out)
    side = out.with_suffix(".json")
    write_json(side, {**result.header(), "summary": run.summary, "run": run.provenance})
    return f"{out} (+ {side.name})"


__all__ = ["DeviceRun", "LoadSweepRun", "run_device", "write_device"]
