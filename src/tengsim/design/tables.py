"""The one reading of a design file's tables, for every command that takes a design (``design``, ``calibrate``,
``design --material``'s band points).

The file is read at the edge by :func:`tengsim.schema.read_config` (TOML or JSON, UTF-8 whatever the locale, one
line on any failure); :func:`design_table` turns its tables into the design's table: its ``[design]`` table, or its
top-level keys when it has none.  Any other table (``[contact]`` beside ``[design]``, a ``[contact]`` table in a
file of top-level keys) is refused by name: a design's contact keys are its own keys, so a table the design would
not read is never read differently by another command.  The keys and their bounds are then
:func:`tengsim.design.plan.plan_design`'s, whatever the command.
"""
from __future__ import annotations

from pathlib import Path

from tengsim.errors import ConfigValueError, TengsimError, listed, shown


def design_table(cfg: dict, source: str = "") -> dict:
    """The design's table of a file's tables ``cfg`` (module doc); ``source``: the file, for the one-line error."""
    where = f"{shown(str(source), 200)[1:-1]}: " if source else ""
    if not isinstance(cfg, dict):
        raise ConfigValueError(f"{where}a design file holds [design] or the design's keys, got {shown(cfg)}")
    if "design" not in cfg:
        tables = [k for k, v in cfg.items() if isinstance(v, dict)]
        if tables:
            raise ConfigValueError(f"{where}unknown table(s) {listed(tables)}: a design file holds [design] or the "
                                   "design's keys at its top level")
        return dict(cfg)
    design = cfg["design"]
    if not isinstance(design, dict):
        raise ConfigValueError(f"{where}design must be a table ([design] with its keys), got {shown(design)}")
    others = [k for k in cfg if k != "design"]
    if others:
        raise ConfigValueError(f"{where}{listed(others)} beside [design]: a design file holds [design] only (its "
                               "contact keys, law among them, go in [design])")
    return dict(design)


__all__ = ["design_table"]


def read_design(path) -> dict:
    """The design's table of the design file ``path``: read by :func:`tengsim.schema.read_config` and taken by
    :func:`design_table`; the one reader of a design file (``tengsim design``, ``tengsim calibrate``, the API)."""
    from tengsim.schema import read_config

    if not Path(path).is_file():
        raise TengsimError(f"{shown(str(path), 200)[1:-1]}: no such file (give a design TOML file)")
    return design_table(read_config(path), str(path))
