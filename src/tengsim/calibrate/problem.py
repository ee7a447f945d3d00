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

from tengsim.errors import TengsimError

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


def parse_bounds(spec) -> dict:
    """'W=20mJ/m2:200mJ/m2,eps=30nm:300nm' (or a dict {name: (lo, hi)} of strings or SI numbers) → {name: (lo, hi)}."""
    from tengsim.units import parse_quantity

    if not spec:
        return {}
    items = spec.items() if isinstance(spec, dict) else [s.split("=", 1) for s in spec.split(",") if s.strip()]
    out = {}
    for item in items:
        if len(item) != 2:
            raise TengsimError(f"--bounds {'='.join(item)!r}: give NAME=LOW:HIGH, e.g. W=20mJ/m2:200mJ/m2")
        k, v = item
        name = ALIASES.get(str(k).strip().lower()) if str(k).strip() not in PARAMS else str(k).strip()
        if name is None:
            raise TengsimError(f"--bounds {k!r}: not a parameter (sigma, W, eps, E_star)")
        lo, hi = v.split(":", 1) if isinstance(v, str) else v
        try:
            lo, hi = (_bound(x, name) for x in (lo, hi))
        except TengsimError as exc:
            raise TengsimError(f"--bounds {name}: {exc}") from None
        if not 0 < lo < hi:
            raise TengsimError(f"--bounds {name}: need 0 < low < high, got {text(name, lo)} to {text(name, hi)}")
        out[name] = (lo, hi)
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
    """A curve whose voltage exceeds what its geometry can give at any σ within bounds (the whole cell charged,
    A/S = 1): refused with the numbers."""
    s_hi = prob.bounds["sigma"][1] if "sigma" in prob.free else prob.fixed["sigma"]
    for i, c in enumerate(prob.curves):
        top = s_hi * prob.factor(i) * 1.0
        k = int(np.argmax(c.voc))
        if c.voc[k] > top:
            which = "the upper bound of σ" if "sigma" in prob.free else "the fixed σ"
            raise TengsimError(f"--data {c.source}: {c.voc[k]:.4g} V at {c.pressure[k] / 1e3:g} kPa exceeds what "
                               f"the design can give at any σ within bounds: at most {top:.4g} V ({which} "
                               f"{text('sigma', s_hi)}, the whole cell charged, A/S = 1, {prob.voc})")


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
