"""Numbers as a designer reads them: lengths in nm/µm/mm, pressures in Pa/kPa/MPa (for messages, reports, plots)."""
from __future__ import annotations

import math


def _scaled(value: float, steps, digits: int = 3) -> str:
    if not math.isfinite(value):
        return "n/a"
    for factor, unit in steps:
        if abs(value) >= factor * 0.9995 or factor == steps[-1][0]:
            return f"{value / factor:.{digits}g} {unit}"
    return f"{value:g}"


def length_text(m: float, digits: int = 3) -> str:
    """'85.4 nm', '10 µm', '0.4 mm' for a length in metres."""
    return _scaled(m, ((1e-3, "mm"), (1e-6, "µm"), (1e-9, "nm")), digits)


def pressure_text(pa: float, digits: int = 3) -> str:
    """'100 kPa', '530 Pa', '1 MPa' for a pressure in pascals."""
    if pa == 0:
        return "0 kPa"
    return _scaled(pa, ((1e6, "MPa"), (1e3, "kPa"), (1.0, "Pa")), digits)


def time_text(s: float) -> str:
    """'35 s', '4.2 min', '1.3 h'."""
    if s < 90:
        return f"{s:.0f} s"
    if s < 5400:
        return f"{s / 60:.1f} min"
    return f"{s / 3600:.1f} h"


def bytes_text(b: float) -> str:
    return f"{b / 2**20:.0f} MiB" if b < 2**30 else f"{b / 2**30:.1f} GiB"
