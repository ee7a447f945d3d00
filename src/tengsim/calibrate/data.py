"""A measured curve: V_OC against the nominal pressure, read from a CSV file and checked.

The file: lines starting with ``#`` are comments; a header row; a pressure column whose name carries its unit
(``pressure_Pa``, ``pressure_kPa``, ``pressure_MPa``: the unit's case matters, ``mPa`` is refused); ``voc_V``
(volts); optionally ``branch`` (approach or retraction; default approach) and ``voc_err_V`` (the measurement's
standard uncertainty, volts).  What spreadsheets write is read: a UTF-8 byte-order mark (Excel's "CSV UTF-8"), a
UTF-16 one (Excel's "Unicode text"), CRLF line ends, ``,`` ``;`` or a tab between the columns (the header's
separator is the file's), empty fields at the end of a row.  A decimal comma (``6,1``) is refused, never read as
two fields; a row with more fields than the header is an error.  At most :data:`MAX_POINTS` points, lines of at
most :data:`MAX_LINE` characters and files of at most :data:`MAX_BYTES`, checked while reading.  Anything wrong is
one :class:`tengsim.errors.TengsimError` line naming the file, the line and the value.
"""
from __future__ import annotations

import codecs
import csv
import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from tengsim.errors import ConfigValueError, TengsimError, shown

PRESSURE_UNITS = {"Pa": 1.0, "kPa": 1e3, "MPa": 1e6}
"""The pressure column's units, as spelled (case-sensitive where it matters: mPa is not MPa)."""
BRANCHES = ("approach", "retraction")
SEPARATORS = {",": "','", ";": "';'", "\t": "a tab"}
"""Column separators read, with their names in messages."""
MAX_POINTS = 10_000
"""The most points of one measured curve (a curve is tens of points; thin a logger's stream first)."""
MAX_LINE = 4096
"""The longest line of a measured-curve file (characters)."""
MAX_BYTES = 16 * 2**20
"""The largest measured-curve file (bytes): 10 000 points with comments fit many times over."""
MAX_PRESSURE = 1e10
"""The largest measured pressure (Pa, 10 GPa): beyond any contact of a TENG; a larger one is a wrong unit."""
_UNITS_TEXT = "pressure_Pa, pressure_kPa or pressure_MPa"


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
    """One field as a number (:func:`tengsim.units.read_number`: no underscores, bounded), a decimal comma
    refused."""
    from tengsim.units import read_number

    s = str(text).strip()
    if re.fullmatch(r"[-+]?[0-9]*,[0-9]*([eE][-+]?[0-9]+)?", s) and any(c.isdigit() for c in s):
        raise TengsimError(f"{where}: {column} = {shown(text)} has a decimal comma: write "
                           f"{s.replace(',', '.')} (a decimal point, no thousands separator)")
    try:
        v = read_number(s, column)
    except ConfigValueError as exc:
        raise TengsimError(f"{where}: {exc}") from None
    except ValueError:
        raise TengsimError(f"{where}: {column} = {shown(text)} is not a number") from None
    if not math.isfinite(v):
        raise TengsimError(f"{where}: {column} = {shown(text)} is not a finite number")
    return v


def _fields(line, sep, where):
    """The fields of one line (csv quoting), empty fields at its end dropped."""
    try:
        row = next(csv.reader([line], delimiter=sep, strict=True), [])
    except csv.Error as exc:
        raise TengsimError(f"{where}: not a CSV row ({exc})") from None
    while row and not row[-1].strip():
        row.pop()
    return row


def _lines(path, label):
    """(line number, text) of the file's lines that are neither blank nor comments, read as a spreadsheet
    writes them (module doc); the size and each line's length bounded."""
    p = Path(path)
    if p.is_dir():
        raise TengsimError(f"{label}: is a folder, not a CSV file")
    if not p.is_file():
        raise TengsimError(f"{label}: no such file")
    size = p.stat().st_size
    if size > MAX_BYTES:
        raise TengsimError(f"{label}: {size / 2**20:.1f} MiB, more than a measured curve ({MAX_BYTES // 2**20} MiB "
                           f"at most; a curve is at most {MAX_POINTS} points)")
    try:
        raw = p.read_bytes()
    except OSError as exc:
        raise TengsimError(f"{label}: {exc.strerror or exc}") from None
    enc = "utf-16" if raw[:2] in (codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE) else "utf-8-sig"
    try:
        text = raw.decode(enc)
    except UnicodeDecodeError as exc:
        raise TengsimError(f"{label}: not UTF-8 text (byte {exc.start}): save it as CSV UTF-8") from None
    if "\x00" in text:
        raise TengsimError(f"{label}: holds NUL characters: not a text (CSV) file")
    for i, line in enumerate(text.splitlines(), start=1):
        if len(line) > MAX_LINE:
            raise TengsimError(f"{label}, line {i}: {len(line)} characters, more than a measured curve's line "
                               f"({MAX_LINE} at most)")
        s = line.strip()
        if s and not s.startswith("#"):
            yield i, line


def _separator(header):
    """The header's column separator: the first of ',', ';', tab whose split names a pressure and a voc_V
    column, else the one that splits it most; None for a header of one column."""
    found = [s for s in SEPARATORS if s in header]
    for s in found:
        low = [h.strip().lower() for h in header.split(s)]
        if "voc_v" in low and any(h.startswith("pressure") for h in low):
            return s
    return max(found, key=lambda s: header.count(s)) if found else None


