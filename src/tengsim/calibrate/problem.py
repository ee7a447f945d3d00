"""What is fitted: the designs the curves were measured on, the free parameters and their bounds, the noise model.

Parameters (SI): ``sigma`` (tribo-charge density, C/m²), ``W`` (work of adhesion, J/m²), ``eps`` (range ε of the
adhesive law, m), ``E_star`` (effective modulus, Pa).  Each is free within bounds (fitted in log space) or fixed at
the designs' value.  V_OC is linear in σ (Eq. 12: σ (A/S) T/(ε_r ε0); Eq. 17: σ (A/S) d0/ε0), so σ is profiled out
in closed form; only W, ε and E* need contact solves.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from tengsim.errors import TengsimError, shown

PARAMS = ("sigma", "W", "eps", "E_star")
UNITS = {"sigma": ("µC/m²", 1e-6, "uC/m2"), "W": ("mJ/m²", 1e-3, "mJ/m2"), "eps": ("nm", 1e-9, "nm"),
         "E_star": ("MPa", 1e6, "MPa")}
"""Display unit (text, SI factor, parse spelling)."""
KINDS = {"sigma": "charge/area", "W": "energy/area", "eps": "length", "E_star": "pressure"}
DEFAULT_BOUNDS = {"sigma": (0.01e-6, 500e-6), "W": (10e-3, 1000e-3), "eps": (20e-9, 400e-9), "E_star": (0.1e6, 10e6)}
"""Default bounds (SI): σ 0.01–500 µC/m² (air breakdown caps a TENG's σ at a few hundred), W 10–1000 mJ/m² (the
literature the paper cites spans 25–1000), ε 20–400 nm (a continuum model range: below, grids grow as ε⁻¹ per
side; the paper's own is 370 nm), E* 0.1–10 MPa (soft polymers; PDMS 0.36–0.87)."""
DEFAULT_FREE = ("sigma", "W", "eps")
ALIASES = {"sigma": "sigma", "σ": "sigma", "w": "W", "eps": "eps", "ε": "eps", "epsilon": "eps", "e_star": "E_star",
           "estar": "E_star", "e*": "E_star"}
NOISES = ("relative", "absolute")
VOC_MODELS = ("eq12", "eq17")


def text(name: str, value: float, digits: int = 4) -> str:
    """'54 mJ/m²' of a parameter value (SI)."""
    unit, f, _ = UNITS[name]
    return f"{value / f:.{digits}g} {unit}"


def label(name: str) -> str:
    return {"sigma": "σ", "W": "W", "eps": "ε", "E_star": "E*"}[name]


def parse_free(spec) -> tuple:
    """'sigma,W,eps' → ('sigma', 'W', 'eps') in :data:`PARAMS` order."""
    if spec is None:
        return DEFAULT_FREE
    items = [s.strip() for s in (spec.split(",") if isinstance(spec, str) else spec) if str(s).strip()]
    out = []
    for s in items:
        k = ALIASES.get(s.lower()) if s not in PARAMS else s
        if k is None:
            raise TengsimError(f"--free {s!r}: not a parameter (sigma, W, eps, E_star)")
        out.append(k)
    if not out:
        raise TengsimError("--free names no parameter (sigma, W, eps, E_star)")
    return tuple(k for k in PARAMS if k in out)


PLAUSIBLE_AS = {"W": "energy/area", "eps": "length", "E_star": "modulus"}
"""The quantity (:data:`tengsim.units.PLAUSIBLE`) a bare number given as a bound must be plausible for."""


def _bound(text, name: str) -> float:
    """One bound in SI: a quantity with its unit, or a bare number read as SI and refused where implausible
    (``W=10:60`` is 10 to 60 J/m², not mJ/m²: one line naming it, as a design's keys are)."""
    from tengsim.units import check_plausible, parse_quantity

    value = parse_quantity(text, KINDS[name], name)
    try:
        float(str(text).strip())
    except ValueError:
        return value  # it carries its unit
    if name in PLAUSIBLE_AS:
        check_plausible(name, value, PLAUSIBLE_AS[name])
    return value


ALLOWED = {"sigma": (1e-9, 1e-2), "W": (1e-6, 10.0), "eps": (0.1e-9, 10e-6), "E_star": (1e2, 1e12)}
"""The range (SI) a bound may lie in: σ a design's own (:data:`tengsim.design.plan.DEVICE_BOUNDS`, 1 nC/m² …
10 mC/m²), W and E* what a design's keys take as plausible (:data:`tengsim.units.PLAUSIBLE`: 0.001 … 10 000 mJ/m²,
100 Pa … 1 TPa), ε from an atomic spacing to the largest micro-structures (0.1 nm … 10 µm)."""


def _range_text(name: str) -> str:
    from tengsim.units import format_si

    unit = {"sigma": "C/m²", "W": "J/m²", "eps": "m", "E_star": "Pa"}[name]
    return " to ".join(format_si(x, unit, 4) for x in ALLOWED[name])


def _one_bound(name: str, v) -> tuple:
    if isinstance(v, str):
        parts = v.split(":")
        if len(parts) != 2 or not all(x.strip() for x in parts):
            raise TengsimError(f"--bounds {name}={shown(v)}: give {name}=LOW:HIGH, e.g. {name}="
                               f"{EXAMPLE[name]}")
    else:
        parts = tuple(v) if isinstance(v, (tuple, list)) else ()
        if len(parts) != 2:
            raise TengsimError(f"--bounds {name}: give (LOW, HIGH), got {shown(v)}")
    try:
        lo, hi = (_bound(x, name) for x in parts)
    except TengsimError as exc:
        raise TengsimError(f"--bounds {name}: {exc}") from None
    if not 0 < lo < hi:
        raise TengsimError(f"--bounds {name}: need 0 < low < high, got {text(name, lo)} to {text(name, hi)}")
    a, b = ALLOWED[name]
    if lo < a or hi > b:
        raise TengsimError(f"--bounds {name}: {text(name, lo)} to {text(name, hi)} is outside the allowed range "
                           f"{_range_text(name)}")
    return lo, hi


EXAMPLE = {"sigma": "1uC/m2:100uC/m2", "W": "20mJ/m2:200mJ/m2", "eps": "30nm:300nm", "E_star": "0.5MPa:5MPa"}


def parse_bounds(spec, free=None) -> dict:
    """'W=20mJ/m2:200mJ/m2,eps=30nm:300nm' (or a dict {name: (lo, hi)} of strings or SI numbers) → {name: (lo, hi)}
    (SI), each within :data:`ALLOWED`; a parameter named twice, or (given ``free``) one that is not free, is
    refused."""
    if not spec:
        return {}
    if isinstance(spec, dict):
        items = list(spec.items())
    else:
        items = []
        for s in str(spec).split(","):
            if not s.strip():
                continue
            if "=" not in s:
                raise TengsimError(f"--bounds {shown(s.strip())}: give NAME=LOW:HIGH, e.g. W=20mJ/m2:200mJ/m2")
            items.append(tuple(s.split("=", 1)))
    out = {}
    for k, v in items:
        key = str(k).strip()
        name = key if key in PARAMS else ALIASES.get(key.lower())
        if name is None:
            raise TengsimError(f"--bounds {shown(key)}: not a parameter (sigma, W, eps, E_star)")
        if name in out:
            raise TengsimError(f"--bounds {name} is given twice: give each parameter's bounds once")
        if free is not None and name not in free:
            raise TengsimError(f"--bounds {name}: {name} is not free (--free {','.join(free)}): its bounds would "
                               f"be ignored; add it to --free or leave its bounds out")
        out[name] = _one_bound(name, v)
    return out


@dataclass(frozen=True)
class Problem:
    """The designs (one :class:`tengsim.design.DesignPlan` per curve), the curves, what is free and its bounds
    (SI), the fixed values (SI), the noise model and the V_OC model; ``E_ref`` the modulus the contact solves use
    (E* enters as a pressure scale: :mod:`tengsim.calibrate.surrogate`)."""

    plans: tuple
    tables: tuple
    curves: tuple
    free: tuple
    bounds: dict
    fixed: dict
    noise: str = "relative"
    voc: str = "eq12"
    E_ref: float = 1e6
    names: tuple = field(default_factory=tuple)

    @property
    def contact_free(self) -> tuple:
        return tuple(k for k in self.free if k != "sigma")

    @property
    def n_points(self) -> int:
        return sum(c.n for c in self.curves)

    @property
    def known_errors(self) -> bool:
        return all(c.err is not None for c in self.curves)

    def factor(self, i: int) -> float:
        """V_OC per unit σ per unit A/S of curve ``i`` (V m²/C): T/(ε_r ε0) (Eq. 12) or d0/ε0 (Eq. 17)."""
        from tengsim.device.formulas import eq12_volts_per_charge, eq17_volts_per_charge

        p = self.plans[i]
        return eq12_volts_per_charge(p.eps_r, p.T) if self.voc == "eq12" else float(eq17_volts_per_charge(p.gap))

    def value(self, name: str, theta: dict | None = None) -> float:
        if theta is not None and name in theta:
            return theta[name]
        return self.fixed[name]


def check_reachable(prob: Problem) -> None:
    """A curve whose voltages no σ within bounds can give, refused with the numbers and the reason: one above
    what its geometry gives with the whole cell charged (A/S = 1); one that is 0 V at every point (nothing to
    fit: σ is at least its lower bound); one whose largest voltage needs, at the lowest σ, a charged area below
    one pixel of the largest grid any design may use (:data:`tengsim.resources.MAX_PIXELS_PER_SIDE` ²)."""
    from tengsim.resources import MAX_PIXELS_PER_SIDE

    s_hi = prob.bounds["sigma"][1] if "sigma" in prob.free else prob.fixed["sigma"]
    s_lo = prob.bounds["sigma"][0] if "sigma" in prob.free else prob.fixed["sigma"]
    which = "the upper bound of σ" if "sigma" in prob.free else "the fixed σ"
    a_min = 1.0 / MAX_PIXELS_PER_SIDE**2
    for i, c in enumerate(prob.curves):
        top = s_hi * prob.factor(i) * 1.0
        k = int(np.argmax(c.voc))
        if c.voc[k] > top:
            raise TengsimError(f"--data {c.source}: {c.voc[k]:.4g} V at {c.pressure[k] / 1e3:g} kPa exceeds what "
                               f"the design can give at any σ within bounds: at most {top:.4g} V ({which} "
                               f"{text('sigma', s_hi)}, the whole cell charged, A/S = 1, {prob.voc})")
        if not c.voc[k] > 0:
            raise TengsimError(f"--data {c.source}: every voc_V is 0 V: nothing to fit (V_OC = σ (A/S) k, and σ is at "
                               f"least {text('sigma', s_lo)}); give a curve with voltages above 0")
        low = s_lo * prob.factor(i) * a_min
        if c.voc[k] < low:
            lower = "the lower bound of σ" if "sigma" in prob.free else "the fixed σ"
            raise TengsimError(f"--data {c.source}: its largest voltage {c.voc[k]:.4g} V is below what the design "
                               f"can give at any σ within bounds: at least {low:.3g} V ({lower} "
                               f"{text('sigma', s_lo)}, one pixel of a {MAX_PIXELS_PER_SIDE}² grid charged, "
                               f"{prob.voc}): check the voltage's unit (voc_V is in volts)")


def count_check(prob: Problem) -> None:
    n, p = prob.n_points, len(prob.free)
    if n < p:
        raise TengsimError(f"{n} measured points for {p} free parameters ({', '.join(prob.free)}): give at least {p}")
    if n == p and not prob.known_errors:
        raise TengsimError(f"{n} measured points for {p} free parameters and no voc_err_V column: the noise cannot "
                           f"be estimated; give at least {p + 1} points or the uncertainty column")


def log_bounds(prob: Problem) -> np.ndarray:
    """(d, 2) natural-log bounds of the contact parameters that are free."""
    return np.array([[math.log(v) for v in prob.bounds[k]] for k in prob.contact_free]).reshape(-1, 2)
