"""Physical units at the edges: quantity parsing and the scaling of Eq. (7) for any shape."""
from __future__ import annotations

import math
import re
from dataclasses import dataclass

from tengsim.errors import ConfigValueError, NumberError, TengsimError, positive, shown

_PREFIX = {"": 1.0, "k": 1e3, "M": 1e6, "G": 1e9, "m": 1e-3, "u": 1e-6, "µ": 1e-6, "μ": 1e-6,
           "n": 1e-9, "p": 1e-12, "c": 1e-2}
_BASE = {
    "m": ("length", 1.0),
    "m2": ("area", 1.0),  # its prefix is squared: 4cm2 is 4e-4 m2
    "Pa": ("pressure", 1.0),
    "N/m2": ("pressure", 1.0),
    "J/m2": ("energy/area", 1.0),
    "N/m": ("energy/area", 1.0),
    "N": ("force", 1.0),
    "C/m2": ("charge/area", 1.0),
    "F/m": ("permittivity", 1.0),
    "ohm": ("resistance", 1.0),
    "Ohm": ("resistance", 1.0),
    "Hz": ("frequency", 1.0),
    "s": ("time", 1.0),
    "g": ("mass", 1e-3),
    "kg": ("mass", 1.0),
}
_NUM = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"


def _compact(text, name: str = "value") -> str:
    """``text`` without its spaces ('20 kPa' → '20kPa', '^2' and '²' as '2'), refusing a space inside the
    number itself ('2 0kPa' is not 20 kPa; '- 5' is not -5): spaces may only stand between the number and its
    unit, or inside the unit."""
    raw = str(text).strip()
    m = re.match(_NUM, raw)
    if re.match(r"[-+]\s+[\d.]", raw) or (m and re.match(r"\s+[-+]?[\d.]", raw[m.end():])):
        raise ConfigValueError(f"{name} = {shown(text)}: a space inside a number (write it without spaces, "
                               "e.g. '20kPa' or '20 kPa')")
    return raw.replace(" ", "").replace("^2", "2").replace("²", "2")


MAX_TEXT = 64
"""The longest text read as a number or a quantity (characters): a longer one is refused unread."""
MAX_MAGNITUDE = 1e100
"""The largest |value| (SI) any input may have; the smallest non-zero one is its inverse.  Every
physical input lies far inside (a Planck length is 1.6e-35 m); past it, grids and scalings overflow."""

_OUT_OF_RANGE = (f" is out of range: a value's magnitude must lie between {1 / MAX_MAGNITUDE:g} and {MAX_MAGNITUDE:g} "
                 "(or be 0)")


def bounded(x: float, text, name: str = "value") -> float:
    """``x`` if finite and 0 or within [1/MAX_MAGNITUDE, MAX_MAGNITUDE] in magnitude, else a
    ConfigValueError naming ``name`` and (cut) ``text``."""
    if not math.isfinite(x):
        raise NumberError(name, text, "", finite=True)
    if x != 0 and not (1.0 / MAX_MAGNITUDE <= abs(x) <= MAX_MAGNITUDE):
        raise NumberError(name, text, _OUT_OF_RANGE)
    return x


def read_number(text, name: str = "value") -> float:
    """The one place where text becomes a number: '0.5', '-1e-3', 'nan' → float, bounded (:func:`bounded`).

    A text longer than :data:`MAX_TEXT` characters, or holding an underscore ('0_5': Python's ``float``
    reads it as 5, a typo for 0.5 more likely than a digit separator), is refused; so is anything
    ``float`` does not read.  A ValueError (not a TengsimError) for text that is not a plain number, so
    that a caller may read it as a quantity instead; a ConfigValueError for a number out of bounds."""
    if isinstance(text, bool):
        raise ValueError(f"{text!r} is not a number")
    if isinstance(text, int):
        if abs(text) > MAX_MAGNITUDE:
            raise NumberError(name, text, _OUT_OF_RANGE)
        return bounded(float(text), text, name)
    if isinstance(text, float):
        return bounded(text, text, name)
    s = str(text).strip()
    if len(s) > MAX_TEXT:
        raise NumberError(name, text, f" is not a number (a number or quantity is at most {MAX_TEXT} characters)")
    if "_" in s:
        raise NumberError(name, text, ": no underscores in numbers (write 0.5, not 0_5)")
    x = float(s)  # a ValueError for anything else
    if math.isnan(x):
        return x  # NaN is left to each key's own check (finite, positive), which names it
    return bounded(x, text, name)


