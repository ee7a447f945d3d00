"""A fitted material for new designs: the table of a material.toml (``tengsim calibrate`` writes it), checked.

The file (:func:`tengsim.calibrate.write.material_text`): ``[design]`` the best values (``E_star``, ``W``, ``eps``,
``sigma`` with units), which replace a design's own; ``[uncertainty]`` the 95 % intervals and
``[[uncertainty.point]]`` the parameter points that span the fitted uncertainty, whose designs give a prediction's
band (:mod:`tengsim.design.bands`).  :func:`material_table` checks a table read at the edge
(:func:`tengsim.schema.read_config`): every key a material key, every value a quantity of its kind, every point a
table; anything else is one line naming the file and the key.  The values' physical bounds are the design's own:
:func:`tengsim.design.plan.plan_design` applies them to the values and to every point before anything runs.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from tengsim.errors import ConfigValueError, shown

MATERIAL_KEYS = {"E_star": "pressure", "W": "energy/area", "eps": "length", "sigma": "charge/area"}
"""The keys a material gives a design, and each one's quantity."""
TABLES = ("design", "material", "uncertainty")
"""The tables of a material file (``[material]``: the values under that name instead of ``[design]``)."""


@dataclass(frozen=True)
class Material:
    """A checked material: ``values`` {key: value as given} replacing a design's own, ``points`` ({key: value},
    ...) spanning its uncertainty, ``source`` the file it came from (for messages)."""

    values: dict
    points: tuple = ()
    source: str = ""

    def without(self, keys) -> "Material":
        """The material with ``keys`` left out of its values (keys a user gives on the command line win)."""
        return dataclasses.replace(self, values={k: v for k, v in self.values.items() if k not in set(keys)})

    @property
    def where(self) -> str:
        return f"--material {self.source}" if self.source else "the material"


def _checked(mapping: dict, where: str) -> dict:
    """``mapping`` with every key a material key and every value a quantity of its kind (kept as given)."""
    from tengsim.schema import Field

    bad = sorted(str(k) for k in mapping if k not in MATERIAL_KEYS)
    if bad:
        raise ConfigValueError(f"{where}: {', '.join(bad)}: not a material key ({', '.join(MATERIAL_KEYS)})")
    for k, v in mapping.items():
        Field(k, dim=MATERIAL_KEYS[k]).parse(v, f"{where}: ")
    return dict(mapping)


def material_table(cfg: dict, source: str = "") -> Material:
    """The :class:`Material` of a material file's tables ``cfg`` (module doc); a table that is not one: one line
    naming ``source`` and the key."""
    where = f"--material {source}" if source else "the material"
    if not isinstance(cfg, dict):
        raise ConfigValueError(f"{where}: not a material file (tables [design] and [uncertainty])")
    vals = cfg.get("design", cfg.get("material"))
    if not isinstance(vals, dict) or not any(k in vals for k in MATERIAL_KEYS):
        raise ConfigValueError(f"{where}: no [design] table with E_star, W, eps or sigma (a material.toml that "
                               "tengsim calibrate writes)")
    others = sorted(str(k) for k in cfg if k not in TABLES)
    if others:
        raise ConfigValueError(f"{where}: unknown table(s) {', '.join(others)} (a material file holds "
                               f"{', '.join(f'[{t}]' for t in TABLES)})")
    values = _checked(vals, f"{where} [design]")
    unc = cfg.get("uncertainty", {})
    if not isinstance(unc, dict):
        raise ConfigValueError(f"{where}: uncertainty must be a table ([uncertainty]), got {shown(unc)}")
    raw = unc.get("point", [])
    if isinstance(raw, dict):
        raw = [raw]
    if not isinstance(raw, list) or not all(isinstance(p, dict) for p in raw):
        raise ConfigValueError(f"{where}: [uncertainty] point must be tables ([[uncertainty.point]] with E_star, W, "
                               f"eps, sigma), got {shown(raw)}")
    points = tuple(_checked(p, f"{where} [[uncertainty.point]] {i + 1}") for i, p in enumerate(raw))
    return Material(values, points, str(source))


__all__ = ["MATERIAL_KEYS", "Material", "material_table"]


def read_material(path) -> Material:
    """The fitted material of the file ``path`` (``tengsim calibrate``'s material.toml), taken by
    :func:`material_table`; the one reader of a material file."""
    from pathlib import Path

    from tengsim.errors import TengsimError
    from tengsim.schema import read_config

    if not Path(path).is_file():
        raise TengsimError(f"--material {path}: no such file (give the material.toml tengsim calibrate wrote)")
    try:
        cfg = read_config(path)
    except TengsimError as exc:
        raise TengsimError(f"--material {path}: {exc}") from None
    return material_table(cfg, str(path))
