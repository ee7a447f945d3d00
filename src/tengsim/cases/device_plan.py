"""A device run, planned: every input of ``tengsim device`` checked before anything runs, as one frozen value.

:func:`plan_device` takes a case (fig7 and fig8, the paper's devices; run, the [device] of the tables as given;
sweep, a load sweep; design, the device a design result describes), the config tables, the values given beside
them (the CLI's options, as {table: {key: raw value}}) and the config's path, and returns a :class:`DevicePlan`
(or raises :class:`~tengsim.errors.TengsimError`, one line, nothing written).  :func:`tengsim.cases.device_run.
run_device` runs it.  The plan's ``messages`` are the lines the run says before it starts (notes, warnings), in
order; ``quiet`` keeps the notes out, never the warnings.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path

from tengsim.cases import device_inputs as given
from tengsim.errors import TengsimError, require

CASES = ("fig7", "fig8", "run", "sweep", "design")
DEFAULT_CYCLES = {"fig7": 5, "run": 5, "sweep": 3, "design": 5}
MAX_SWEEP_POINTS = 10_000
"""The most loads one sweep may hold (each is a multi-cycle device run)."""


@dataclass(frozen=True)
class SweepLoads:
    """The loads of a load sweep (ohm, log-spaced from ``r_min_ohm`` to ``r_max_ohm``), the periods run at each
    (the first dropped) and whether each load runs to its steady cycle."""

    loads_ohm: tuple
    r_min_ohm: float
    r_max_ohm: float
    cycles: int
    steady: object


@dataclass(frozen=True)
class DevicePlan:
    """One device run, checked: the device ``params`` and ``waveform`` it runs, until ``t_end`` (s; None for a
    sweep, whose length is its ``sweep.cycles``), sampled every ``dt_out`` (s, None: the integrator's own), with
    the integrator's ``solver`` options; ``out`` the file it writes; ``tables`` the config tables as used and
    ``source`` their file (the run's provenance); ``designed`` the designed device (case design);
    ``area_engine_quick`` whether fig8's area table is still to be built by the contact engine (None: it is given);
    ``air_pressure_Pa`` Paschen's (None: 1 atm); ``messages`` the lines said before it runs."""

    case: str
    params: object
    waveform: object
    out: Path
    solver: object
    t_end: float | None = None
    dt_out: float | None = None
    tables: dict = dataclasses.field(default_factory=dict)
    source: str | None = None
    quiet: bool = False
    messages: tuple = ()
    designed: object = None
    area_engine_quick: bool | None = None
    air_pressure_Pa: float | None = None
    sweep: SweepLoads | None = None


def plan_device(case: str, tables: dict | None = None, overrides: dict | None = None, source: str | None = None,
                quiet: bool = False) -> DevicePlan:
    """The checked plan of device ``case`` from config ``tables`` and the given values ``overrides`` ({table:
    {key: raw value}}, as :data:`tengsim.cases.device_inputs.OPTIONS` names them; they win over the tables, which
    win over the case's default); ``source``: the config file's path (its folder holds relative area files)."""
    from tengsim.device import config as dc

    require(case in CASES, f"device case {case!r}: one of {', '.join(CASES)}")
    cfg, cli = dict(tables or {}), dict(overrides or {})
    said = []
    dc.check_device_tables(cfg, source or "config")
    cfg = given.area_beside(cfg, source)
    ignored = []  # keys of the other command (run <-> sweep) in a config that serves both
    if "sweep" in cfg and case != "sweep":
        if case != "run":
            raise TengsimError(f"[sweep] is used only by the sweep case, not {case}")
        ignored.append("[sweep]")
    run = {**dc.parse_run(cfg.get("run", {}), case, ignored), **given.typed(dc.RUN_TABLE, cli.get("run", {}))}
    if case == "sweep" and "load_ohm" in cfg.get("device", {}):
        ignored.append("[device] load_ohm")
        cfg = {**cfg, "device": {k: v for k, v in cfg["device"].items() if k != "load_ohm"}}
    if ignored and not quiet:
        other = "run" if case == "sweep" else "sweep"
        said.append(f"tengsim: note: the {case} does not use {', '.join(ignored)} (used by `tengsim device {other}`)")
    dev_cli = given.typed(dc.DEVICE_TABLE, cli.get("device", {}))
    solver = dc.parse_solver(cfg.get("solver", {}))
    out = given.out_path(run, case)
    given.guard(out, cfg, cli, source)
    said += given.unconverged(cfg, cli)
    plan = dict(case=case, out=out, solver=solver, tables=cfg, source=source, quiet=quiet,
                air_pressure_Pa=cli.get("air_pressure_Pa"))
    if case == "sweep":
        return _sweep(plan, cfg, cli, run, dev_cli, said)
    from tengsim.device.config import check_pressures

    designed = None
    if case == "design":
        designed = _designed(cfg, cli, dev_cli)
        params, wf = designed.params, designed.waveform
    else:
        params, wf = _device_and_waveform(case, cfg, dev_cli)
        params = _viscoelastic(case, cfg, cli, params, wf)
    if case == "fig8":
        n = len(wf.amplitudes_Pa)
        cycles = run.get("cycles", n)
        require(cycles <= n, f"cycles = {cycles} but the staircase has {n} steps (give at most {n})")
        wf = dataclasses.replace(wf, amplitudes_Pa=wf.amplitudes_Pa[:cycles])
        check_pressures(params.area, wf, wf.duration, given.area_source(cfg, cli))
        said += _paper_device_note(case, cfg, dev_cli, quiet)
        quick = None
        if "area" not in cfg.get("device", {}) and "area" not in dev_cli:  # the slow engine: run_device builds it
            quick = bool(run.get("quick", False))
        return DevicePlan(params=params, waveform=wf, t_end=wf.duration, dt_out=run.get("dt_out", 1e-4),
                          messages=tuple(said), area_engine_quick=quick, **plan)
    t_end = run.get("t_end")
    if t_end is None:
        per = wf.period or wf.duration
        require(per is not None, "give --t-end (or [run] t_end) for a waveform with no period")
        t_end = run.get("cycles", DEFAULT_CYCLES[case]) * per
    check_pressures(params.area, wf, t_end, given.area_source(cfg, cli),
                    " (--pressure)" if designed is not None else "")
    if designed is not None and not quiet:  # after every check: an error stays one line
        said += [f"tengsim: {line}" for line in designed.lines()]
    said += [f"tengsim: warning: {line}" for line in (designed.warnings() if designed is not None else [])]
    said += _paper_device_note(case, cfg, dev_cli, quiet)
    return DevicePlan(params=params, waveform=wf, t_end=t_end, dt_out=run.get("dt_out"), messages=tuple(said),
                      designed=designed, **plan)


def _sweep(plan: dict, cfg, cli, run, dev_cli, said) -> DevicePlan:
    import numpy as np

    from tengsim.device import config as dc
    from tengsim.device.config import check_pressures
    from tengsim.resources import check_count

    sw_cfg = {**dc.SWEEP_TABLE.parse(cfg.get("sweep", {})), **given.typed(dc.SWEEP_TABLE, cli.get("sweep", {}))}
    r_min, r_max, points = sw_cfg["r_min_ohm"], sw_cfg["r_max_ohm"], sw_cfg["points"]
    require(0 < r_min < r_max, f"need 0 < r_min < r_max, got {r_min!r}, {r_max!r}")
    require(points >= 2, f"points must be >= 2, got {points!r}")
    check_count(points, "the load sweep's points", MAX_SWEEP_POINTS)  # before a load array is made
    cycles = run.get("cycles", DEFAULT_CYCLES["sweep"])
    require(cycles >= 2, f"cycles must be >= 2 for a sweep (the first is dropped), got {cycles!r}")
    params, wf = _device_and_waveform("sweep", cfg, dev_cli)
    params = _viscoelastic("sweep", cfg, cli, params, wf)
    loads = np.logspace(np.log10(r_min), np.log10(r_max), points)
    check_pressures(params.area, wf, cycles * wf.period, given.area_source(cfg, cli))
    said += _paper_device_note("sweep", cfg, dev_cli, plan["quiet"])
    sweep = SweepLoads(tuple(float(r) for r in loads), r_min, r_max, cycles, sw_cfg["steady"])
    return DevicePlan(params=params, waveform=wf, dt_out=run.get("dt_out"), messages=tuple(said), sweep=sweep,
                      **plan)


def _device_and_waveform(case, cfg, dev_cli):
    """The case's device and waveform with the [device] and [waveform] tables and the given values applied."""
    from tengsim.device import config as dc

    base_wf = None
    if case in ("fig7", "sweep"):
        from tengsim.cases.paper import fig7_params, fig7_waveform

        params = dc.parse_device(cfg.get("device", {}), fig7_params(), dev_cli)
        base_wf = fig7_waveform(area_m2=params.area_m2)
    elif case == "fig8":
        from tengsim.cases.paper import fig8_params, fig8_waveform
        from tengsim.device import ConstantArea

        params = dc.parse_device(cfg.get("device", {}), fig8_params(ConstantArea(1.0)), dev_cli)
        base_wf = fig8_waveform()
    else:
        require("device" in cfg, "device run needs a config with [device] and [waveform] (--config FILE)")
        params = dc.parse_device(cfg["device"], None, dev_cli)
        require("waveform" in cfg, "device run needs a [waveform] table in its config (kind = square, ...)")
    wf = dc.parse_waveform(cfg["waveform"], base_wf) if "waveform" in cfg else base_wf
    if case == "fig8":
        from tengsim.device import Staircase

        require(isinstance(wf, Staircase), f"fig8 needs [waveform] kind = 'staircase', got {wf.to_dict()['kind']!r} "
                "(use `tengsim device run` for other waveforms)")
    if case == "sweep":
        require(getattr(wf, "period", None) is not None, "a load sweep needs a periodic waveform")
    return params, wf


def _viscoelastic(case, cfg, cli, params, wf):
    """``params`` with the viscoelastic A(t) of a design result with cycles given as the area (--area-from, [device]
    area), as `device design` takes it (:func:`tengsim.device.areas.area_cycle_for_waveform`): never its quasi-static
    A(P) in silence; a waveform that is none of its recorded presses is one line."""
    from tengsim.device.areas import area_cycle_for_waveform, design_visco_record

    raw = given.given_area(cfg, cli)
    if not isinstance(raw, (str, Path)) or design_visco_record(raw) is None:
        return params
    rec = design_visco_record(raw)
    if case == "fig8":  # its staircase is no press a design records
        raise TengsimError(f"device fig8 --area-from {raw}: the design's viscoelastic cycles press to "
                           f"{rec['p_max_Pa'] / 1e3:.4g} kPa only, the staircase to {len(wf.amplitudes_Pa)} pressures: "
                           "run its square or sine press with `tengsim device design --area-from` (or `device run`), or "
                           "give a design without --relaxation for the quasi-static A(P)")
    cycle = area_cycle_for_waveform(raw, wf, float(params.area(rec["p_max_Pa"])),
                                    where=f"device {case} --area-from {raw}")
    return params.replace(area=cycle)


def _designed(cfg, cli, dev_cli):
    """The designed device (:func:`tengsim.design.device.designed_device`) of ``device design``."""
    from tengsim.design.device import designed_device
    from tengsim.device import config as dc

    raw = given.given_area(cfg, cli)
    require(isinstance(raw, str), "device design needs a design result: give --area-from DIR/design.nc (or [device] "
                                  "area = 'DIR/design.nc')")
    dev = {**dc.DEVICE_TABLE.parse({k: v for k, v in (cfg.get("device") or {}).items() if k != "area"},
                                   defaults=False), **{k: v for k, v in dev_cli.items() if k != "area"}}
    for opt in ("mass", "stiffness", "electrode_area"):
        key = given.OPTIONS[opt][1]
        if key in dev_cli and not dev_cli[key] > 0:
            raise TengsimError(f"--{opt.replace('_', '-')} must be > 0, got {cli['device'][key]!r}")
    wcli = given.typed(None, cli.get("waveform", {}))
    for opt in ("pressure", "frequency"):
        key = given.OPTIONS[opt][1]
        if key in wcli and not wcli[key] > 0:
            raise TengsimError(f"the {opt} must be > 0 {given.unit_of(cli['waveform'][key], key)}, got "
                               f"{given.as_given(cli['waveform'][key], key)}")
    return designed_device(raw, dev, cfg.get("waveform"), wcli.get("amplitude_Pa"), wcli.get("frequency_Hz"))


def _paper_device_note(case, cfg, dev_cli, quiet) -> list:
    """fig7/fig8/sweep with a design's area: the paper's device with the design's A/S, said once."""
    raw = (cfg.get("device") or {}).get("area")
    if quiet or case not in ("fig7", "fig8", "sweep") or not ("area" in dev_cli or isinstance(raw, str)):
        return []
    return [f"tengsim: note: {case} is the paper's device (its σ, ε_r, T, rest gap, mass, spring and waveform) with "
            "this A/S(P); `tengsim device design --area-from DIR/design.nc` runs the device the design describes"]


__all__ = ["CASES", "DevicePlan", "SweepLoads", "plan_device", "MAX_SWEEP_POINTS"]
