"""Device parameters (paper Section 5, Eqs. 13-24) and the charged-area models.

All inputs are SI. The dimensionless groups of Eq. (23) are derived here so that the
integrator works on the well-scaled core of Eq. (24).
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import asdict, dataclass, field

import numpy as np

from tengsim.constants import EPS0
from tengsim.errors import TengsimError, finite, positive, require
from tengsim.schema import REQUIRED

FORCE_MODELS = ("field", "eq20", "none")
FIELD_MODELS = ("parallel", "finite")  # device/field.py
ELECTRODE_SHAPES = ("square", "disk")
AREA_PRESSURES = ("applied", "contact")
AREA_MEMORIES = ("max", "release")
INITIAL_CHARGES = ("zero", "rest")


def _f(help_text: str, default=REQUIRED, **meta):
    """A dataclass field whose help (and optional ``dim``, ``choices``) the config schema reads;
    without ``default`` (:data:`tengsim.schema.REQUIRED`) the field is required."""
    meta = {"help": help_text, **meta}
    if default is REQUIRED:
        return field(metadata=meta)
    if callable(default) and not isinstance(default, (int, float, str)):
        return field(default_factory=default, metadata=meta)
    return field(default=default, metadata=meta)


@dataclass(frozen=True)
class ConstantArea:
    """Charged area A = fraction * S, independent of pressure (flat interface, Fig. 7)."""

    fraction: float = 1.0
    carries_history = False  # A follows the pressure; the device's area_memory patches the gap (AreaCycle: True)

    def __post_init__(self):
        f = finite("area fraction", self.fraction)
        require(0.0 <= f <= 1.0, f"area fraction must be in [0, 1], got {self.fraction!r}")
        object.__setattr__(self, "fraction", f)

    @property
    def initial_fraction(self) -> float:
        """A flat device is taken as charged from the start."""
        return self.fraction

    def __call__(self, pressure_Pa):
        return np.full_like(np.asarray(pressure_Pa, dtype=float), self.fraction)

    def to_dict(self) -> dict:
        return {"kind": "constant", "fraction": self.fraction}


@dataclass(frozen=True, eq=False)
class AreaTable:
    """Charged-area fraction A/S = lambda_c^2/L^2 against pressure (Fig. 8a), linearly interpolated.

    Outside the table the end values are held. The polymer is uncharged until first contact.
    """

    carries_history = False

    pressure_Pa: np.ndarray
    area_fraction: np.ndarray

    def __post_init__(self):
        try:
            p = np.array(self.pressure_Pa, dtype=float).ravel()
            a = np.array(self.area_fraction, dtype=float).ravel()
        except (TypeError, ValueError):
            raise TengsimError("area table must hold numbers") from None
        require(p.size >= 2, f"area table needs at least 2 points, got {p.size}")
        require(p.size == a.size, f"area table: {p.size} pressures but {a.size} area fractions")
        require(bool(np.all(np.isfinite(p)) and np.all(np.isfinite(a))), "area table holds non-finite values")
        bad = np.flatnonzero(np.diff(p) <= 0)
        if bad.size:
            i = int(bad[0]) + 1
            raise TengsimError(f"area table pressures must be strictly increasing: row {i} holds {p[i]:.6g} Pa "
                               f"after {p[i - 1]:.6g} Pa (row {i - 1})")
        bad = a[(a < 0) | (a > 1)]
        require(bad.size == 0, f"area fractions must be in [0, 1], got {bad[:3].tolist()}")
        p.setflags(write=False)
        a.setflags(write=False)
        object.__setattr__(self, "pressure_Pa", p)
        object.__setattr__(self, "area_fraction", a)

    @classmethod
    def from_table(cls, table) -> "AreaTable":
        """Wrap any object with ``pressure_Pa`` and ``area_fraction`` (e.g. the contact engine's)."""
        return cls(table.pressure_Pa, table.area_fraction)

    @property
    def initial_fraction(self) -> float:
        return 0.0

    def __call__(self, pressure_Pa):
        return np.interp(np.asarray(pressure_Pa, dtype=float), self.pressure_Pa, self.area_fraction)

    def to_dict(self) -> dict:
        return {"kind": "table", "pressure_Pa": self.pressure_Pa.tolist(),
                "area_fraction": self.area_fraction.tolist()}


@dataclass(frozen=True, eq=False)
class AreaFunction:
    """Any callable pressure (Pa) -> charged-area fraction A/S in [0, 1], e.g. a user's model.

    ``initial_fraction`` is the charged fraction before the first contact (0: a patterned polymer).
    """

    carries_history = False

    function: object
    initial_fraction: float = 0.0
    name: str = ""

    def __post_init__(self):
        require(callable(self.function), f"area model must be callable, got {type(self.function).__name__}")
        f = finite("initial_fraction", self.initial_fraction)
        require(0.0 <= f <= 1.0, f"initial_fraction must be in [0, 1], got {self.initial_fraction!r}")
        object.__setattr__(self, "initial_fraction", f)
        if not self.name:
            object.__setattr__(self, "name", getattr(self.function, "__qualname__", type(self.function).__name__))

    def __call__(self, pressure_Pa):
        p = np.asarray(pressure_Pa, dtype=float)
        a = np.asarray(self.function(p), dtype=float)
        if a.shape != p.shape:
            a = np.broadcast_to(a, p.shape).astype(float)
        require(bool(np.all((a >= 0) & (a <= 1))),
                f"area model {self.name!r} returned a fraction outside [0, 1]: {np.ravel(a)[:3].tolist()}")
        return a

    def to_dict(self) -> dict:
        return {"kind": "function", "name": self.name, "initial_fraction": self.initial_fraction}


@dataclass(frozen=True, eq=False)
class AreaCycle:
    """A charged area that carries its own history: A/S over each period of a periodic press, at the phase
    ``phase`` (t f mod 1, increasing over [0, 1]) of a waveform at ``frequency_Hz`` (a viscoelastic contact's
    cycles, :func:`tengsim.device.areas.area_cycle_from_design`).  ``area_fraction``: the first press, from rest;
    ``later``: presses 2, 3, … as the contact passed them, each from the memory the one before left; ``steady``:
    the periodic steady state the presses tend to (None: every press is the first).  Press n beyond the recorded
    ones is the steady state plus the last recorded press's difference from it times ``decay``^(n − recorded),
    ``decay`` the ratio of the last two recorded presses' differences from the steady state (a geometric approach,
    the slowest branch's).  In contact the device's A/S is its press's at the waveform's phase; in flight the value
    the largest of the press just ended (the area that press charged, :meth:`largest`; the square press's at its
    release).  No ``area_memory`` rule applies: the history is in the cycles.  ``label`` says which cycle it is."""

    frequency_Hz: float
    phase: np.ndarray
    area_fraction: np.ndarray
    label: str = "viscoelastic cycle"
    details: dict = field(default_factory=dict)
    later: tuple = ()
    steady: np.ndarray | None = None

    carries_history = True

    def __post_init__(self):
        object.__setattr__(self, "frequency_Hz", positive("frequency_Hz", self.frequency_Hz))
        try:
            ph = np.array(self.phase, dtype=float).ravel()
            rows = [np.array(a, dtype=float).ravel() for a in (self.area_fraction, *self.later)]
            st = None if self.steady is None else np.array(self.steady, dtype=float).ravel()
        except (TypeError, ValueError):
            raise TengsimError("area cycle must hold numbers") from None
        require(ph.size >= 2, f"area cycle: {ph.size} phases, needs at least 2")
        for a in rows + ([st] if st is not None else []):
            require(a.size == ph.size, f"area cycle: {ph.size} phases but {a.size} area fractions")
            require(bool(np.all(np.isfinite(a))), "area cycle holds non-finite values")
            require(bool(np.all((a >= 0) & (a <= 1))), f"area fractions must be in [0, 1], got {a[(a < 0) | (a > 1)][:3]}")
        require(bool(np.all(np.isfinite(ph))), "area cycle holds non-finite values")
        require(bool(np.all(np.diff(ph) >= 0)) and ph[0] >= 0 and ph[-1] <= 1,
                "area cycle phases must increase within [0, 1]")
        for a in [ph] + rows + ([st] if st is not None else []):
            a.setflags(write=False)
        object.__setattr__(self, "phase", ph)
        object.__setattr__(self, "area_fraction", rows[0])
        object.__setattr__(self, "later", tuple(rows[1:]))
        object.__setattr__(self, "steady", st)
        decay = 0.0
        if st is not None and len(rows) >= 2:
            d1, d2 = rows[-2] - st, rows[-1] - st
            den = float(np.dot(d1, d1))
            decay = float(np.clip(np.dot(d2, d1) / den, 0.0, 1.0 - 1e-12)) if den > 0 else 0.0
        object.__setattr__(self, "_decay", decay)

    @property
    def decay(self) -> float:
        """The presses' geometric approach to the steady state beyond the recorded ones (class doc)."""
        return self._decay

    @property
    def initial_fraction(self) -> float:
        """Uncharged until the first contact."""
        return 0.0

    def press(self, n: int) -> np.ndarray:
        """A/S on ``phase`` of press ``n`` (1: the first, from rest)."""
        rows = (self.area_fraction, *self.later)
        n = max(int(n), 1)
        if n <= len(rows) or self.steady is None:
            return rows[min(n, len(rows)) - 1]
        return np.clip(self.steady + (rows[-1] - self.steady) * self._decay ** (n - len(rows)), 0.0, 1.0)

    def at_time(self, t_s):
        """A/S at time ``t_s`` (s) of the waveform: its press's value at its phase."""
        x = np.asarray(t_s, dtype=float) * self.frequency_Hz
        k = np.floor(x)
        phase = x - k
        out = np.empty_like(phase)
        for n in np.unique(k):
            m = k == n
            out[m] = np.interp(phase[m], self.phase, self.press(int(n) + 1))
        return out

    def largest(self, t0_s: float, t1_s: float) -> float:
        """The largest A/S over the times [t0_s, t1_s] (s) of the waveform, at its ends and every node of the cycles
        between: the area a press in contact over that interval charged."""
        f = self.frequency_Hz
        t = [float(t0_s), float(t1_s)]
        for k in range(math.floor(t0_s * f), math.floor(t1_s * f) + 1):
            nodes = (k + self.phase) / f
            t += nodes[(nodes > t0_s) & (nodes < t1_s)].tolist()
        return float(np.max(self.at_time(np.asarray(t))))

    def at_phase(self, phase, press: int = 1):
        """A/S at ``phase`` of press ``press`` (1: the first)."""
        return np.interp(np.asarray(phase, dtype=float), self.phase, self.press(press))

    def to_dict(self) -> dict:
        d = {"kind": "cycle", "label": self.label, "frequency_Hz": self.frequency_Hz,
             "phase": self.phase.tolist(), "area_fraction": self.area_fraction.tolist(), **self.details}
        if self.later:
            d["later_presses"] = [a.tolist() for a in self.later]
        if self.steady is not None:
            d["steady_area_fraction"] = self.steady.tolist()
            d["decay"] = self._decay
        return d


QUASI_STATIC = "quasi-static A(P)"
"""The label of an area read from the pressure (an A/S(P) table or function, a constant): the ``area_model`` a
device summary states; an area that carries its own history states its ``label``."""


def area_model_label(area) -> str:
    """Which A a device used: the cycle's label ('viscoelastic cycle at 2 Hz') or :data:`QUASI_STATIC`
    ('constant A/S' for a constant fraction)."""
    if area.carries_history:
        return str(area.label)
    return "constant A/S" if isinstance(area, ConstantArea) else QUASI_STATIC


def area_model(area):
    """The charged-area model for ``area``: a number (constant fraction), an area model, or any callable
    pressure (Pa) -> A/S (wrapped in :class:`AreaFunction`)."""
    if isinstance(area, (ConstantArea, AreaTable, AreaFunction, AreaCycle)):
        return area
    if isinstance(area, (int, float)) and not isinstance(area, bool):
        return ConstantArea(area)
    if hasattr(area, "pressure_Pa") and hasattr(area, "area_fraction"):
        return AreaTable.from_table(area)
    if callable(area):
        return AreaFunction(area)
    raise TengsimError(f"area must be a fraction, an AreaTable or a callable pressure -> A/S, "
                       f"got {type(area).__name__}")


def _choice(name, value, allowed):
    require(value in allowed, f"{name} must be one of {list(allowed)}, got {value!r}")
    return value


@dataclass(frozen=True)
class DeviceParams:
    """A conductor-to-dielectric contact-separation TENG (Fig. 6), SI units.

    ``load_ohm`` = 0 is the short-circuit limit, ``math.inf`` the open circuit.
    ``damping_ratio`` zeta adds c = 2 zeta sqrt(M k_e) to Eq. (13).
    ``force_model``: "field" (default, (sigma A - Q)^2 / (2 eps0 S)), "eq20" (Eq. 20, sign
    corrected, 1/d regularised by ``eq20_reg`` d0) or "none".
    """

    mass_kg: float = _f("moving plate mass M")
    stiffness_N_per_m: float = _f("spring stiffness k_e (N/m; a unit such as '5.12kN/m' is read)",
                                  dim="energy/area")
    area_m2: float = _f("electrode area S (m2; a unit such as '4cm2' is read)", dim="area")
    thickness_m: float = _f("dielectric thickness T")
    gap_m: float = _f("rest air gap d0")
    eps_r: float = _f("relative permittivity of the dielectric")
    sigma_C_per_m2: float = _f("tribo-charge density sigma")
    load_ohm: float = _f("load R; 0 = short circuit, 'inf' = open circuit", 1.0e6)
    damping_ratio: float = _f("damping ratio zeta, c = 2 zeta sqrt(M k_e)", 0.7)
    area: ConstantArea | AreaTable | AreaFunction | AreaCycle = _f(
        "charged-area model: a fraction, or a table {pressure_Pa = [...], area_fraction = [...]}", ConstantArea)
    force_model: str = _f("electrostatic force on the plate", "field", choices=FORCE_MODELS)
    eq20_reg: float = _f("eq20 only: the 1/d term uses d + eq20_reg d0", 1.0e-3)
    area_pressure: str = _f("pressure that sets A in contact: applied P_a, or contact P_a - k_e d0/S",
                            "applied", choices=AREA_PRESSURES)
    area_memory: str = _f("charged area in flight: largest reached, or the area at release (not used by an "
                          "area that carries its own history, a viscoelastic cycle)", "max",
                          choices=AREA_MEMORIES)
    initial_charge: str = _f("Q(0): zero (paper), or rest (V = 0, no start spike)", "zero",
                             choices=INITIAL_CHARGES)
    field: str = _f("field model: parallel plates (Eqs. 14-19) or finite electrodes (boundary elements)",
                    "parallel", choices=FIELD_MODELS)
    electrode_shape: str = _f("finite field only: square (side sqrt S) or disk (diameter sqrt(4 S/pi))",
                              "square", choices=ELECTRODE_SHAPES)

    def __post_init__(self):
        for name in ("mass_kg", "stiffness_N_per_m", "area_m2", "thickness_m", "gap_m", "eps_r",
                     "sigma_C_per_m2", "eq20_reg"):
            object.__setattr__(self, name, positive(name, getattr(self, name)))
        try:
            r = float(self.load_ohm)
        except (TypeError, ValueError):
            raise TengsimError(f"load_ohm must be a number, got {self.load_ohm!r}") from None
        require(r >= 0 and r == r, f"load_ohm must be >= 0 (0 = short, inf = open), got {self.load_ohm!r}")
        object.__setattr__(self, "load_ohm", r)
        z = finite("damping_ratio", self.damping_ratio)
        require(z >= 0, f"damping_ratio must be >= 0, got {self.damping_ratio!r}")
        object.__setattr__(self, "damping_ratio", z)
        object.__setattr__(self, "area", area_model(self.area))
        _choice("force_model", self.force_model, FORCE_MODELS)
        _choice("area_pressure", self.area_pressure, AREA_PRESSURES)
        _choice("area_memory", self.area_memory, AREA_MEMORIES)
        _choice("initial_charge", self.initial_charge, INITIAL_CHARGES)
        _choice("field", self.field, FIELD_MODELS)
        _choice("electrode_shape", self.electrode_shape, ELECTRODE_SHAPES)
        require(self.field == "parallel" or self.force_model != "eq20",
                "force_model 'eq20' is the parallel plates' Eq. 20; the finite field takes 'field' or 'none'")

    # --- scales and dimensionless groups (Eq. 23) ---
    @property
    def time_scale(self) -> float:
        """sqrt(M / k_e) (s)."""
        return math.sqrt(self.mass_kg / self.stiffness_N_per_m)

    @property
    def voltage_scale(self) -> float:
        """sigma d0 / eps0 (V): V_OC of a fully charged plate at the rest gap (Eq. 17)."""
        return self.sigma_C_per_m2 * self.gap_m / EPS0

    @property
    def charge_scale(self) -> float:
        """sigma S (C)."""
        return self.sigma_C_per_m2 * self.area_m2

    @property
    def energy_scale(self) -> float:
        """k_e d0^2 (J)."""
        return self.stiffness_N_per_m * self.gap_m ** 2

    @property
    def load_mode(self) -> str:
        """"short" (R = 0), "open" (R = inf) or "finite"."""
        if self.load_ohm == 0:
            return "short"
        return "open" if math.isinf(self.load_ohm) else "finite"

    @property
    def gamma2(self) -> float:
        """d0 sqrt(M/k_e) / (eps0 S R) (Eq. 23); inf for a short, 0 for an open circuit."""
        if self.load_mode == "short":
            return math.inf
        return self.gap_m * self.time_scale / (EPS0 * self.area_m2 * self.load_ohm)

    @property
    def gamma3(self) -> float:
        """T / (eps_r d0) (Eq. 23)."""
        return self.thickness_m / (self.eps_r * self.gap_m)

    @property
    def kappa(self) -> float:
        """S sigma^2 / (eps0 d0 k_e): gamma4 of Eq. (23) with A = S."""
        return self.area_m2 * self.sigma_C_per_m2 ** 2 / (EPS0 * self.gap_m * self.stiffness_N_per_m)

    def replace(self, **changes) -> "DeviceParams":
        return dataclasses.replace(self, **changes)

    def to_dict(self) -> dict:
        d = asdict(self)
        d["area"] = self.area.to_dict()
        if math.isinf(self.load_ohm):
            d["load_ohm"] = "inf"
        return d


@dataclass(frozen=True)
class SolverOptions:
    """Integrator settings for the flight phases (scipy.integrate.solve_ivp)."""

    method: str = _f("scipy.integrate.solve_ivp method", "LSODA",
                     choices=("RK45", "DOP853", "Radau", "BDF", "LSODA"))
    rtol: float = _f("relative tolerance", 1e-8)
    atol: float = _f("absolute tolerance (dimensionless state)", 1e-10)
    max_step: float = _f("largest integrator step (s); default unlimited", math.inf, dim="time")

    def __post_init__(self):
        _choice("method", self.method, ("RK45", "DOP853", "Radau", "BDF", "LSODA"))
        for name in ("rtol", "atol", "max_step"):
            v = float(getattr(self, name))
            require(v > 0, f"{name} must be > 0, got {getattr(self, name)!r}")
            object.__setattr__(self, name, v)

    def to_dict(self) -> dict:
        d = asdict(self)
        if math.isinf(self.max_step):
            d["max_step"] = None
        return d
