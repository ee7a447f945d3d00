"""A measured curve: V_OC against the nominal pressure, read from a CSV file and checked.

The file: lines starting with ``#`` are comments; a header row; a pressure column whose name carries its unit
(``pressure_Pa``, ``pressure_kPa``, ``pressure_MPa``); ``voc_V`` (volts); optionally ``branch`` (approach or
retraction; default approach) and ``voc_err_V`` (the measurement's standard uncertainty, volts).  Anything wrong
is one :class:`tengsim.errors.TengsimError` line naming the file, the row and the value.
"""
from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from tengsim.errors import TengsimError, shown

PRESSURE_UNITS = {"pa": 1.0, "kpa": 1e3, "mpa": 1e6}
BRANCHES = ("approach", "retraction")


@dataclass(frozen=True)
class Curve:
    """One measured curve (SI): ``pressure`` (Pa), ``voc`` (V), ``err`` (V, or None), ``branch`` (one name per
    point), the ``source`` file."""

    source: str
    pressure: np.ndarray
    voc: np.ndarray
    branch: tuple
    err: np.ndarray | None = None

    @property
    def n(self) -> int:
        return len(self.voc)


def _number(text, where, column):
    try:
        v = float(str(text).strip())
    except ValueError:
        raise TengsimError(f"{where}: {column} = {shown(text)} is not a number") from None
    if not math.isfinite(v):
        raise TengsimError(f"{where}: {column} = {shown(text)} is not a finite number")
    return v


def read_curve(path) -> Curve:
    """Read and check one measured curve (module doc)."""
    p = Path(path)
    if not p.is_file():
        raise TengsimError(f"--data {path}: no such file")
    try:
        lines = [ln for ln in p.read_text(encoding="utf-8").splitlines() if ln.strip() and not ln.lstrip().startswith("#")]
    except UnicodeDecodeError:
        raise TengsimError(f"--data {path}: not a text (CSV) file") from None
    if not lines:
        raise TengsimError(f"--data {path}: no header row and no data")
    rows = list(csv.reader(lines))
    head = [h.strip() for h in rows[0]]
    low = [h.lower() for h in head]
    pcols = [i for i, h in enumerate(low) if h.startswith("pressure")]
    if not pcols:
        raise TengsimError(f"--data {path}: no pressure column (name it with its unit: pressure_kPa or pressure_Pa)")
    pi = pcols[0]
    unit = low[pi][len("pressure"):].lstrip("_ ([").rstrip(")]")
    if unit not in PRESSURE_UNITS:
        raise TengsimError(f"--data {path}: the pressure column {head[pi]!r} names no unit: call it pressure_kPa, "
                           "pressure_Pa or pressure_MPa")
    if "voc_v" not in low:
        raise TengsimError(f"--data {path}: no voc_V column (the open-circuit voltage in volts); columns: "
                           f"{', '.join(head)}")
    vi = low.index("voc_v")
    ei = low.index("voc_err_v") if "voc_err_v" in low else None
    bi = low.index("branch") if "branch" in low else None
    P, V, E, B = [], [], [], []
    for k, row in enumerate(rows[1:], start=2):
        where = f"--data {path}, data row {k - 1}"
        if len(row) < len(head):
            raise TengsimError(f"{where}: {len(row)} values for {len(head)} columns")
        P.append(_number(row[pi], where, head[pi]) * PRESSURE_UNITS[unit])
        v = _number(row[vi], where, "voc_V")
        if v < 0:
            raise TengsimError(f"{where}: voc_V = {row[vi].strip()} V is negative (give the open-circuit voltage's "
                               "magnitude)")
        V.append(v)
        if ei is not None:
            e = _number(row[ei], where, "voc_err_V")
            if not e > 0:
                raise TengsimError(f"{where}: voc_err_V = {row[ei].strip()} V must be > 0")
            E.append(e)
        b = row[bi].strip().lower() if bi is not None else "approach"
        if b not in BRANCHES:
            raise TengsimError(f"{where}: branch = {shown(row[bi])}: approach or retraction")
        B.append(b)
        if P[-1] < 0:
            raise TengsimError(f"{where}: {head[pi]} = {row[pi].strip()} is a negative pressure")
    if not P:
        raise TengsimError(f"--data {path}: a header and no data rows")
    seen = {}
    for p, v, b in zip(P, V, B):
        if (p, b) in seen and seen[(p, b)] != v:
            raise TengsimError(f"--data {path}: the pressure {p / 1e3:g} kPa ({b}) appears twice with different "
                               f"voltages ({seen[(p, b)]:g} V and {v:g} V)")
        seen[(p, b)] = v
    return Curve(str(path), np.asarray(P, float), np.asarray(V, float), tuple(B),
                 None if ei is None else np.asarray(E, float))


def write_curve(path, pressure_Pa, voc_V, err_V=None, comment: str = "") -> None:
    """A measured-curve CSV (pressure_kPa, voc_V[, voc_err_V]) as :func:`read_curve` reads it."""
    from tengsim.io import write_text

    lines = [f"# {ln}" for ln in comment.splitlines()] if comment else []
    lines.append("pressure_kPa,voc_V" + (",voc_err_V" if err_V is not None else ""))
    for i, (p, v) in enumerate(zip(pressure_Pa, voc_V)):
        lines.append(f"{p / 1e3:.10g},{v:.10g}" + (f",{err_V[i]:.6g}" if err_V is not None else ""))
    write_text(path, "\n".join(lines) + "\n")