def number_or_text(v, label: str, quantity: str):
    """A key that takes a plain number or, in a physical run, ``quantity`` with a unit ("5nm", "-2kPa"): the
    number as float, a numeric string as float, other text stripped (its unit is checked later)."""
    if isinstance(v, bool) or not isinstance(v, (int, float, str)):
        raise TengsimError(f"{label} must be a number or {quantity} with a unit, got {shown(v)}")
    try:
        return read_number(v, label)
    except ConfigValueError:
        raise
    except ValueError:
        return v.strip()


def parse_quantity(text, kind: str | None = None, name: str = "value") -> float:
    """'0.59MPa' → 590000.0 (SI).  A bare number is taken as SI.  ``kind`` checks the dimension.

    Units: m, m2, Pa, N/m2, J/m2, N/m, N, C/m2, ohm, Hz, s, g, kg, with prefixes k M G m u µ n p c
    (e.g. um, mJ/m2, uC/m2, MOhm, cm, cm2: an area's prefix is squared).  'm2', '^2' and '²' are all accepted.
    """
    if isinstance(text, (int, float)) and not isinstance(text, bool):
        v = read_number(text, name)
    else:
        s = _compact(text, name)
        if len(s) > MAX_TEXT or "_" in s:
            read_number(s, name)  # refuses it, naming it
        m = re.fullmatch(f"({_NUM})(.*)", s)
        if not m:
            raise TengsimError(f"cannot read {name} = {shown(text)} as a number with a unit")
        v = read_number(m.group(1), name)
        unit = m.group(2)
        if unit:
            found = None
            for base, (dim, f) in _BASE.items():
                for pre, pf in _PREFIX.items():
                    if unit == pre + base and (found is None or len(base) > len(found[0])):
                        found = (base, dim, f * (pf * pf if dim == "area" else pf))
            if found is None:
                raise TengsimError(f"unknown unit {shown(unit)} in {name} = {shown(text)}")
            _, dim, factor = found
            if kind and dim != kind:
                raise TengsimError(f"{name} = {shown(text)} is a {dim}, expected {'an' if kind[0] in 'aeiou' else 'a'} "
                                   f"{kind}")
            v = bounded(v * factor, text, name)
    if not math.isfinite(v):
        raise TengsimError(f"{name} must be finite, got {shown(text)}")
    return v


def quantity_dim(text) -> str | None:
    """The dimension of a quantity's unit ('2um' → 'length'), or None for a bare number (int, float or
    a numeric string).  An unreadable value or unknown unit is a TengsimError, as in :func:`parse_quantity`."""
    parse_quantity(text)
    if isinstance(text, (int, float)):
        return None
    s = _compact(text)
    unit = re.fullmatch(f"({_NUM})(.*)", s).group(2)
    if not unit:
        return None
    found = None
    for base, (dim, _) in _BASE.items():
        for pre in _PREFIX:
            if unit == pre + base and (found is None or len(base) > len(found[0])):
                found = (base, dim)
    return found[1]


DIMENSIONS = {
    "length": (0, 1, 0, 0),
    "area": (0, 2, 0, 0),
    "pressure": (1, -1, -2, 0),
    "energy/area": (1, 0, -2, 0),
    "force": (1, 1, -2, 0),
    "charge/area": (0, -2, 1, 1),
    "permittivity": (-1, -3, 4, 2),
    "resistance": (1, 2, -3, -2),
    "frequency": (0, 0, -1, 0),
    "time": (0, 0, 1, 0),
    "mass": (1, 0, 0, 0),
}
"""Each dimension of :func:`parse_quantity` as exponents of (kg, m, s, A); expressions multiply them."""

SI_UNIT = {"length": "m", "area": "m2", "pressure": "Pa", "energy/area": "J/m2", "force": "N", "charge/area": "C/m2",
           "permittivity": "F/m", "resistance": "ohm", "frequency": "Hz", "time": "s", "mass": "kg"}
