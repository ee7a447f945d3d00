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
"""
from __future__ import annotations

import hashlib
import itertools
import json
import math
import re
from dataclasses import dataclass, field

import numpy as np

from tengsim.errors import TengsimError, listed, shown
from tengsim.resources import check_count

POINT_TABLES = ("contact", "device", "var")
"""Tables of a point; an axis is named 'table.key' with table one of these ('var': free variables that
only expressions read, e.g. an aspect ratio)."""
STUDY_TABLES = ("base", "axes", "study", "observables", "objective")
SAMPLINGS = ("grid", "lhs", "sobol")
DEVICE_DEFAULTS = {"sigma": "5.84uC/m2", "eps_r": 2.40, "thickness": "400um"}
"""Eq. (12) inputs of the paper's Fig. 5: tribo-charge density σ, relative permittivity ε_r, thickness T."""
IGNORED_CONTACT_KEYS = ("out", "plot")
"""Keys of a `tengsim run` [contact] table that name output files; a sweep writes its own."""

_NUM_UNIT = re.compile(r"\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*([^\d\s].*)?\s*$")


@dataclass(frozen=True)
class Axis:
    """One dimension of the study: ``name`` and, per index, the values of its ``members``.

    A plain axis has one member (its own name); a zip group several, varied together.
    """

    name: str
    members: tuple
    values: tuple          # values[k] = tuple of member values at index k
    labels: tuple = ()     # zip group: one label per index (default 0, 1, ...)
    continuous: tuple = () # range axes: (start, stop, scale, unit) for sampling

    def __len__(self):
        return len(self.values)

    def coord(self):
        """Index values along this dimension (the axis value, or the zip label)."""
        if len(self.members) == 1:
            return [v[0] for v in self.values]
        return list(self.labels) if self.labels else list(range(len(self.values)))


@dataclass
class Point:
    """One study point: its axis values (by axis member name) and resolved tables."""

    axes: dict
    tables: dict
    index: tuple = ()

    @property
    def contact(self) -> dict:
        return self.tables["contact"]

    @property
    def id(self) -> str:
        return point_id(self.contact)


@dataclass
class Study:
    """A parsed study: base tables, axes, sampling, observables and objective settings, points."""

    base: dict
    axes: list
    sampling: str = "grid"
    n: int = 0
    seed: int = 0
    observables: dict = field(default_factory=dict)
    objective: dict = field(default_factory=dict)
    points: list = field(default_factory=list)
    source: str = ""

    @property
    def is_grid(self) -> bool:
        return self.sampling == "grid"

    @property
    def columns(self) -> list:
        """Axis value columns, named as in [axes] (zip members by their own names)."""
        out = []
        for a in self.axes:
            if len(a.members) > 1:
                out.append(a.name)
            out.extend(a.members)
        return out

    def resolved(self) -> dict:
        """What DIR/study.json stores: enough to check a resumed study against the first one."""
        return {
            "format": "tengsim-study/1",
            "source": self.source,
            "sampling": self.sampling, "n": self.n, "seed": self.seed,
            "axes": [{"name": a.name, "members": list(a.members), "coord": _jsonable(a.coord()),
                      "values": [list(v) for v in a.values]}
                     for a in self.axes],
            "base": self.base,
            "observables": self.observables,
            "points": [{"id": p.id, "axes": p.axes, "index": list(p.index), "tables": p.tables}
                       for p in self.points],
        }


def canonical(obj) -> str:
    """Canonical JSON: sorted keys, no spaces, integers that are whole floats written as floats."""
    return json.dumps(_norm(obj), sort_keys=True, separators=(",", ":"), ensure_ascii=False)


