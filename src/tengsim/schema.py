"""The one config schema: typed fields, tables that refuse unknown keys, units only on dimensional keys.

Every config file (``tengsim run``, ``tengsim device --config``, ``tengsim sweep``) and every CLI option
set is validated through :class:`Table`: a key not in the table is refused with its name, a number is
typed, and a unit string ('2um', '0.59MPa') is accepted only where the field has a dimension.
"""
from __future__ import annotations

import inspect
import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

from tengsim.errors import ConfigValueError, TengsimError, listed, shown

MAX_INT = 10**15
"""The largest |value| of an integer key (seeds, counts): exactly representable as a float."""

REQUIRED = object()
"""Marker default of a field that must be given."""


@dataclass(frozen=True)
class Field:
    """One config key.

    ``kind``: 'float', 'int', 'bool', 'str', 'floats' (list or comma-separated), 'any'.
    ``dim``: the dimension of a quantity ('length', 'pressure', 'energy/area', ...; see
    :func:`tengsim.units.parse_quantity`); a field with a dimension takes a number (SI) or a unit string,
    one without refuses unit strings.  ``choices``: a tuple of names, or a callable returning them (a
    registry's ``names``), checked case-insensitively.  ``check``: an extra validator ``value -> value``.
    """

    name: str
    kind: str = "float"
    default: Any = None
    dim: str | None = None
    choices: Any = None
    help: str = ""
    check: Callable | None = None

    @property
    def required(self) -> bool:
        return self.default is REQUIRED

    def _choices(self):
        c = self.choices
        return tuple(c()) if callable(c) else tuple(c or ())

    def parse(self, value, where: str = ""):
        """Typed value of ``value`` for this field; a TengsimError naming ``where.name`` if it is bad."""
        label = f"{where}{self.name}"
        k = self.kind
        if k == "any":
            v = value
        elif k == "bool":
            if isinstance(value, bool):
                v = value
            elif isinstance(value, str) and value.lower() in ("true", "false", "1", "0", "yes", "no"):
                v = value.lower() in ("true", "1", "yes")
            else:
                raise ConfigValueError(f"{label} must be true or false, got {shown(value)}")
        elif k == "str":
            if not isinstance(value, str):
                raise ConfigValueError(f"{label} must be a string, got {shown(value)}")
            v = value
            ch = self._choices()
            if ch:
                key = value.strip().lower().replace("-", "_")
                norm = {c.lower().replace("-", "_"): c for c in ch}
                if key not in norm:
                    raise ConfigValueError(f"{label} = {shown(value)} is not one of {', '.join(ch)}")
                v = norm[key]
        elif k == "int":
            from tengsim.units import read_number

            if isinstance(value, bool) or not isinstance(value, (int, float, str)):
                raise ConfigValueError(f"{label} must be an integer, got {shown(value)}")
            try:
                f = read_number(value, label)
            except ConfigValueError:
                raise
            except ValueError:
                raise ConfigValueError(f"{label} must be an integer, got {shown(value)}") from None
            if not math.isfinite(f) or f != int(f) or abs(f) > MAX_INT:
                raise ConfigValueError(f"{label} must be an integer" + (f" of magnitude at most {MAX_INT:.0e}"
                                       if math.isfinite(f) and f == int(f) else "") + f", got {shown(value)}")
            v = int(f)
        elif k == "float":
            v = self._number(value, label)
        elif k == "floats":
            items = value
            if isinstance(value, str):
                items = [s for s in value.split(",") if s.strip()]
            elif isinstance(value, (int, float)) and not isinstance(value, bool):
                items = [value]
            if not isinstance(items, (list, tuple)):
                raise ConfigValueError(f"{label} must be a list of numbers, got {shown(value)}")
            v = tuple(self._number(x, label) for x in items)
        else:  # pragma: no cover - a schema bug
            raise TypeError(f"unknown field kind {k!r}")
        if self.check is not None:
            try:
                v = self.check(v, label) if _arity(self.check) == 2 else self.check(v)
            except TengsimError as e:  # the check sees the number in SI: name the value as the user wrote it
                if self.dim is None or not isinstance(value, str):
                    raise
                raise e.reworded(suffix=f" (given as {shown(value)})") from None
        return v

    def _number(self, value, label):
        from tengsim.units import parse_quantity, read_number

        if isinstance(value, bool):
            raise ConfigValueError(f"{label} must be a number, got {value!r}")
        if isinstance(value, str):
            s = value.strip()
            try:
                x = read_number(s, label)
            except ConfigValueError:
                raise
            except ValueError:
                if self.dim is None:
                    raise ConfigValueError(f"{label} is dimensionless: give a plain number, got {shown(value)}") from None
                x = parse_quantity(s, self.dim, name=label)
        elif isinstance(value, (int, float)):
            x = read_number(value, label)
        else:
            raise ConfigValueError(f"{label} must be a number, got {shown(value)}")
        if not math.isfinite(x):
            raise ConfigValueError(f"{label} must be finite, got {shown(value)}")
        return x

    def describe(self) -> str:
        """One line for --help and the docs."""
        bits = [self.kind if self.dim is None else f"{self.dim} (number in SI or with a unit)"]
        ch = self._choices()
        if ch:
            bits.append("one of " + ", ".join(ch))
        if self.required:
            bits.append("required")
        elif self.default is not None:
            bits.append(f"default {self.default!r}")
        return f"{self.name}: {self.help}" + (f" [{'; '.join(bits)}]" if bits else "")


def _arity(fn) -> int:
    try:
        return len(inspect.signature(fn).parameters)
    except (TypeError, ValueError):  # pragma: no cover
        return 1


