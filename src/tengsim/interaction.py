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
    """Base class: subclasses give the raw law for g >= g_safe via ``_raw(g) -> (Φ, P, dP/dg)``."""

    g_safe: float

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


def make_law(name: str, **params) -> Law:
    """Law by registered name or alias (see ``tengsim.registry.LAWS``): 'lj93' (the paper's) or 'repulsive'."""
    return LAWS.get(name)(**params)


LAWS.register("lj93", LJ93, aliases=("lj", "paper", "lj82"), summary="the paper's 9-3 law, Eq. (2)/(8)")
LAWS.register("repulsive", Repulsive, aliases=("hertz", "nonadhesive"), summary="non-adhesive wall")
