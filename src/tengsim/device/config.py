"""Config tables of a device run, derived from the dataclasses through the one schema (tengsim.schema).

A device config (``tengsim device CASE --config FILE``, ``tengsim run FILE`` with a [device] table) holds:

* ``[device]``: :class:`DeviceParams` fields (SI; a unit string is read where the field has a dimension);
* ``[waveform]``: ``kind`` (a :data:`WAVEFORMS` name) plus that waveform's dataclass fields;
* ``[run]``: ``case``, ``out``, ``cycles``, ``t_end``, ``dt_out``, ``quick`` (which ones a case uses: :data:`RUN_KEYS`);
* ``[solver]``: :class:`SolverOptions` fields;
* ``[sweep]``: load range of the ``sweep`` case.

Field names, types, defaults and help come from the dataclasses (``dataclasses.fields`` and each field's
``metadata``); the dimension of a number comes from its name's SI suffix (``_Pa``, ``_Hz``, ``_m``, ...).
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np

from tengsim.device.areas import area_table_from_file, stable_branch
from tengsim.device.params import AreaTable, ConstantArea, DeviceParams, SolverOptions
from tengsim.device.waveforms import WAVEFORMS
from tengsim.errors import TengsimError
from tengsim.schema import REQUIRED, Field, Table

# name suffix -> dimension understood by tengsim.units.parse_quantity (first match wins)
SUFFIX_DIMS = (("_N_per_m", "energy/area"), ("_C_per_m2", "charge/area"), ("_Pa", "pressure"),
               ("_Hz", "frequency"), ("_kg", "mass"), ("_ohm", "resistance"), ("_s", "time"), ("_m", "length"))
_KINDS = {"float": "float", "int": "int", "str": "str", "bool": "bool", "tuple": "floats", "np.ndarray": "floats"}

TABLES = ("device", "waveform", "run", "solver", "sweep")
CASES = ("fig7", "fig8", "run", "sweep", "design")
RUN_KEYS = {  # the [run] keys each case uses; any other given key is refused with its name
    "fig7": ("case", "out", "cycles", "t_end", "dt_out"),
    "fig8": ("case", "out", "cycles", "dt_out", "quick"),
    "run": ("case", "out", "cycles", "t_end", "dt_out"),
    "sweep": ("case", "out", "cycles", "dt_out"),
    "design": ("case", "out", "cycles", "t_end", "dt_out"),
}


def dim_of(name: str):
    """Dimension of a config key from its SI suffix, or None (dimensionless, plain number)."""
    for suffix, dim in SUFFIX_DIMS:
        if name.endswith(suffix):
            return dim
    return None


def table_from_dataclass(cls, name: str, *, required: bool = True, special: dict | None = None,
                         doc: str = "") -> Table:
    """A :class:`Table` with one :class:`Field` per dataclass field of ``cls``.

    Kind from the annotation, default from the field (no default -> REQUIRED when ``required``),
    help/dim/choices from the field's metadata (dim otherwise from the name's suffix).
    ``special`` maps a field name to a replacement Field.
    """
    special = special or {}
    out = []
    for f in dataclasses.fields(cls):
        if f.name in special:
            out.append(special[f.name])
            continue
        ann = f.type if isinstance(f.type, str) else getattr(f.type, "__name__", "any")
        kind = _KINDS.get(ann, "any")
        if f.default is not dataclasses.MISSING:
            default = f.default
        elif f.default_factory is not dataclasses.MISSING:
            default = None
        else:
            default = REQUIRED if required else None
        if isinstance(default, float) and not math.isfinite(default):
            default = None
        dim = f.metadata.get("dim", dim_of(f.name))
        out.append(Field(f.name, kind, default, dim=dim, choices=f.metadata.get("choices"),
                         help=f.metadata.get("help", "")))
    return Table(name, out, doc or (cls.__doc__ or "").strip().splitlines()[0])


# --- [device] ---

def _load_ohm(value, label):
    if isinstance(value, str) and value.strip().lower() in ("inf", "open"):
        return math.inf
    if isinstance(value, float) and value == math.inf:
        return math.inf
    return Field("load_ohm", dim="resistance")._number(value, label)


def _is_file(value: str) -> bool:
    """A [device] area given as a path: a design result (.nc, or its folder) or a contact result (.nc, .csv)."""
    from pathlib import Path

    return value.strip().lower().endswith((".nc", ".csv")) or Path(value).is_dir()


def _area(value, label):
    if isinstance(value, dict):
        kind = value.get("kind", "table" if "pressure_Pa" in value else "constant")
        if kind == "constant":
            t = Table("area", [Field("kind", "str", choices=("constant",)),
                               Field("fraction", "float", REQUIRED, help="A/S")])
            return ConstantArea(t.parse(value, where=f"{label}.")["fraction"])
        t = Table("area", [Field("kind", "str", choices=("table",)),
                           Field("pressure_Pa", "floats", REQUIRED, dim="pressure"),
                           Field("area_fraction", "floats", REQUIRED)])
        v = t.parse(value, where=f"{label}.")
        return AreaTable(*stable_branch(v["pressure_Pa"], v["area_fraction"], where=label))
    if isinstance(value, str) and _is_file(value):
        return area_table_from_file(value)
    f = Field("area", "float")._number(value, label)
    return ConstantArea(f)


DEVICE_TABLE = table_from_dataclass(
    DeviceParams, "device", required=False,
    special={"load_ohm": Field("load_ohm", "any", 1.0e6, check=_load_ohm,
                               help="load R in ohm (unit string such as '10MOhm' read); 0 = short, 'inf' = open"),
             "area": Field("area", "any", None, check=_area,
                           help="charged-area model: a fraction A/S (default 1), a table "
                                "{pressure_Pa = [...], area_fraction = [...]} (A(P), linear, ends held; a "
                                "pressure repeated at a snap keeps its first row), a design result "
                                "'DIR/design.nc' (its approach branch) or a physical contact result .nc/.csv "
                                "(approach, A/S = λc²/L²)")},
    doc="DeviceParams fields, SI; a case (fig7, fig8, sweep) supplies any not given, `run` needs the first seven")
REQUIRED_DEVICE = tuple(f.name for f in dataclasses.fields(DeviceParams)
                        if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING)


def parse_device(mapping: dict, base: DeviceParams | None = None, overrides: dict | None = None) -> DeviceParams:
    """DeviceParams from a [device] mapping, then the typed ``overrides`` (CLI options) on top; keys given
    in neither come from ``base`` (the case's device), and without a base the first seven are required."""
    v = {**DEVICE_TABLE.parse(mapping, defaults=False), **(overrides or {})}
    if base is not None:
        return base.replace(**v)
    missing = [k for k in REQUIRED_DEVICE if k not in v]
    if missing:
        raise TengsimError(f"[device] missing key(s) {', '.join(map(repr, missing))} (a device run with no "
                           "case needs all of them; or name a case, e.g. [run] case = 'fig7')")
    return DeviceParams(**v)


# --- [waveform] ---

def waveform_table(kind: str) -> Table:
    """The [waveform] table of one waveform kind: ``kind`` plus the kind's dataclass fields."""
    cls = WAVEFORMS.get(kind)
    t = getattr(cls, "config_table", None) or table_from_dataclass(cls, "waveform")
    kind_field = Field("kind", "str", REQUIRED, choices=WAVEFORMS.names, help="waveform kind")
    return Table("waveform", [kind_field, *t.fields.values()], f"kind = {WAVEFORMS.canonical(kind)!r}: {t.doc}")


def parse_waveform(mapping: dict, base=None):
    """A waveform from a [waveform] mapping; without ``kind`` (or with ``base``'s kind) the given keys
    change ``base`` (the case's waveform)."""
    if not isinstance(mapping, dict):
        raise TengsimError(f"[waveform] must be a table, got {mapping!r}")
    d = dict(mapping)
    kind_field = Field("kind", "str", choices=WAVEFORMS.names)
    if base is not None:
        bd = base.to_dict()
        if "kind" not in d or kind_field.parse(d["kind"], "[waveform] ") == WAVEFORMS.canonical(bd["kind"]):
            d = {**{k: v for k, v in bd.items() if not (bd["kind"] == "table" and k == "interp")}, **d}
            if bd["kind"] == "table" and "interp" not in d:
                d["interp"] = bd["interp"]
    if "kind" not in d:
        raise TengsimError(f"[waveform] missing required key 'kind' (one of {', '.join(WAVEFORMS.names())})")
    kind = WAVEFORMS.canonical(kind_field.parse(d["kind"], "[waveform] "))
    v = waveform_table(kind).parse(d, defaults=False)
    v.pop("kind")
    cls = WAVEFORMS.get(kind)
    try:
        return cls(**v)
    except TypeError as exc:  # a registered waveform whose constructor differs from its fields
        raise TengsimError(f"[waveform] kind = {kind!r}: {exc}") from None


# --- [solver], [run], [sweep] ---

SOLVER_TABLE = table_from_dataclass(SolverOptions, "solver")


def parse_solver(mapping: dict) -> SolverOptions:
    return SolverOptions(**SOLVER_TABLE.parse(mapping, defaults=False))


def _positive_int(v, label):
    if v < 1:
        raise TengsimError(f"{label} must be >= 1, got {v!r}")
    return v


def _positive(v, label):
    if not v > 0:
        raise TengsimError(f"{label} must be > 0, got {v!r}")
    return v


RUN_TABLE = Table("run", [
    Field("case", "str", None, choices=CASES,
          help="what to run: fig7, fig8 (the paper's devices), run (the [device] as given), sweep (load sweep)"),
    Field("out", "str", None, help="output file, .csv (+ .json sidecar) or .nc; --out overrides"),
    Field("cycles", "int", None, check=_positive_int,
          help="periods to run (fig8: staircase steps, at most the staircase length)"),
    Field("t_end", "float", None, dim="time", check=_positive, help="run length; else cycles x period"),
    Field("dt_out", "float", None, dim="time", check=_positive, help="output time step"),
    Field("quick", "bool", False, help="fig8: coarse contact-engine A(P) table"),
], "what to run and how long (CLI options override)")

SWEEP_TABLE = Table("sweep", [
    Field("r_min_ohm", "float", 1e3, dim="resistance", check=_positive, help="smallest load"),
    Field("r_max_ohm", "float", 1e10, dim="resistance", check=_positive, help="largest load"),
    Field("points", "int", 15, help="loads, log-spaced, >= 2"),
    Field("steady", "bool", True, help="start each load from the periodic steady-state charge"),
], "load-resistance sweep (case sweep only; CLI options override)")


MODES = ("run", "sweep")  # one config serves both commands: each accepts the other's keys and ignores them


def parse_run(mapping: dict, case: str, ignored: list | None = None) -> dict:
    """Typed [run] values; keys the case does not use are refused with their name, except, for the run and
    sweep commands, the other one's keys (and its [run] case), which are dropped and named in ``ignored``."""
    v = RUN_TABLE.parse(mapping, defaults=False)
    other = {k for c in MODES if c != case for k in RUN_KEYS[c]} if case in MODES else set()
    unused = [k for k in v if k not in RUN_KEYS[case]]
    refused = [k for k in unused if k not in other]
    if refused:
        raise TengsimError(f"[run] key(s) {', '.join(map(repr, refused))} not used by the {case} case "
                           f"(it uses: {', '.join(RUN_KEYS[case])})")
    if "case" in v and v["case"] != case:
        if not (case in MODES and v["case"] in MODES):
            raise TengsimError(f"[run] case = {v['case']!r} but the command runs {case!r}")
        unused.append("case")
    for k in unused:
        v.pop(k, None)
        if ignored is not None:
            ignored.append(f"[run] {k}")
    return v


def waveform_peak(waveform, t_end: float) -> float:
    """The highest pressure ``waveform`` applies over [0, t_end] (Pa), from its values between its breakpoints."""
    t = np.linspace(0.0, float(t_end), 20001)
    b = np.asarray(waveform.breakpoints(0.0, float(t_end)), float)
    t = np.unique(np.r_[t, b, np.maximum(b - 1e-9 * t_end, 0.0)])
    return float(np.max(waveform(t)))


def check_pressures(area, waveform, t_end: float, source: str = "the area table", hint: str = "") -> None:
    """Refuse (TengsimError, one line) a waveform whose highest pressure over [0, t_end] lies outside an area
    table's pressures: beyond its top the table would be held at its last value, not extended.  ``hint``: what
    the user can give instead (e.g. an option)."""
    lo_hi = getattr(area, "pressure_Pa", None)
    if lo_hi is None or t_end is None:
        return
    lo, hi = float(lo_hi[0]), float(lo_hi[-1])
    peak = waveform_peak(waveform, t_end)
    where = f"{source} ({lo / 1e3:.4g} to {hi / 1e3:.4g} kPa; it is not extended)"
    if peak > hi * (1 + 1e-9):
        raise TengsimError(f"the waveform presses to {peak / 1e3:.4g} kPa, beyond the pressures of {where}: give a "
                           f"waveform within them{hint}, or an area table reaching {peak / 1e3:.4g} kPa (a design "
                           f"with --p-max {peak / 1e3:.4g}kPa)")
    if 0 < peak < lo * (1 - 1e-9):
        raise TengsimError(f"the waveform presses to {peak / 1e3:.4g} kPa, below the pressures of {where}: give a "
                           f"waveform within them{hint}, or an area table from a lower pressure")


def check_device_tables(cfg: dict, where: str = "config") -> None:
    """Refuse tables other than :data:`TABLES` (and values that are not tables)."""
    from tengsim.schema import check_tables

    check_tables(cfg, TABLES, where)


def fields_help() -> str:
    """Every table and field of a device config, for ``tengsim device fields`` and docs/device.md."""
    parts = [DEVICE_TABLE.help()]
    for kind in WAVEFORMS.names():
        t = waveform_table(kind)
        lines = [f"[waveform] kind = {kind!r}  {WAVEFORMS.summary(kind)}"]
        lines += ["  " + f.describe() for f in t.fields.values() if f.name != "kind"]
        parts.append("\n".join(lines))
    parts += [RUN_TABLE.help(), SOLVER_TABLE.help(), SWEEP_TABLE.help()]
    return "\n\n".join(parts)


__all__ = ["TABLES", "CASES", "MODES", "RUN_KEYS", "DEVICE_TABLE", "SOLVER_TABLE", "RUN_TABLE", "SWEEP_TABLE", "dim_of",
           "table_from_dataclass", "parse_device", "parse_waveform", "parse_solver", "parse_run", "waveform_table",
           "check_device_tables", "check_pressures", "fields_help", "waveform_peak"]
