"""The help pages of ``tengsim contact``: one per shape (its keys, then the common ones) and an index.

Every key and text comes from the [contact] schema (:func:`tengsim.run.keys.contact_table`) and the
registries; nothing here lists a key by name.  ``tengsim contact SHAPE --help`` is one page of at
most 100 lines: the shape's keys in full, then one line per common and law key.
"""
from __future__ import annotations

import argparse
import os
import shutil
import sys
import textwrap

CLI_ONLY_HELP = {  # the command line's own options (not [contact] keys)
    "out": "output file: .csv (curves) or .nc (everything, maps included)",
    "plot": "also draw the curves to this .png/.pdf/.svg",
    "quiet": "no progress bar",
    "resume": "continue the interrupted run of these settings from OUT.partial.csv; a longer path "
              "(larger d_max or f_max) keeps the finished part",
}
_KEY_COL = 26


def _width() -> int:
    return max(80, min(120, shutil.get_terminal_size((100, 24)).columns)) if sys.stdout.isatty() else 100


def _flag(key: str) -> str:
    return "--" + key.replace("_", "-")


def _text(field) -> str:
    """A field's help with its kind/default, as one string ('key: ' removed)."""
    return field.describe().split(": ", 1)[1]


def _full(key: str, text: str, width: int) -> list:
    """``--key`` and its whole text, wrapped under a key column."""
    lines = textwrap.wrap(text, width - _KEY_COL) or [""]
    head = f"  {_flag(key):<{_KEY_COL - 3}} "
    if len(head) > _KEY_COL:
        return [head.rstrip()] + [" " * _KEY_COL + ln for ln in lines]
    return [head.ljust(_KEY_COL) + lines[0]] + [" " * _KEY_COL + ln for ln in lines[1:]]


def _short(field) -> tuple:
    """(help, ' [default …]'): a field's help without its kind, and its default (kept whole on one line)."""
    return field.help, (f" [default {field.default!r}]" if field.default not in (None, (), "") else "")


def _one_line(key: str, text, width: int, flag: bool = True) -> str:
    """``--key`` (``key`` with ``flag`` False) and its text cut to one line (at a clause where it can);
    ``text`` may be (text, tail), the tail kept whole."""
    text, tail = text if isinstance(text, tuple) else (text, "")
    room = width - _KEY_COL - len(tail)
    if len(text) > room:
        cut = text[: room - 1]
        for sep in ("; ", " ("):
            i = cut.rfind(sep)
            if i > room // 2:
                cut = cut[:i]
                break
        text = cut.rstrip(" ,;") + "…"
    return f"  {_flag(key) if flag else key:<{_KEY_COL - 3}} ".ljust(_KEY_COL) + text + tail


def _keys():
    """(common fields {name: Field}, law keys {name: help text})."""
    from tengsim.run.keys import common_fields, law_key_help, law_keys

    common = {f.name: f for f in common_fields() if f.name != "shape"}
    laws = {k: law_key_help(e) + " (a plain number, no unit)" for k, e in law_keys().items()}
    return common, laws


def shape_keys(shape: str) -> dict:
    """{key: Field} of the keys ``shape`` has beyond the common and law keys (schema order)."""
    from tengsim.run.keys import common_fields, contact_table, law_keys

    skip = {f.name for f in common_fields()} | set(law_keys())
    return {k: f for k, f in contact_table(shape).fields.items() if k not in skip}


def title_keys(params: dict):
    """The keys of the shape a saved run was made with (for a figure's title), or None if unknown."""
    cfg = (params or {}).get("config")
    shape = cfg.get("shape") if isinstance(cfg, dict) else None
    try:
        return tuple(shape_keys(shape)) if shape else None
    except Exception:  # noqa: BLE001 - a shape not registered here (a plugin's): every key is shown
        return None


def shape_help(shape: str) -> str:
    """The page of ``tengsim contact SHAPE --help``."""
    from tengsim.registry import SHAPES

    w = _width()
    name = SHAPES.canonical(shape)
    cls = SHAPES.get(name)
    pos = getattr(cls, "positional", None)
    lines = [f"usage: tengsim contact {name}{' ' + pos.upper() if pos else ''} [--KEY VALUE ...] --out FILE", "",
             f"{name}: {SHAPES.summary(name)}.",
             *textwrap.wrap("Dimensionless input (the shape's own numbers) or physical input (lengths with a "
                            "unit, and --E-star, --W, --eps); a key's text says which form it takes.", w), "",
             f"{name} keys:"]
    for k, f in shape_keys(name).items():
        lines += _full(k, _text(f), w)
    common, laws = _keys()
    lines += ["", "common keys (full text: tengsim contact --help):"]
    lines += [_one_line(k, _short(f), w) for k, f in common.items() if k not in CLI_ONLY_HELP]
    lines += [_one_line(k, h, w) for k, h in CLI_ONLY_HELP.items()]
    lines += ["", "law keys (with --law):"]
    lines += [_one_line(k, h, w) for k, h in laws.items()]
    return "\n".join(lines) + "\n"


def index_help() -> str:
    """The page of ``tengsim contact --help``: the shapes, how to see one's keys, the common keys."""
    from tengsim.registry import SHAPES

    w = _width()
    lines = ["usage: tengsim contact SHAPE [INPUT] [--KEY VALUE ...] --out FILE", "",
             *textwrap.wrap("Solve the adhesive contact (paper Eq. 9) of one micro-structure against a flat plate "
                            "along an approach and a retraction. Dimensionless input (the shape's own numbers, "
                            "e.g. pyramid --N 0.946 --cell 3.78 --tabor 0.5) or physical input with units (e.g. "
                            "pyramid --pitch 10um --base 5um --height 3.5um --E-star 1MPa --W 50mJ/m2 --eps 20nm).",
                            w), "",
             "shapes (tengsim contact SHAPE --help lists that shape's keys):"]
    lines += [_one_line(n, SHAPES.summary(n), w, flag=False) for n in SHAPES.names()]
    common, laws = _keys()
    lines += ["", "common keys:"]
    for k, f in common.items():
        if k not in CLI_ONLY_HELP:
            lines += _full(k, _text(f), w)
    for k, h in CLI_ONLY_HELP.items():
        lines += _full(k, h, w)
    lines += ["", "law keys (with --law):"]
    for k, h in laws.items():
        lines += _full(k, h, w)
    return "\n".join(lines) + "\n"


class HelpAction(argparse.Action):
    """``-h/--help`` of ``tengsim contact``: the shape's page once a shape was named, else the index."""

    def __init__(self, option_strings, dest=argparse.SUPPRESS, default=argparse.SUPPRESS, help=None):
        super().__init__(option_strings, dest=dest, default=default, nargs=0, help=help)

    def __call__(self, parser, namespace, values, option_string=None):
        shape = getattr(namespace, "shape", None)
        if shape is None:  # '--help' before the shape: look for a shape word anywhere on the line
            from tengsim.registry import SHAPES

            shape = next((a for a in sys.argv[1:] if a in SHAPES), None)
        page = shape_help(shape) if shape else index_help()
        try:
            sys.stdout.write(page)
            sys.stdout.flush()
        except BrokenPipeError:  # 'tengsim contact --help | head'
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        parser.exit(0)