"""The SI unit text of each dimension (what :func:`parse_quantity` reads back with factor 1)."""


def dimension_name(vec) -> str:
    """'length' for (0, 1, 0, 0); a product of base units (kg m^-1 ...) for a vector with no name."""
    for name, v in DIMENSIONS.items():
        if tuple(vec) == v:
            return name
    if not any(vec):
        return "dimensionless"
    return " ".join(f"{u}^{e}" if e != 1 else u for u, e in zip(("kg", "m", "s", "A"), vec) if e)


PLAUSIBLE = {
    # quantity: (smallest |value|, largest |value|, SI unit, what it is, the unit a user likely meant)
    "length": (1e-12, 1.0, "m", "a length", "um"),
    "modulus": (1e2, 1e12, "Pa", "a modulus", "MPa"),
    "pressure": (0.0, 1e10, "Pa", "a pressure", "kPa"),
    "energy/area": (1e-6, 10.0, "J/m2", "a work of adhesion", "mJ/m2"),
}
"""Ranges a bare number (read as SI) must fall in for its quantity (the [contact] keys of a physical run:
lengths, E* as a modulus, W as an energy per area; pressures for loads).  No real input lies outside them;
a value outside is almost surely a number given in another unit (0.59 meant as MPa, 2 as µm).  Zero and
negative values are left to each key's own check."""


def check_plausible(name: str, value, quantity: str) -> float:
    """Refuse a bare number ``value`` (SI) of ``quantity`` (a key of :data:`PLAUSIBLE`) outside its range:
    a ConfigValueError naming the value and the likely unit.  Quantities not in the table pass."""
    from tengsim.errors import ConfigValueError

    x = float(value)
    if quantity not in PLAUSIBLE or x == 0 or not math.isfinite(x):
        return x
    lo, hi, unit, what, likely = PLAUSIBLE[quantity]
    if lo <= abs(x) <= hi:
        return x
    shown = f"{x:g}"
    hint = "give it with its unit"
    if lo <= abs(parse_quantity(f"{shown}{likely}")) <= hi:  # the likely unit brings it into range
        hint += f", e.g. '{shown}{likely}'"
    raise ConfigValueError(f"{name} = {shown} is read as {shown} {unit} (a bare number is SI), implausible for "
                           f"{what} ({lo:g} to {hi:g} {unit}): {hint}")


class _Units:
    """Conversions shared by :class:`Scaling` and the paper's own (paper Eqs. 7, 9, 10).

    Needs ``E_star`` (Pa), ``W`` (J/m²), ``eps`` (m), ``lateral`` ℓ (m per unit of X) and
    ``cell_area`` (m², or None).
    """

    @property
    def coupling(self) -> float:
        """κ = W ℓ/(E* ε²), the factor of Eq. (9); κ = μ^{3/2}."""
        return self.W * self.lateral / (self.E_star * self.eps**2)

    @property
    def mu(self) -> float:
        """The Tabor-like parameter μ = κ^{2/3}."""
        return self.coupling ** (2.0 / 3.0)

    def length(self, X):
        """In-plane X (e.g. Λc) → metres: X ℓ."""
        return X * self.lateral

    def force(self, F):
        """Dimensionless F (Eq. 10) → newtons per cell: 3π W ℓ²/ε · F."""
        return F * 3 * math.pi * self.W * self.lateral**2 / self.eps

    def pressure(self, F):
        """Nominal pressure on the array: force per cell / cell area (Pa)."""
        if not self.cell_area:
            raise TengsimError("this scaling has no cell area: pressure is undefined")
        return self.force(F) / self.cell_area

    def displacement(self, D):
        """D → metres: D ε."""
        return D * self.eps

    def work(self, E):
        """∮ F dD → joules per cell: 3π W ℓ² · E."""
        return E * 3 * math.pi * self.W * self.lateral**2

    def units(self) -> dict:
        """Unit text of the dimensionless result columns, with their SI values."""
        return {
            "D": f"ε = {self.eps:.6g} m (rigid approach, Eq. 7)",
            "F": f"3π W ℓ²/ε = {self.force(1.0):.6g} N per cell (Eq. 10)",
            "contact_length": f"ℓ = {self.lateral:.6g} m (Λc)",
            "area_repulsive": f"ℓ² = {self.lateral**2:.6g} m²",
            "charged_fraction": "1 (A/S)",
            "residual": "ε (max |r| of Eq. 9)",
            "min_gap": f"ε = {self.eps:.6g} m",
            "F_N": "N (force per cell)",
            "pressure_Pa": "Pa (force per cell / cell area)",
            "contact_length_m": "m",
        }


