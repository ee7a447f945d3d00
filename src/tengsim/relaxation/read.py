"""The `[relaxation]` table: a Prony series with units, a DMA file to fit, or the stated default.

    [relaxation]
    E_inf = "1.5MPa"
    branches = [{E = "0.12MPa", tau = "10ms"}, {E = "0.08MPa", tau = "0.1s"}]

or ``dma = "pdms_dma.csv"`` (frequency, storage, loss; ``per_decade`` optional), or
``default = "sylgard184"`` (:func:`tengsim.relaxation.prony.sylgard184`).  Times take s, ms, us (a bare
number is SI).  Bad input: a :class:`tengsim.errors.TengsimError` naming the value.
"""
from __future__ import annotations

import tomllib
from pathlib import Path

from tengsim.errors import TengsimError
from tengsim.relaxation.fit import read_dma
from tengsim.relaxation.prony import Prony, sylgard184
from tengsim.units import parse_quantity

KEYS = ("E_inf", "branches", "dma", "per_decade", "default", "source")


def relaxation_from_table(table: dict, base: Path | None = None) -> Prony:
    """The Prony series of a `[relaxation]` table (``base``: the folder a relative ``dma`` path is read from)."""
    if not isinstance(table, dict):
        raise TengsimError("[relaxation] must be a table")
    bad = sorted(set(table) - set(KEYS))
    if bad:
        raise TengsimError(f"[relaxation] has no key {bad[0]!r} (its keys: {', '.join(KEYS)})")
    if "default" in table:
        if table["default"] != "sylgard184":
            raise TengsimError(f"[relaxation] default = {table['default']!r}: the one default is 'sylgard184'")
        return sylgard184()
    if "dma" in table:
        p = Path(str(table["dma"]))
        if base is not None and not p.is_absolute():
            p = base / p
        return read_dma(p, float(table.get("per_decade", 1.0))).prony
    if "E_inf" not in table:
        raise TengsimError("[relaxation] needs E_inf (with branches), dma = FILE or default = 'sylgard184'")
    E_inf = parse_quantity(table["E_inf"], "pressure", "relaxation E_inf")
    branches = table.get("branches", [])
    if not isinstance(branches, list):
        raise TengsimError("[relaxation] branches must be a list of {E, tau} tables")
    E, tau = [], []
    for i, b in enumerate(branches):
        if not isinstance(b, dict) or set(b) != {"E", "tau"}:
            raise TengsimError(f"[relaxation] branch {i + 1} must be {{E = ..., tau = ...}}, got {b!r}")
        E.append(parse_quantity(b["E"], "pressure", f"relaxation branch {i + 1} E"))
        tau.append(parse_quantity(b["tau"], "time", f"relaxation branch {i + 1} tau"))
    return Prony(E_inf, tuple(E), tuple(tau), str(table.get("source", "")))


def read_relaxation(path) -> Prony:
    """The `[relaxation]` table of a TOML file."""
    p = Path(path)
    try:
        doc = tomllib.loads(p.read_text())
    except OSError as e:
        raise TengsimError(f"cannot read relaxation file {str(p)!r}: {e.strerror}") from None
    except UnicodeDecodeError:
        raise TengsimError(f"relaxation file {str(p)!r}: not a text (TOML) file") from None
    except tomllib.TOMLDecodeError as e:
        raise TengsimError(f"relaxation file {str(p)!r} is not valid TOML: {e}") from None
    if "relaxation" not in doc:
        raise TengsimError(f"relaxation file {str(p)!r} has no [relaxation] table")
    return relaxation_from_table(doc["relaxation"], p.parent)
