"""The inputs of a device run from the command line: the config file, the options typed by their tables, the paths.

:func:`read` reads a config file (:func:`tengsim.schema.read_config`); :func:`options` gathers the options given as
{table: {key: raw value}} and :func:`typed` types them by the table's own fields (an error names the option);
:func:`area_beside` finds an area file beside its config; :func:`out_path`, :func:`guard` check the output before
anything runs; :func:`warn_unconverged` says when the area comes from a design that is not converged.
"""
from __future__ import annotations

import dataclasses
import sys
from pathlib import Path

from tengsim.errors import require

# CLI option -> (table, key)
OPTIONS = {"out": ("run", "out"), "cycles": ("run", "cycles"), "t_end": ("run", "t_end"), "dt": ("run", "dt_out"),
            "quick": ("run", "quick"), "load_ohm": ("device", "load_ohm"), "damping": ("device", "damping_ratio"),
            "force_model": ("device", "force_model"), "initial_charge": ("device", "initial_charge"),
            "r_min": ("sweep", "r_min_ohm"), "r_max": ("sweep", "r_max_ohm"), "points": ("sweep", "points"),
            "area_from": ("device", "area"), "mass": ("device", "mass_kg"),
            "stiffness": ("device", "stiffness_N_per_m"), "electrode_area": ("device", "area_m2"),
            "pressure": ("waveform", "amplitude_Pa"), "frequency": ("waveform", "frequency_Hz"),
            "field": ("device", "field")}


def read(path) -> dict:
    if path is None:
        return {}
    from tengsim.schema import read_config

    return read_config(path)


def options(args) -> dict:
    """Options given on the command line, as {table: {key: raw value}}."""
    out = {}
    for opt, (table, key) in OPTIONS.items():
        v = getattr(args, opt, None)
        if v is not None and v != "":
            out.setdefault(table, {})[key] = v
    from tengsim.cli import device_field  # --electrode-side/--electrode-diameter: S and the shape

    for key, v in device_field.device_values(args).items():
        out.setdefault("device", {})[key] = v
    if getattr(args, "air_pressure", None) is not None:
        out["air_pressure_Pa"] = device_field.air_pressure(args)
    return out


def typed(table, values: dict) -> dict:
    """CLI values typed by the table's own fields; an error names the option (--load-ohm, not load_ohm)."""
    names = {key: "--" + opt.replace("_", "-") for opt, (_, key) in OPTIONS.items()}
    if table is None:  # --pressure, --frequency: the square wave's fields
        from tengsim.device.config import waveform_table

        table = waveform_table("square")
    out = {}
    for key, raw in values.items():
        if key == "area":  # --area-from: always a file (a design or contact result), never a number
            from tengsim.device.areas import area_table_from_file

            out[key] = area_table_from_file(raw)
            continue
        f = dataclasses.replace(table.fields[key], name=names.get(key, key))
        out[key] = f.parse(raw)
    return out


def area_beside(cfg: dict, source) -> dict:
    """A [device] area given as a relative path that is not in the working folder but beside the config
    file (``area = "d1/design.nc"`` next to the TOML) is read from there."""
    dev = cfg.get("device")
    area = dev.get("area") if isinstance(dev, dict) else None
    if not source or not isinstance(area, str) or Path(area).is_absolute() or Path(area).exists():
        return cfg
    beside = Path(source).parent / area
    return {**cfg, "device": {**dev, "area": str(beside)}} if beside.exists() else cfg


def out_path(run: dict, case: str) -> Path:
    """The output path (checked by suffix only: nothing is created before every input has been checked)."""
    out = run.get("out")
    require(out, "give --out FILE (or [run] out = 'FILE' in the config)")
    out = Path(out)
    allowed = (".csv",) if case == "sweep" else (".csv", ".nc")
    require(out.suffix.lower() in allowed, f"out must end in {' or '.join(allowed)}, got {str(out)!r}")
    return out


def inputs(cfg: dict, cli: dict, source) -> list:
    """Every file a device run reads: the config file, the area result (a file, or a design folder's
    design.nc) from --area-from or [device] area."""
    out = [source] if source else []
    for area in (cli.get("device", {}).get("area"), (cfg.get("device") or {}).get("area")):
        if isinstance(area, (str, Path)) and len(str(area)) < 4096:
            out.append(str(area))
            if Path(area).is_dir():
                from tengsim.device.areas import DESIGN_FILE

                out.append(str(Path(area) / DESIGN_FILE))
    return out


def guard(out: Path, cfg: dict, cli: dict, source) -> None:
    """The output and its .json sidecar (a .csv output), checked before anything runs: neither may be an input
    (:func:`tengsim.io.check_outputs`), both must be writable."""
    from tengsim.io import check_output

    read_ = inputs(cfg, cli, source)
    check_output(out, read_)
    if out.suffix.lower() == ".csv":
        check_output(out.with_suffix(".json"), read_, what=f"the sidecar of --out {out.name}:")


def warn_unconverged(cfg: dict, cli: dict, quiet: bool) -> None:
    """A warning line when the area comes from a design whose status is not ok (under-resolved, not
    converged): the device then inherits that design's error."""
    for path in inputs(cfg, cli, None):
        p = Path(path)
        if p.suffix.lower() != ".nc" or not p.is_file():
            continue
        try:
            from tengsim.io import read_dataset

            status = str(read_dataset(p).attrs.get("status", "ok"))
        except Exception:  # noqa: BLE001 - the area reader has said what is wrong with it already
            continue
        if status != "ok":
            print(f"tengsim: warning: the area comes from {p}, a design of status {status!r} (not converged to "
                  "its tolerance): the device's numbers carry its error (see its report.md)", file=sys.stderr)
