"""A study file: a ``[base]`` run, its ``[axes]``, and how the points are drawn; expanded to points.

Format (TOML)::

    [base.contact]            # exactly what the [contact] table of a `tengsim run` file holds
    shape = "pyramid"
    ...
    [base.device]             # optional: σ, ε_r, T of Eq. (12) for V_OC (defaults: paper Fig. 5)
    [base.shapes.cone]        # optional: merged into [contact] when a point's shape is 'cone'
    slope = "=2*aspect"       # an expression ('=' first): + - * / of numbers, [contact] keys and [var]s
    [base.var]                # optional: free variables (defaults) that expressions read
    aspect = 1.0
    [axes]
    "contact.shape" = ["pyramid", "cone"]                          # the shape itself
    "var.aspect" = [0.5, 1.5]
    "contact.N" = [0.946, 1.5]                                   # a list
    "contact.tabor" = { start = 0.3, stop = 0.5, num = 2 }        # a range (scale = "linear" | "log")
    group = { zip = { "contact.pitch" = ["2um", "5um"], "contact.base" = ["1um", "2.5um"] },
              labels = ["A", "B"] }                              # parameters that vary together
    [study]                   # optional
    sampling = "grid"         # or "lhs" / "sobol" with n and seed
    [observables]             # optional, see tengsim.study.observe

A point is the base with the axis values put in: [base.contact], then [base.shapes.<its shape>],
then its axis values; then every expression value is evaluated (in SI; see :func:`evaluate`).
Its id is a short SHA-256 of the canonical JSON of
its resolved ``[contact]`` table (the computation) and of what else determines its result (the format,
the tengsim version, plugin and input-file digests: :mod:`tengsim.study.points`), so points that run
the same contact share it and a changed code or input file never does.

Parsed here into a :class:`~tengsim.study.model.Study`; its points are drawn by
:mod:`tengsim.study.sampling`, its expressions evaluated by :mod:`tengsim.study.expressions`, their ids
made by :mod:`tengsim.study.hashing`.
"""
from __future__ import annotations

import dataclasses
import math
import re

import numpy as np

from tengsim.errors import TengsimError, listed, shown
from tengsim.resources import check_count
from tengsim.study.expressions import var_number
from tengsim.study.model import DEVICE_DEFAULTS, IGNORED_CONTACT_KEYS, POINT_TABLES, Axis, Study, with_unit
from tengsim.study.sampling import expand

STUDY_TABLES = ("base", "axes", "study", "observables", "objective")
SAMPLINGS = ("grid", "lhs", "sobol")

_NUM_UNIT = re.compile(r"\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*([^\d\s].*)?\s*$")


def load_study(path) -> Study:
    """Read, check and expand a study file; every error is one TengsimError naming the bad value."""
    from tengsim.schema import read_config

    return parse_study(read_config(path), source=str(path))


def parse_study(cfg: dict, source: str = "") -> Study:
    from tengsim.schema import check_tables

    where = source or "study"
    check_tables(cfg, STUDY_TABLES, where=where)
    base_in = cfg.get("base")
    if not base_in:
        raise TengsimError(f"{where}: needs a [base.contact] table (the run every point starts from)")
    check_tables(base_in, (*POINT_TABLES, "shapes"), where=f"{where} [base]")
    if "contact" not in base_in:
        raise TengsimError(f"{where}: needs a [base.contact] table (the run every point starts from)")
    contact = {k: v for k, v in base_in["contact"].items() if k not in IGNORED_CONTACT_KEYS}
    device = dict(DEVICE_DEFAULTS)
    device.update(base_in.get("device", {}))
    bad = [k for k in device if k not in DEVICE_DEFAULTS]
    if bad:
        raise TengsimError(f"{where}: [base.device] unknown key(s) {listed(bad)} "
                           f"(known: {', '.join(DEVICE_DEFAULTS)})")
    var = dict(base_in.get("var", {}))
    for k, v in var.items():
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            raise TengsimError(f"{where}: [base.var] {k} must be a number, got {shown(v)}")
        var_number(k, v)
    shapes = _parse_shapes(base_in.get("shapes", {}), where)
    base = {"contact": contact, "device": device, "var": var}
    if shapes:
        base["shapes"] = shapes

    axes = [_parse_axis(name, spec, where) for name, spec in (cfg.get("axes") or {}).items()]
    seen = {}
    for a in axes:
        for m in a.members:
            if m in seen:
                raise TengsimError(f"{where}: parameter {m!r} is on two axes ({seen[m]!r} and {a.name!r})")
            seen[m] = a.name

    st = dict(cfg.get("study") or {})
    sampling = str(st.pop("sampling", "grid")).lower()
    if sampling not in SAMPLINGS:
        raise TengsimError(f"{where}: [study] sampling = {sampling!r} is not one of {', '.join(SAMPLINGS)}")
    n = st.pop("n", None)
    seed = st.pop("seed", 0)
    if st:
        raise TengsimError(f"{where}: [study] unknown key(s) {listed(st)} (known: sampling, n, seed)")
    if sampling != "grid":
        if not isinstance(n, int) or isinstance(n, bool) or n < 1:
            raise TengsimError(f"{where}: [study] sampling = {shown(sampling)} needs n = a positive integer, got {shown(n)}")
        check_count(n, f"{where}: [study] n")
        if not isinstance(seed, int) or isinstance(seed, bool) or not 0 <= seed < 2**63:
            raise TengsimError(f"{where}: [study] seed must be an integer from 0 to 2**63 - 1, got {shown(seed)}")
        if not axes:
            raise TengsimError(f"{where}: sampling = {sampling!r} needs at least one axis")
    elif n is not None:
        raise TengsimError(f"{where}: [study] n is only for sampling = 'lhs' or 'sobol'")

    from tengsim.study.observe import parse_observables

    study = Study(base=base, axes=axes, sampling=sampling, n=int(n or 0), seed=int(seed),
                  observables=parse_observables(cfg.get("observables") or {}, where),
                  objective=dict(cfg.get("objective") or {}), source=source)
    return dataclasses.replace(study, points=expand(study))