@dataclass(frozen=True)
class Scaling(_Units):
    """Physical units of a dimensionless run, for any shape (paper Eq. 7 generalised).

    Heights are in ε, in-plane lengths in ℓ = ``lateral`` (metres per unit of X), pressures in W/ε.
    Eq. (9) then has the coupling κ = W ℓ/(E* ε²) = μ^{3/2}; the force of Eq. (10) is per cell in
    units of 3π W ℓ²/ε.  ``cell_area`` (m²) turns the force into a nominal pressure.
    """

    E_star: float
    W: float
    eps: float
    lateral: float
    cell_area: float | None = None

    def __post_init__(self):
        for k in ("E_star", "W", "eps", "lateral"):
            positive(k, getattr(self, k))
        if self.cell_area is not None:
            positive("cell_area", self.cell_area)

    def params(self) -> dict:
        d = {"E_star_Pa": self.E_star, "W_J_m2": self.W, "eps_m": self.eps, "lateral_m": self.lateral,
             "tabor": self.mu}
        if self.cell_area is not None:
            d["cell_area_m2"] = self.cell_area
        return d


def eps_for_tabor(lateral, E_star: float, W: float, mu: float) -> float:
    """ε (m) with κ(ε) = W ℓ(ε)/(E* ε²) = μ^{3/2}, for a lateral scale ``lateral(eps) -> ℓ``.

    Solved by Brent's method in log ε between 1e-15 m and 1 m; a TengsimError if no root lies there.
    """
    from scipy.optimize import brentq

    mu, E_star, W = positive("tabor", mu), positive("E_star", E_star), positive("W", W)
    target = 1.5 * math.log(mu)

    def f(t):
        e = math.exp(t)
        return math.log(W * lateral(e) / (E_star * e * e)) - target

    a, b = math.log(1e-15), math.log(1.0)
    fa, fb = f(a), f(b)
    if fa * fb > 0:
        raise TengsimError(f"no interaction range ε in [1e-15 m, 1 m] gives tabor = {mu:g}")
    t = brentq(f, a, b, xtol=1e-14, rtol=1e-15, maxiter=200)
    return math.exp(t)


_ENG = ((1e9, "G"), (1e6, "M"), (1e3, "k"), (1.0, ""), (1e-3, "m"), (1e-6, "µ"), (1e-9, "n"), (1e-12, "p"),
        (1e-15, "f"))


def si_prefix(magnitude: float, unit: str) -> tuple[float, str]:
    """(factor, prefixed unit) that shows numbers of about ``magnitude`` (in ``unit``, SI) between 1 and
    1000: ``si_prefix(3e-6, 'W')`` is (1e-6, 'µW'); 0 or a non-finite magnitude keeps the plain unit.
    A pressure stays in kPa or MPa style, a length in m…nm; ``unit`` 'kg' is not prefixed."""
    m = abs(float(magnitude))
    if not (m > 0 and math.isfinite(m)) or unit in ("kg", "1", ""):
        return 1.0, unit
    for f, p in _ENG:
        if m >= f * 0.9995:
            return f, p + unit
    return _ENG[-1][0], _ENG[-1][1] + unit


def format_si(value: float, unit: str, digits: int = 3) -> str:
    """``value`` (SI ``unit``) with an engineering prefix: ``format_si(1.23e-5, 'W')`` is '12.3 µW'."""
    f, u = si_prefix(value, unit)
    return f"{value / f:.{digits}g} {u}"


def si_unit(dim: str) -> str:
    """The SI unit symbol of a dimension of :func:`parse_quantity` ('length' → 'm', 'energy/area' → 'J/m2')."""
    for base, (d, factor) in _BASE.items():
        if d == dim and factor == 1.0:
            return base
    raise TengsimError(f"no SI unit for dimension {dim!r}")


# ---- numbers as a designer reads them (messages, reports, plots) ---------------------------------------
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
