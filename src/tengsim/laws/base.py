"""Surface interaction laws: pressure P(g) and energy per area Φ(g) of the gap g = H + 1 = h/ε.

Positive P is repulsive and P = −dΦ/dg.  Units: P in W/ε, Φ in W (paper Eq. 7).

Every law is made safe for any trial gap (a solver's line search may try g <= 0): below ``g_safe``
the pressure continues linearly with the slope it has there (Φ quadratic), so P and Φ stay finite and
C¹; physical equilibria never reach g_safe.  States are always judged by the residual of Eq. (9).
"""
from __future__ import annotations

import dataclasses
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


def make_law(name: str, **params) -> Law:
    """Law by registered name or alias (see ``tengsim.registry.LAWS``): 'lj93' (the paper's), 'repulsive',
    'md' (Maugis–Dugdale) or 'exp' (exponential)."""
    return LAWS.get(name)(**params)