def _parse_shapes(tables, where) -> dict:
    """[base.shapes.<name>] tables, keyed by canonical shape name."""
    from tengsim.plugins import SHAPES

    if not isinstance(tables, dict):
        raise TengsimError(f"{where}: [base.shapes] must hold one table per shape, got {tables!r}")
    out = {}
    for name, t in tables.items():
        try:
            canon = SHAPES.canonical(name)
        except (TengsimError, KeyError, ValueError) as exc:
            raise TengsimError(f"{where}: [base.shapes.{name}]: {exc}") from None
        if not isinstance(t, dict):
            raise TengsimError(f"{where}: [base.shapes.{name}] must be a table, got {t!r}")
        if "shape" in t:
            raise TengsimError(f"{where}: [base.shapes.{name}] may not set shape")
        bad = [k for k in t if k in IGNORED_CONTACT_KEYS]
        if bad:
            raise TengsimError(f"{where}: [base.shapes.{name}]: the sweep names its own output files ({bad[0]})")
        out[canon] = dict(t)
    return out


def _member_name(name, where):
    if not isinstance(name, str) or "." not in name:
        raise TengsimError(f"{where}: axis {name!r} must be named 'table.key' (table one of "
                           f"{', '.join(POINT_TABLES)}), e.g. 'contact.N'")
    table, key = name.split(".", 1)
    if table not in POINT_TABLES or not key or "." in key:
        raise TengsimError(f"{where}: axis {name!r} must be named 'table.key' (table one of "
                           f"{', '.join(POINT_TABLES)}), e.g. 'contact.N'")
    if table == "device" and key not in DEVICE_DEFAULTS:
        raise TengsimError(f"{where}: axis {name!r}: unknown device parameter {key!r} "
                           f"(known: {', '.join(DEVICE_DEFAULTS)})")
    if table == "var" and not re.fullmatch(r"[A-Za-z_]\w*", key):
        raise TengsimError(f"{where}: axis {name!r}: a variable name is letters, digits and _")
    if table == "contact" and key in IGNORED_CONTACT_KEYS:
        raise TengsimError(f"{where}: axis {name!r}: the sweep names its own output files")
    return name