def _norm(x):
    if isinstance(x, dict):
        return {str(k): _norm(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_norm(v) for v in x]
    if isinstance(x, bool) or x is None or isinstance(x, str):
        return x
    if isinstance(x, (int, float, np.integer, np.floating)):
        return float(x)
    return str(x)


def _jsonable(x):
    return json.loads(canonical(x))


def point_id(contact: dict, provenance: dict | None = None) -> str:
    """Deterministic id of a contact computation: the first 16 hex digits of the SHA-256 of the canonical
    JSON of its table and its ``provenance`` (default :func:`tengsim.study.points.provenance`: the
    point-file format, the tengsim version, the plugin modules' and the input files' digests), so that
    other code or data never gives a point the id of this one."""
    if provenance is None:
        from tengsim.study.points import provenance as current

        provenance = current(contact)
    return hashlib.sha256(canonical({"contact": contact, "provenance": provenance}).encode()).hexdigest()[:16]


# ---- parsing ------------------------------------------------------------------------------------

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
        _var_number(k, v)
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
    study.points = expand(study)
    return study


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
        return [_with_unit(x, ua) for x in xs], cont
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


def _with_unit(x, unit):
    """A generated axis value: a float (12 significant digits), or '<6 significant digits><unit>'."""
    if unit:
        return f"{float(x):.6g}{unit}"
    return float(f"{float(x):.12g}")


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


# ---- expansion ----------------------------------------------------------------------------------

def _resolve(base: dict, assign: dict, pressures=()) -> dict:
    """A point's tables: [base.contact] < [base.shapes.<shape>] < axis values; then expressions evaluated;
    a physical point refined automatically (resolve = 'auto') also converges A/S at the study's
    [observables] pressures (``resolve_pressures``, unless the table names its own)."""
    tables = {t: dict(v) for t, v in base.items() if t != "shapes"}
    tables.setdefault("var", {})
    for name, v in assign.items():
        t, k = name.split(".", 1)
        tables[t][k] = v
    shapes = base.get("shapes") or {}
    if shapes:
        from tengsim.registry import SHAPES

        try:
            shape = SHAPES.canonical(tables["contact"].get("shape") or "pyramid")
        except (TengsimError, KeyError, ValueError):
            shape = None  # an unknown shape: plan_contact names it
        own = {k: v for k, v in shapes.get(shape, {}).items() if f"contact.{k}" not in assign}
        tables["contact"].update(own)
    tables["contact"] = evaluate(tables["contact"], tables["var"])
    c = tables["contact"]
    if (pressures and str(c.get("resolve", "")).strip().lower() == "auto" and "resolve_pressures" not in c
            and _physical(c)):
        c["resolve_pressures"] = [f"{float(p):.6g}Pa" for p in pressures]
    return tables


def _pressures(study) -> tuple:
    return tuple(study.observables.get("pressures", ()))


def _physical(contact: dict) -> bool:
    """A [contact] table of a physical run (one that :func:`tengsim.run.keys.key_dims` gives units to)."""
    from tengsim.run.keys import key_dims

    try:
        return bool(key_dims(contact))
    except TengsimError:
        return False  # plan_contact names the problem




def evaluate(contact: dict, var: dict) -> dict:
    """Evaluate the expression values of a [contact] table: strings starting with '='.

    An expression is + - * / and parentheses over numbers, the point's [var] variables, and other
    [contact] keys (quantities such as '5um' in SI, expressions first evaluated themselves).  It is
    computed in SI with its dimension: a unit string's, a physical run's key's (a bare number on E_star,
    W, eps or a shape's length is SI), none for [var]s and plain numbers (a plain number added to a
    quantity is read in its SI unit).  The value gets the key's own unit: in a physical run dx,
    thickness, f_min, f_max and f_step (whose bare numbers are in X units or F) get their SI unit
    appended ('0.0004m', '-2000Pa'), SI keys keep the number in SI, dimensionless keys (d_*, tabor, law
    parameters, every key of a dimensionless run) a plain number.  A value of the wrong dimension is
    refused (``d_max = "=2*eps"`` is a length, ``dx = "=E_star/2"`` a pressure), as is a bare dx,
    thickness or load used as an operand in a physical run (it is not SI).
    E.g. ``height = "=aspect*0.5*pitch"``, ``d_max = "=1.3*height/eps + 2"``, ``thickness = "=200*pitch"``.
    """
    import ast

    if not any(isinstance(v, str) and v.startswith("=") for v in contact.values()):
        return dict(contact)
    from tengsim.run.keys import key_dims
    from tengsim.units import DIMENSIONS, SI_UNIT, parse_quantity, quantity_dim, read_number

    zero = (0, 0, 0, 0)
    qdims = key_dims(contact)  # {} in a dimensionless run
    out = dict(contact)
    done = {}  # key -> (SI value, dimension vector, plain) of its evaluated expression
    busy = set()

    def value(name):
        """(SI value, dimension, plain): plain for a number with no dimension of its own."""
        if name in var:
            return _var_number(name, var[name]), zero, True
        if name not in out:
            raise TengsimError(f"expression: unknown name {name!r} (a [contact] key or a [var] variable)")
        v = out[name]
        if name in done:
            return done[name]
        if isinstance(v, str) and v.startswith("="):
            if name in busy:
                raise TengsimError(f"expression: {name!r} depends on itself")
            busy.add(name)
            done[name] = calc(name, v)
            busy.discard(name)
            return done[name]
        if isinstance(v, bool) or isinstance(v, (dict, list)):
            raise TengsimError(f"expression: {name} = {v!r} is not a number")
        x = parse_quantity(v, name=name)
        d = quantity_dim(v)
        if d is not None:
            return x, DIMENSIONS[d], False
        if name not in qdims:
            return x, zero, True
        dim, si = qdims[name]
        if not si:
            own = "X units" if dim == "length" else "units of F (Eq. 10)"
            raise TengsimError(f"expression: {name} = {v!r} is in {own}, not SI: give it with a unit "
                               f"(e.g. '{v}{'um' if dim == 'length' else 'kPa'}') to use it in an expression")
        return x, DIMENSIONS[dim], False

    def calc(key, text):
        src = text[1:].strip()
        if len(src) > MAX_EXPRESSION:
            raise TengsimError(f"{key} = {shown(text)}: an expression is at most {MAX_EXPRESSION} characters")
        try:
            tree = ast.parse(src, mode="eval")
        except (SyntaxError, ValueError, RecursionError, MemoryError):
            raise TengsimError(f"{key} = {shown(text)}: cannot read the expression") from None
        text = shown(text)[1:-1] if len(text) > 60 else text

        def ev(n):
            if isinstance(n, ast.Expression):
                return ev(n.body)
            if isinstance(n, ast.Constant) and isinstance(n.value, (int, float)) and not isinstance(n.value, bool):
                return read_number(n.value, key), zero, True
            if isinstance(n, ast.Name):
                return value(n.id)
            if isinstance(n, ast.UnaryOp) and isinstance(n.op, (ast.USub, ast.UAdd)):
                x, d, p = ev(n.operand)
                return (-x if isinstance(n.op, ast.USub) else x), d, p
            if isinstance(n, ast.BinOp) and isinstance(n.op, (ast.Add, ast.Sub, ast.Mult, ast.Div)):
                (a, da, pa), (b, db, pb) = ev(n.left), ev(n.right)
                if isinstance(n.op, (ast.Add, ast.Sub)):
                    if not pa and not pb and da != db:
                        raise TengsimError(f"{key} = {text!r}: adds {_what(da)} and {_what(db)}")
                    d, p = (db, pb) if pa else (da, pa)
                    return (a + b if isinstance(n.op, ast.Add) else a - b), d, p
                if isinstance(n.op, ast.Mult):
                    return a * b, tuple(x + y for x, y in zip(da, db)), pa and pb
                if b == 0:
                    raise TengsimError(f"{key} = {text!r}: division by zero")
                return a / b, tuple(x - y for x, y in zip(da, db)), pa and pb
            raise TengsimError(f"{key} = {text!r}: only numbers, names, + - * / and parentheses are allowed")

        try:
            x, d, p = ev(tree)
        except RecursionError:
            raise TengsimError(f"{key} = {text!r}: the expression is nested too deeply") from None
        if not math.isfinite(x):
            raise TengsimError(f"{key} = {text!r}: the expression overflows (its value is {x})")
        want = DIMENSIONS[qdims[key][0]] if key in qdims else zero
        if not p and d != want:
            takes = f"{key} takes {_what(want)}" + ("" if key in qdims else " (it is dimensionless here)")
            raise TengsimError(f"{key} = {text!r} is {_what(d)}, but {takes}")
        return float(f"{x:.12g}"), want, False

    for k in list(out):
        v = out[k]
        if isinstance(v, str) and v.startswith("="):
            x = value(k)[0]
            if k in qdims and not qdims[k][1]:  # a bare number here is not SI: give the SI value its unit
                out[k] = f"{x:.12g}{SI_UNIT[qdims[k][0]]}"
            else:
                out[k] = x
    return out


MAX_EXPRESSION = 1000
"""The longest '=' expression (characters): longer ones are refused unread (a parser's recursion)."""


def _var_number(name, v) -> float:
    """A [var] variable's value as a number: a string on a 'var.' axis is refused, naming it."""
    from tengsim.units import read_number

    try:
        if isinstance(v, (bool, dict, list)):
            raise ValueError
        return read_number(v, f"var.{name}")
    except TengsimError:
        raise
    except ValueError:
        raise TengsimError(f"var.{name} = {shown(v)} is not a number (a [var] variable is a plain number)") from None


def _what(vec) -> str:
    from tengsim.units import dimension_name

    name = dimension_name(vec)
    return "a plain number" if name == "dimensionless" else f"a {name}"


def expand(study: Study) -> list:
    """The study's points: the full grid of its axes, or n lhs/sobol samples of them."""
    axes = study.axes
    if study.sampling == "grid":
        for a in axes:
            if not a.values and study.objective:
                return []  # an optimisation: tengsim optimize draws the points
            if not a.values:
                raise TengsimError(f"axis {a.name!r} is a range without num (only sampling = 'lhs' or "
                                   "'sobol' may leave num out)")
        check_count(math.prod(len(a) for a in axes), "the study's grid of points ("
                    + " × ".join(f"{len(a)} {a.name}" for a in axes) + ")")
        pts = []
        for idx in itertools.product(*(range(len(a)) for a in axes)):
            assign, labels = {}, {}
            for a, k in zip(axes, idx):
                assign.update(zip(a.members, a.values[k]))
                if len(a.members) > 1:
                    labels[a.name] = a.coord()[k]
            pts.append(Point({**labels, **assign}, _resolve(study.base, assign, _pressures(study)), tuple(idx)))
        return pts
    from scipy.stats import qmc

    d = len(axes)
    if study.sampling == "lhs":
        u = qmc.LatinHypercube(d=d, seed=study.seed).random(study.n)
    else:
        u = qmc.Sobol(d=d, scramble=True, seed=study.seed).random(study.n)
    pts = []
    for i, row in enumerate(u):
        assign, labels = {}, {}
        for a, x in zip(axes, row):
            if a.continuous and len(a.members) == 1:
                lo, hi, scale, unit = a.continuous
                v = lo * (hi / lo) ** x if scale == "log" else lo + (hi - lo) * x
                assign[a.members[0]] = _with_unit(v, unit)
            else:
                k = min(int(x * len(a)), len(a) - 1)
                assign.update(zip(a.members, a.values[k]))
                if len(a.members) > 1:
                    labels[a.name] = a.coord()[k]
        pts.append(Point({**labels, **assign}, _resolve(study.base, assign, _pressures(study)), (i,)))
    return pts


def point_at(study: Study, x) -> Point:
    """The point of a study of range axes at ``x``: one value per axis, log10 of the value on a log axis
    (the search space of ``tengsim optimize``); values are written as :func:`expand` writes them."""
    assign = {}
    for a, v in zip(study.axes, x):
        lo, hi, scale, unit = a.continuous
        assign[a.members[0]] = _with_unit(10**v if scale == "log" else v, unit)
    return Point(assign, _resolve(study.base, assign, _pressures(study)), ())


def numeric(v) -> float:
    """An axis value as a number in SI (unit strings parsed); NaN if it is not a quantity."""
    from tengsim.units import parse_quantity

    if isinstance(v, (int, float)) and not isinstance(v, bool):
        return float(v)
    try:
        return parse_quantity(v)
    except Exception:  # noqa: BLE001 - names such as 'pyramid'
        return math.nan