class Table:
    """A named set of fields; :meth:`parse` types a mapping and refuses keys it does not know."""

    def __init__(self, name: str, fields, doc: str = ""):
        self.name = name
        self.fields = {f.name: f for f in fields}
        self.doc = doc

    def __contains__(self, key) -> bool:
        return key in self.fields

    def keys(self):
        return tuple(self.fields)

    def parse(self, mapping: dict, *, defaults: bool = True, where: str | None = None) -> dict:
        """Typed values of ``mapping``; unknown keys and missing required ones are errors.

        With ``defaults`` the result holds every field (defaults filled in), else only the given keys.
        """
        where = f"[{self.name}] " if where is None else where
        if not isinstance(mapping, dict):
            raise TengsimError(f"{where.strip() or self.name} must be a table, got {shown(mapping)}")
        unknown = [k for k in mapping if k not in self.fields]
        if unknown:
            raise TengsimError(f"{where}unknown key(s) {listed(unknown)} "
                               f"(known: {', '.join(self.fields)})")
        out = {}
        for name, f in self.fields.items():
            if name in mapping and mapping[name] is not None:
                out[name] = f.parse(mapping[name], where)
            elif f.required:
                raise TengsimError(f"{where}missing required key {name!r}")
            elif defaults:
                out[name] = f.default
        return out

    def help(self) -> str:
        lines = [f"[{self.name}]" + (f"  {self.doc}" if self.doc else "")]
        lines += ["  " + f.describe() for f in self.fields.values()]
        return "\n".join(lines)


def read_config(path) -> dict:
    """Read a TOML (or .json) config file into a dict; any failure is one clear TengsimError."""
    path = Path(path)
    if not path.is_file():
        raise TengsimError(f"config file {str(path)!r} not found")
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise TengsimError(f"cannot read config file {str(path)!r}: {exc.strerror}") from None
    name = shown(str(path), 200)
    if path.suffix.lower() == ".json":
        try:
            cfg = json.loads(raw.decode("utf-8"))
        except RecursionError:
            raise TengsimError(f"config file {name} is nested too deeply (at most {MAX_DEPTH} levels)") from None
        except (ValueError, UnicodeDecodeError) as exc:
            raise TengsimError(f"config file {name} is not valid JSON: {shown(str(exc), 200)[1:-1]}") from None
    else:
        try:
            import tomllib
        except ModuleNotFoundError:  # Python 3.10
            import tomli as tomllib
        try:
            cfg = tomllib.loads(raw.decode("utf-8"))
        except RecursionError:
            raise TengsimError(f"config file {name} is nested too deeply (at most {MAX_DEPTH} levels)") from None
        except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
            raise TengsimError(f"config file {name} is not valid TOML: {shown(str(exc), 200)[1:-1]}") from None
    if not isinstance(cfg, dict):
        raise TengsimError(f"config file {name} must hold tables")
    if _depth(cfg) > MAX_DEPTH:
        raise TengsimError(f"config file {name} is nested too deeply (at most {MAX_DEPTH} levels)")
    return cfg


MAX_DEPTH = 16
"""The deepest nesting of tables and lists a config may hold (a table of a table of a list is 3): deeper is not a
configuration, and Python's own recursion (a comparison, a copy) would fail on it."""


def _depth(value) -> int:
    """How deep ``value`` nests dicts and lists (without recursion: a 600-deep list is measured, not crashed on)."""
    deepest, todo = 0, [(value, 0)]
    while todo:
        v, d = todo.pop()
        if isinstance(v, (dict, list)):
            d += 1
            deepest = max(deepest, d)
            if d > MAX_DEPTH:
                return d
            todo.extend((x, d) for x in (v.values() if isinstance(v, dict) else v))
    return deepest


def check_tables(cfg: dict, allowed, where: str = "config") -> None:
    """Refuse top-level tables not in ``allowed`` and top-level values that are not tables."""
    unknown = [k for k in cfg if k not in allowed]
    if unknown:
        raise TengsimError(f"{where}: unknown table(s) {listed(unknown)} "
                           f"(known: {', '.join(allowed)})")
    for k, v in cfg.items():
        if not isinstance(v, dict):
            raise TengsimError(f"{where}: [{k}] must be a table, got {shown(v)}")


def field_kind(annotation) -> str:
    """Schema kind of a dataclass/argument annotation: 'int', 'bool' or (anything else) 'float'."""
    return {"int": "int", "bool": "bool"}.get(getattr(annotation, "__name__", annotation), "float")


def dataclass_fields(cls, skip=(), helps=None) -> tuple:
    """Fields of a dataclass's init arguments (defaults kept, REQUIRED where none), minus ``skip``;
    help texts from ``helps`` (name → text).  Shapes' and laws' input schemas are built with it."""
    import dataclasses

    out = []
    for f in dataclasses.fields(cls):
        if not f.init or f.name in skip:
            continue
        if f.default is not dataclasses.MISSING:
            default = f.default
        elif f.default_factory is not dataclasses.MISSING:  # pragma: no cover
            default = f.default_factory()
        else:
            default = REQUIRED
        out.append(Field(f.name, field_kind(f.type), default, help=(helps or {}).get(f.name, "")))
    return tuple(out)


def signature_fields(cls, skip=(), helps=None) -> tuple:
    """Input fields from a constructor's signature (for shapes and laws that are not dataclasses)."""
    out = []
    for p in inspect.signature(cls).parameters.values():
        if p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY) and p.name not in skip:
            out.append(Field(p.name, "float" if p.annotation is p.empty else field_kind(p.annotation),
                             REQUIRED if p.default is p.empty else p.default, help=(helps or {}).get(p.name, "")))
    return tuple(out)