def _pressure_unit(name, label):
    unit = name[len("pressure"):].strip().lstrip("_ ([").rstrip(")]").strip()
    if unit in PRESSURE_UNITS:
        return unit
    if unit.lower() in ("pa", "kpa"):  # no other unit is spelled so: the case does not matter here
        return {"pa": "Pa", "kpa": "kPa"}[unit.lower()]
    if unit.lower() == "mpa":
        raise TengsimError(f"{label}: the pressure column {shown(name)} names {shown(unit)}: mPa would be "
                           f"millipascal, MPa megapascal; write the unit as {_UNITS_TEXT}")
    if not unit:
        raise TengsimError(f"{label}: the pressure column {shown(name)} names no unit: call it {_UNITS_TEXT}")
    raise TengsimError(f"{label}: the pressure column {shown(name)} names the unit {shown(unit)}, not one read "
                       f"here: call it {_UNITS_TEXT}")


def _header(i, line, label):
    """(separator, column names, pressure index, its unit, voc index, error index, branch index)."""
    sep = _separator(line)
    head = _fields(line, sep, f"{label}, line {i}") if sep else [line.strip()]
    low = [h.strip().lower() for h in head]
    if sep is None and re.search(r"\s", line.strip()) and ("voc" in low[0] or "pressure" in low[0]):
        raise TengsimError(f"{label}, line {i}: the header {shown(line.strip())} is one column: separate the "
                           "columns with ',', ';' or a tab")
    how = f" (columns separated by {SEPARATORS[sep]})" if sep else " (one column: separate with ',', ';' or a tab)"
    pcols = [k for k, h in enumerate(low) if h.startswith("pressure")]
    if not pcols:
        raise TengsimError(f"{label}: no pressure column (name it with its unit: {_UNITS_TEXT}); columns{how}: "
                           f"{shown(', '.join(head))}")
    for name in ("pressure", "voc_v", "voc_err_v", "branch"):
        same = [head[k].strip() for k, h in enumerate(low) if (h.startswith(name) if name == "pressure" else
                                                                h == name)]
        if len(same) > 1:
            raise TengsimError(f"{label}: {len(same)} columns {shown(', '.join(same))}: give each once")
    unit = _pressure_unit(head[pcols[0]].strip(), label)
    if "voc_v" not in low:
        raise TengsimError(f"{label}: no voc_V column (the open-circuit voltage in volts); columns{how}: "
                           f"{shown(', '.join(head))}")
    find = lambda n: low.index(n) if n in low else None  # noqa: E731
    return sep, [h.strip() for h in head], pcols[0], unit, low.index("voc_v"), find("voc_err_v"), find("branch")


def _row_width(row, head, line, sep, where):
    if len(row) == len(head):
        return
    other = [SEPARATORS[s] for s in SEPARATORS if s != sep and s in line]
    why = f"; this line is separated by {other[0]}, the header by {SEPARATORS[sep]}" if other else ""
    if len(row) > len(head) and not why and sep == ",":
        why = "; a decimal comma? write 6.1, not 6,1"
    n = len(row)
    raise TengsimError(f"{where}: {n} value{'s' if n != 1 else ''} for {len(head)} columns ({', '.join(head)}){why}")


def read_curve(path) -> Curve:
    """Read and check one measured curve (module doc)."""
    label = f"--data {path}"
    lines = _lines(path, label)
    first = next(lines, None)
    if first is None:
        raise TengsimError(f"{label}: no header row and no data")
    sep, head, pi, unit, vi, ei, bi = _header(*first, label)
    P, V, E, B = [], [], [], []
    seen = {}
    for i, line in lines:
        where = f"{label}, line {i}"
        if len(P) >= MAX_POINTS:
            raise TengsimError(f"{where}: more than {MAX_POINTS} points: a measured curve has at most {MAX_POINTS} "
                               "(thin the data, or split them into curves)")
        row = _fields(line, sep, where)
        _row_width(row, head, line, sep, where)
        p = _number(row[pi], where, head[pi])
        if p < 0:
            raise TengsimError(f"{where}: {head[pi]} = {row[pi].strip()} is a negative pressure")
        p *= PRESSURE_UNITS[unit]
        if p > MAX_PRESSURE:
            raise TengsimError(f"{where}: {head[pi]} = {row[pi].strip()} is {p / 1e9:.3g} GPa, beyond any contact "
                               f"pressure ({MAX_PRESSURE / 1e9:g} GPa at most): check the column's unit")
        v = _number(row[vi], where, "voc_V")
        if v < 0:
            raise TengsimError(f"{where}: voc_V = {row[vi].strip()} V is negative (give the open-circuit voltage's "
                               "magnitude)")
        if ei is not None:
            e = _number(row[ei], where, "voc_err_V")
            if not e > 0:
                raise TengsimError(f"{where}: voc_err_V = {row[ei].strip()} V must be > 0")
            E.append(e)
        b = row[bi].strip().lower() if bi is not None else "approach"
        if b not in BRANCHES:
            raise TengsimError(f"{where}: branch = {shown(row[bi])}: approach or retraction")
        if (p, b) in seen and seen[(p, b)] != v:
            raise TengsimError(f"{label}: the pressure {p / 1e3:g} kPa ({b}) appears twice with different "
                               f"voltages ({seen[(p, b)]:g} V and {v:g} V)")
        seen[(p, b)] = v
        P.append(p)
        V.append(v)
        B.append(b)
    if not P:
        raise TengsimError(f"{label}: a header and no data rows")
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
