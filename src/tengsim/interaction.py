"""Surface interaction laws: pressure P(g) and energy per area Φ(g) of the gap g = H + 1 = h/ε.

Positive P is repulsive and P = −dΦ/dg.  Units: P in W/ε, Φ in W (paper Eq. 7).

Every law is made safe for any trial gap (a solver's line search may try g <= 0): below ``g_safe``
the pressure continues linearly with the slope it has there (Φ quadratic), so P and Φ stay finite and
C¹; physical equilibria never reach g_safe.  States are always judged by the residual of Eq. (9).
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from tengsim.errors import TengsimError, positive
from tengsim.registry import LAWS


class Law:
    """Base class: subclasses give the raw law for g >= g_safe via ``_raw(g) -> (Φ, P, dP/dg)``.

    A law's fields (its dataclass fields, or constructor arguments) are ``[contact]`` keys of a run
    with that law (:func:`tengsim.config.law_fields`), except the numerical guards named in
    ``internal_fields``; ``field_help`` gives a key its help text (with its unit: W and ε).
    """

    g_safe: float
    internal_fields = ("g_safe",)
    field_help = {}

    def _raw(self, g, need_dp=True):  # pragma: no cover - abstract
        raise NotImplementedError

    @cached_property
    def _safe(self):
        gs = np.array([self.g_safe])
        phi, p, dp = self._raw(gs)
        return float(phi[0]), float(p[0]), float(dp[0])

    def evaluate(self, g: np.ndarray):
        """Return (Φ, P) at gaps g (arrays of g's shape)."""
        g = np.asarray(g, dtype=float)
        low = g < self.g_safe
        if not low.any():
            phi, p, _ = self._raw(g, need_dp=False)
            return phi, p
        gg = np.where(low, self.g_safe, g)
        phi, p, _ = self._raw(gg, need_dp=False)
        phs, ps, dps = self._safe
        t = g - self.g_safe
        p = np.where(low, ps + dps * t, p)
        phi = np.where(low, phs - ps * t - 0.5 * dps * t * t, phi)
        return phi, p

    def energy_pressure(self, g: np.ndarray, out: np.ndarray, work) -> float:
        """ΣΦ(g), writing P(g) into ``out``: the solvers' hot path (``work``: two scratch arrays)."""
        phi, p = self.evaluate(g)
        out[...] = p
        return float(phi.sum())

    def pressure(self, g):
        return self.evaluate(g)[1]

    def energy(self, g):
        return self.evaluate(g)[0]

    def stiffness(self, g):
        """−dP/dg = Φ''(g), the local interaction stiffness."""
        g = np.asarray(g, dtype=float)
        gg = np.maximum(g, self.g_safe)
        return -self._raw(gg)[2]

    def params(self) -> dict:
        """The law's parameters (its dataclass fields; public attributes otherwise) and its class name."""
        if dataclasses.is_dataclass(self):
            d = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        else:
            d = {k: v for k, v in vars(self).items() if not k.startswith("_")}
        d["law"] = type(self).__name__
        return d


@dataclass(frozen=True)
class LJ93(Law):
    """The paper's law, Eq. (2)/(8): P = (8/3)[g⁻⁹ − g⁻³], Φ = (1/3)g⁻⁸ − (4/3)g⁻².

    A 9-3 law in pressure (8-2 in energy, Derjaguin): Φ(1) = −1 (the work of adhesion W),
    P(1) = 0, tensile peak P_min = −16/(9√3) ≈ −1.026 at g = 3^{1/6}.
    """

    g_safe: float = 0.6

    def __post_init__(self):
        if not 0 < self.g_safe < 1:
            raise TengsimError(f"g_safe must lie in (0, 1), got {self.g_safe!r}")

    def _raw(self, g, need_dp=True):
        inv = 1.0 / g
        i2 = inv * inv
        i3 = i2 * inv
        i8 = i2 * i2
        i8 *= i8
        i9 = i8 * inv
        phi = i8 / 3.0 - (4.0 / 3.0) * i2
        p = (8.0 / 3.0) * (i9 - i3)
        dp = (8.0 / 3.0) * (-9.0 * i9 + 3.0 * i3) * inv if need_dp else None
        return phi, p, dp

    def energy_pressure(self, g, out, work):
        """In place, no temporaries (same values as ``evaluate``); falls back below g_safe."""
        if float(g.min()) < self.g_safe:
            return super().energy_pressure(g, out, work)
        a, b = work
        np.reciprocal(g, out=a)      # g⁻¹
        np.multiply(a, a, out=b)     # g⁻²
        s2 = float(b.sum())
        np.multiply(b, b, out=out)   # g⁻⁴
        out *= out                   # g⁻⁸
        s8 = float(out.sum())
        out *= a                     # g⁻⁹
        b *= a                       # g⁻³
        out -= b
        out *= 8.0 / 3.0
        return s8 / 3.0 - (4.0 / 3.0) * s2


@dataclass(frozen=True)
class Repulsive(Law):
    """Non-adhesive wall: P = c g^{−k}, Φ = c g^{1−k}/(k − 1) (k > 1); for Hertz-type checks.

    With c = 8/3, k = 9 it is the repulsive half of the paper's law; the wall sits near g ≈ 1.
    """

    scale: float = 8.0 / 3.0
    exponent: float = 9.0
    g_safe: float = 0.6
    field_help = {"scale": "prefactor c of the wall P = c g^-k, in W/ε",
                  "exponent": "power k > 1 of the wall P = c g^-k (pure number)"}

    def __post_init__(self):
        positive("scale", self.scale)
        if not self.exponent > 1:
            raise TengsimError(f"exponent must be > 1, got {self.exponent!r}")
        if not 0 < self.g_safe < 1:
            raise TengsimError(f"g_safe must lie in (0, 1), got {self.g_safe!r}")

    def _raw(self, g, need_dp=True):
        k, c = self.exponent, self.scale
        gk = g ** (-k)
        p = c * gk
        phi = c * gk * g / (k - 1)
        dp = -k * p / g
        return phi, p, dp


#: Peak tension of the LJ93 law, 16/(9√3) W/ε (at g = 3^{1/6}): the default stress of the other laws,
#: so that the Tabor parameter μ means the same for every built-in law.
LJ_PEAK_TENSION = 16.0 / (9.0 * 3.0**0.5)


def _check_common(law):
    positive("wall_stiffness", law.wall_stiffness)
    if not 0 < law.g_safe < 1:
        raise TengsimError(f"g_safe must lie in (0, 1), got {law.g_safe!r}")


def _wall(g, sigma, k, phi1):
    """Linear wall for g < 1: P = −σ + k(1 − g), Φ = Φ(1) − σ(1 − g) + k(1 − g)²/2, dP/dg = −k.

    Continuous with a tension σ at g = 1; zero load at g = 1 − σ/k, where Φ = Φ(1) − σ²/(2k).
    """
    t = 1.0 - g
    return phi1 - sigma * t + 0.5 * k * t * t, -sigma + k * t, np.full_like(g, -k)


@dataclass(frozen=True)
class MaugisDugdale(Law):
    """Dugdale law (Maugis 1992): constant tension σ0 = ``tension`` over 1 < g < 1 + h0, a wall below.

    Wall (g < 1): P = −σ0 + k(1 − g), k = ``wall_stiffness`` (W/ε²), so the contact zone g <= 1 carries
    any pressure down to −σ0, as in Maugis' model, and is rigid as k → ∞ (its compliance σ0/k ε).
    Beyond the range the law is zero.  The range is h0 = 1/σ0 − σ0/(2k) (ε), so that the work of
    adhesion, −Φ at the zero-load gap 1 − σ0/k, is exactly 1 (= W); h0 → W/σ0 as k → ∞.  With the
    default σ0 = 16/(9√3), the LJ93 peak tension, Maugis' λ = 2σ0 (R/(πWK²))^{1/3} = 1.157 μ
    (Greenwood 1997), so ``tabor`` means the same as for LJ93.  The step at g = 1 + h0 is a smoothstep
    ramp 3t² − 2t³ of width ``smoothing`` centred on it (area, hence W, unchanged), so P and dP/dg are
    continuous for the solvers.  Φ is in W, P in W/ε.
    """

    tension: float = LJ_PEAK_TENSION
    wall_stiffness: float = 1000.0
    smoothing: float = 0.2
    g_safe: float = 0.6
    field_help = {"tension": "Dugdale tension σ0, in W/ε (default: the LJ93 peak 16/(9√3))",
                  "wall_stiffness": "stiffness k of the wall g < 1, in W/ε²",
                  "smoothing": "width of the smoothstep ramp at the range's end g = 1 + h0, in ε"}

    def __post_init__(self):
        positive("tension", self.tension)
        _check_common(self)
        if not self.smoothing > 0:
            raise TengsimError(f"smoothing must be > 0, got {self.smoothing!r}")
        if not self.range > 0:
            raise TengsimError(f"wall_stiffness={self.wall_stiffness!r} is too small for tension={self.tension!r}: "
                               "the range h0 = 1/σ0 − σ0/(2k) must be > 0")
        if not self.smoothing < self.range:
            raise TengsimError(f"smoothing must be smaller than the range h0 = {self.range:.4g}, "
                               f"got {self.smoothing!r}")

    @property
    def range(self) -> float:
        """h0 = 1/σ0 − σ0/(2k) in ε (W = σ0 h0 + σ0²/(2k) = 1)."""
        return 1.0 / self.tension - self.tension / (2.0 * self.wall_stiffness)

    def _raw(self, g, need_dp=True):
        s0, k, s = self.tension, self.wall_stiffness, self.smoothing
        h0 = self.range
        ge = 1.0 + h0                                    # the range's end, centre of the ramp
        hi = ge + 0.5 * s
        phi_w, p_w, dp_w = _wall(g, s0, k, -s0 * h0)
        t = np.clip((hi - g) / s, 0.0, 1.0)              # 1 inside the zone, 0 beyond
        phi_z = np.where(g > ge - 0.5 * s, -s0 * s * (t**3 - 0.5 * t**4), -s0 * (ge - g))
        p_z = -s0 * t * t * (3.0 - 2.0 * t)               # smoothstep: P and dP/dg continuous
        dp_z = 6.0 * s0 / s * t * (1.0 - t)
        wall = g < 1.0
        phi = np.where(wall, phi_w, phi_z)
        p = np.where(wall, p_w, p_z)
        dp = np.where(wall, dp_w, dp_z) if need_dp else None
        return phi, p, dp


@dataclass(frozen=True)
class Exponential(Law):
    """Exponential attraction with a wall (the contact-mechanics challenge's kind, Müser et al. 2017).

    g >= 1: Φ = −A exp(−(g − 1)/ρ), P = −(A/ρ) exp(−(g − 1)/ρ), range ρ = ``range`` (ε); peak
    tension A/ρ at g = 1.  Wall (g < 1): P = −A/ρ + k(1 − g), k = ``wall_stiffness`` (W/ε²), as in
    :class:`MaugisDugdale`.  A = 2/(1 + sqrt(1 + 2/(kρ²))) makes the work of adhesion exactly 1 (= W).
    The default ρ = 1/σ − σ/(2k) with σ = 16/(9√3) gives the LJ93 peak tension, so ``tabor``
    means the same as for LJ93.  Φ in W, P in W/ε.
    """

    range: float = 1.0 / LJ_PEAK_TENSION - LJ_PEAK_TENSION / 2000.0
    wall_stiffness: float = 1000.0
    g_safe: float = 0.6
    field_help = {"range": "decay length ρ of the attraction, in ε (default: peak tension A/ρ = LJ93's)",
                  "wall_stiffness": "stiffness k of the wall g < 1, in W/ε²"}

    def __post_init__(self):
        positive("range", self.range)
        _check_common(self)

    @property
    def amplitude(self) -> float:
        """The depth A = −Φ(1) of the attraction, in units of W, from A + (A/ρ)²/(2k) = 1."""
        return 2.0 / (1.0 + np.sqrt(1.0 + 2.0 / (self.wall_stiffness * self.range**2)))

    @property
    def tension(self) -> float:
        """Peak tension A/ρ (W/ε), at g = 1."""
        return self.amplitude / self.range

    def _raw(self, g, need_dp=True):
        A, rho, k = self.amplitude, self.range, self.wall_stiffness
        e = np.exp(-np.maximum(g - 1.0, 0.0) / rho)
        phi_w, p_w, dp_w = _wall(g, A / rho, k, -A)
        wall = g < 1.0
        phi = np.where(wall, phi_w, -A * e)
        p = np.where(wall, p_w, -(A / rho) * e)
        dp = np.where(wall, dp_w, (A / rho**2) * e) if need_dp else None
        return phi, p, dp


def make_law(name: str, **params) -> Law:
    """Law by registered name or alias (see ``tengsim.registry.LAWS``): 'lj93' (the paper's), 'repulsive',
    'md' (Maugis–Dugdale) or 'exp' (exponential)."""
    return LAWS.get(name)(**params)


LAWS.register("lj93", LJ93, aliases=("lj", "paper", "lj82"), summary="the paper's 9-3 law, Eq. (2)/(8)")
LAWS.register("repulsive", Repulsive, aliases=("hertz", "nonadhesive"), summary="non-adhesive wall")
LAWS.register("md", MaugisDugdale, aliases=("maugis_dugdale", "dugdale"),
              summary="Maugis–Dugdale: constant tension over a range, stiff wall")
LAWS.register("exp", Exponential, aliases=("exponential",), summary="exponential attraction, stiff wall")
