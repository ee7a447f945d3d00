"""The inputs of a device run, checked before anything runs: the values given beside the config (typed by their
tables), the area file beside its config, the output path, the files read, a design's status.

:data:`OPTIONS` names each given value's table and key (``--load-ohm`` is [device] load_ohm); :func:`typed` types
given values by the table's own fields (an error names the option); :func:`area_beside` finds an area file beside
its config; :func:`out_path`, :func:`guard` check the output; :func:`unconverged` says, as lines, when the area comes
from a design that is not converged.  Used by :func:`tengsim.cases.device_plan.plan_device`.
"""
from __future__ import annotations

import dataclasses
from pathlib import Path

from tengsim.errors import require

# a given value (the CLI's option) -> (table, key)
OPTIONS = {"out": ("run", "out"), "cycles": ("run", "cycles"), "t_end": ("run", "t_end"), "dt": ("run", "dt_out"),
           "quick": ("run", "quick"), "load_ohm": ("device", "load_ohm"), "damping": ("device", "damping_ratio"),
           "force_model": ("device", "force_model"), "initial_charge": ("device", "initial_charge"),
           "r_min": ("sweep", "r_min_ohm"), "r_max": ("sweep", "r_max_ohm"), "points": ("sweep", "points"),
           "area_from": ("device", "area"), "mass": ("device", "mass_kg"),
           "stiffness": ("device", "stiffness_N_per_m"), "electrode_area": ("device", "area_m2"),
           "pressure": ("waveform", "amplitude_Pa"), "frequency": ("waveform", "frequency_Hz"),
           "field": ("device", "field")}


def typed(table, values: dict) -> dict:
    """Given values typed by the table's own fields; an error names the option (--load-ohm, not load_ohm)."""
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


def inputs(cfg: dict, given: dict, source) -> list:
    """Every file a device run reads: the config file, the area result (a file, or a design folder's
    design.nc) given (--area-from) or in [device] area."""
    out = [source] if source else []
    for area in (given.get("device", {}).get("area"), (cfg.get("device") or {}).get("area")):
        if isinstance(area, (str, Path)) and len(str(area)) < 4096:
            out.append(str(area))
            if Path(area).is_dir():
                from tengsim.device.areas import DESIGN_FILE

                out.append(str(Path(area) / DESIGN_FILE))
    return out


def guard(out: Path, cfg: dict, given: dict, source) -> None:
    """The output and its .json sidecar (a .csv output), checked before anything runs: neither may be an input
    (:func:`tengsim.io.check_outputs`), both must be writable."""
    from tengsim.io import check_output

    read_ = inputs(cfg, given, source)
    check_output(out, read_)
    if out.suffix.lower() == ".csv":
        check_output(out.with_suffix(".json"), read_, what=f"the sidecar of --out {out.name}:")


def unconverged(cfg: dict, given: dict) -> list:
    """A warning line for each area file that is a design whose status is not ok (under-resolved, not
    converged): the device then inherits that design's error."""
    from tengsim.status.levels import Status

    lines = []
    for path in inputs(cfg, given, None):
        p = Path(path)
        if p.suffix.lower() != ".nc" or not p.is_file():
            continue
        try:
            from tengsim.io import read_dataset

            status = str(read_dataset(p).attrs.get("status", Status.OK))
        except Exception:  # noqa: BLE001 - the area reader has said what is wrong with it already
            continue
        if status != Status.OK:
            lines.append(f"tengsim: warning: the area comes from {p}, a design of status {status!r} (not converged "
                         "to its tolerance): the device's numbers carry its error (see its report.md)")
    return lines


def given_area(cfg: dict, given: dict):
    """The area as given (--area-from) or in [device] area (the raw value: a path, a table, or None)."""
    return (given or {}).get("device", {}).get("area") or (cfg.get("device") or {}).get("area")


def area_source(cfg: dict, given: dict) -> str:
    """Where a run's area table came from, for its errors."""
    raw = given_area(cfg, given)
    return f"A/S(P) from {raw}" if isinstance(raw, str) else "the [device] area table"


def unit_of(raw, key: str) -> str:
    """The unit the user gave ``raw`` in ('-5kPa' → 'kPa'), or the key's SI unit for a bare number."""
    import re

    from tengsim.units import _NUM, _compact

    m = re.fullmatch(f"({_NUM})(.*)", _compact(raw)) if isinstance(raw, str) else None
    return m.group(2) if m and m.group(2) else key.rsplit("_", 1)[-1]


def as_given(raw, key: str) -> str:
    """'-5 kPa' of '-5kPa': the value in the user's own unit."""
    import re

    from tengsim.units import _NUM, _compact

    m = re.match(_NUM, _compact(raw)) if isinstance(raw, str) else None
    return f"{m.group(0) if m else raw} {unit_of(raw, key)}"