def _values(name, spec, where):
    """Values of one parameter: a list, or a range table; returns (values, continuous-or-None)."""
    if isinstance(spec, list):
        if not spec:
            raise TengsimError(f"{where}: axis {name!r} is empty")
        for v in spec:
            if isinstance(v, (dict, list)):
                raise TengsimError(f"{where}: axis {name!r}: values must be numbers or strings, got {v!r}")
        return list(spec), None
    if isinstance(spec, dict):
        keys = set(spec)
        bad = keys - {"start", "stop", "num", "scale"}
        if bad:
            raise TengsimError(f"{where}: axis {name!r}: unknown range key(s) {', '.join(map(repr, sorted(bad)))} "
                               "(a range has start, stop, num, scale; a zip group has zip)")
        if not {"start", "stop"} <= keys:
            raise TengsimError(f"{where}: axis {name!r}: a range needs start and stop")
        scale = str(spec.get("scale", "linear")).lower()
        if scale not in ("linear", "log"):
            raise TengsimError(f"{where}: axis {name!r}: scale = {spec.get('scale')!r} is not 'linear' or 'log'")
        num = spec.get("num", 0 if "num" in spec else None)
        a, ua = _split_unit(spec["start"], name, where)
        b, ub = _split_unit(spec["stop"], name, where)
        if ua != ub:
            raise TengsimError(f"{where}: axis {name!r}: start and stop must have the same unit, "
                               f"got {spec['start']!r} and {spec['stop']!r}")
        if scale == "log" and not (a > 0 and b > 0):
            raise TengsimError(f"{where}: axis {name!r}: a log range needs start, stop > 0")
        cont = (a, b, scale, ua)
        if num is None:
            return None, cont   # only for sampling
        if isinstance(num, bool) or not isinstance(num, int):
            raise TengsimError(f"{where}: axis {name!r}: num must be an integer, got {num!r}")
        if num < 1:
            raise TengsimError(f"{where}: axis {name!r} is empty (num = {num})")
        check_count(num, f"{where}: axis {name!r}: num")
        if num == 1:
            xs = [a]
        elif scale == "log":
            xs = list(np.geomspace(a, b, num))
        else:
            xs = list(np.linspace(a, b, num))
        return [with_unit(x, ua) for x in xs], cont
    raise TengsimError(f"{where}: axis {name!r} must be a list, a range {{start, stop, num}} or a zip group, "
                       f"got {spec!r}")


def _split_unit(v, name, where):
    if isinstance(v, bool):
        raise TengsimError(f"{where}: axis {name!r}: {v!r} is not a number")
    from tengsim.units import parse_quantity, read_number

    if isinstance(v, (int, float)):
        return read_number(v, f"axis {name!r}"), ""
    m = _NUM_UNIT.fullmatch(str(v))
    if not m:
        raise TengsimError(f"{where}: axis {name!r}: cannot read {shown(v)} as a number with a unit")
    parse_quantity(str(v), name=f"axis {name!r}")  # bounded, no underscores
    return read_number(m.group(1), f"axis {name!r}"), (m.group(2) or "").strip()


def _parse_axis(name, spec, where) -> Axis:
    if isinstance(spec, dict) and "zip" in spec:
        extra = set(spec) - {"zip", "labels"}
        if extra:
            raise TengsimError(f"{where}: zip group {name!r}: unknown key(s) {', '.join(map(repr, sorted(extra)))} "
                               "(known: zip, labels)")
        z = spec["zip"]
        if not isinstance(z, dict) or not z:
            raise TengsimError(f"{where}: zip group {name!r} needs zip = {{ 'table.key' = [...], ... }}")
        members, cols = [], []
        for m, v in z.items():
            members.append(_member_name(m, where))
            vals, _ = _values(m, v, where)
            if vals is None:
                raise TengsimError(f"{where}: zip group {name!r}: {m!r} needs num")
            cols.append(vals)
        lens = {len(c) for c in cols}
        if len(lens) != 1:
            raise TengsimError(f"{where}: zip group {name!r}: its parameters have different lengths "
                               f"({', '.join(f'{m}: {len(c)}' for m, c in zip(members, cols))})")
        labels = spec.get("labels", ())
        if labels and (not isinstance(labels, list) or len(labels) != len(cols[0])):
            raise TengsimError(f"{where}: zip group {name!r}: labels must be a list of {len(cols[0])} names")
        if "." in name:
            raise TengsimError(f"{where}: zip group {name!r}: name a group without a dot (e.g. 'group')")
        return Axis(name, tuple(members), tuple(zip(*cols)), tuple(str(s) for s in labels))
    _member_name(name, where)
    vals, cont = _values(name, spec, where)
    return Axis(name, (name,), tuple((v,) for v in vals) if vals is not None else (), (), cont or ())


def numeric(v) -> float:
    """An axis value as a number in SI (unit strings parsed); NaN if it is not a quantity."""
    from tengsim.units import parse_quantity

    if isinstance(v, (int, float)) and not isinstance(v, bool):
        return float(v)
    try:
        return parse_quantity(v)
    except Exception:  # noqa: BLE001 - names such as 'pyramid'
        return math.nan
