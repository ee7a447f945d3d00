"""The safe extension below ``g_safe``: a wrapper around any law, applied by the solvers.

A law is a pure formula (tengsim.laws.base): its ``evaluate`` is its own Φ and P at every gap.  A
solver's line search may try any gap, g <= 0 included, where a formula such as LJ93's diverges; so the
solve path evaluates ``SafeLaw(law)`` instead (as Adhesion wraps a law in a linear core): at and above
``g_safe`` the law itself, below it the pressure continued linearly with the slope it has at g_safe
(Φ quadratic), so P and Φ stay finite and C¹.  Physical equilibria never reach g_safe; a state whose
gap does is flagged out of the law's range (tengsim.status).

:func:`safe` wraps a :class:`~tengsim.laws.Law` (anything with ``_raw``), leaves a wrapper as it is, and
returns a law of one's own that is no Law (a duck-typed LawLike) unchanged: such a law answers for
its own gaps.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from tengsim import backend


def extended(raw, g, gs, at_safe, xp):
    """The safe extension's formula, once: (Φ, P) at gaps g of a law whose ``raw(g)`` gives its (Φ, P, …)
    in the array namespace ``xp``; the law's own at g >= gs, below it P continued linearly with the
    slope it has at gs and Φ its integral (quadratic).  ``at_safe``: (Φ, P, dP/dg) at gs (host floats,
    or arrays of ``xp`` when gs is traced).  Branch-free (``xp.where``)."""
    low = g < gs
    phi, p = raw(xp.where(low, gs, g))[:2]
    phs, ps, dps = at_safe
    t = g - gs
    return xp.where(low, phs - ps * t - 0.5 * dps * t * t, phi), xp.where(low, ps + dps * t, p)


@dataclass(frozen=True)
class SafeLaw:
    """``law`` at gaps >= its ``g_safe``, continued linearly in P below.

    Every other attribute (``g_safe``, the declared numbers, the fields, ``params()``) is the law's."""

    law: object

    def __post_init__(self):  # the law's g_safe, read on every sweep: kept here, not looked up through it
        object.__setattr__(self, "g_safe", self.law.g_safe)

    def __getattr__(self, name):  # the wrapped law's g_safe, declared numbers, fields, params()
        if name == "law" or name.startswith("__"):
            raise AttributeError(name)
        return getattr(self.law, name)

    @cached_property
    def _at_safe(self):
        """(Φ, P, dP/dg) at g_safe, host floats."""
        phi, p, dp = self.law._raw(np.array([self.g_safe]))
        return float(phi[0]), float(p[0]), float(dp[0])

    def _raw_np(self, g):
        return self.law._raw(g, need_dp=False)

    def evaluate(self, g):
        """(Φ, P) at gaps g: the law's above g_safe, the linear continuation below."""
        g = np.asarray(g, dtype=float)
        if not backend.to_host((g < self.g_safe).any()):  # a host decision (one sync): the sweeps avoid it
            phi, p, _ = self.law._raw(g, need_dp=False)
            return phi, p
        return extended(self._raw_np, g, self.g_safe, self._at_safe, np)

    def evaluate_xp(self, g, xp):
        """:meth:`evaluate` in the array namespace ``xp`` (jax.numpy inside the compiled solver),
        branch-free (the extension by ``xp.where``; g_safe may be a traced scalar)."""
        gs, raw = self.g_safe, self.law._raw
        return extended(lambda x: raw(x, need_dp=False, xp=xp), g, gs,
                        raw(xp.full((1,), gs, dtype=g.dtype), xp=xp), xp)

    def energy_pressure(self, g, out, work):
        """ΣΦ(g) (a backend scalar), P(g) into ``out``: the law's own hot path when no gap is below
        g_safe.  Looks at the gaps first (one host sync); a sweep avoids that with
        :meth:`energy_pressure_unchecked`."""
        m = backend.to_host(g.min())
        if m < self.g_safe or m != m:
            phi, p = self.evaluate(g)
            out[...] = p
            return phi.sum()
        return self.law.energy_pressure(g, out, work)

    def energy_pressure_unchecked(self, g, out, work):
        """(ΣΦ, min g), both backend scalars, P into ``out``: the law's own hot path without looking at
        the gaps (no host sync).  Right when min g >= g_safe (:meth:`covers`), which the caller checks
        once for the whole sweep, with its other sums; else it sweeps again with :meth:`energy_pressure`
        (rare: a trial step far into contact).  Such a pass may meet g <= 0: the caller runs it under
        ``np.errstate`` ignoring divide, overflow and invalid (tengsim.solvers.FastSolver does)."""
        return self.law.energy_pressure(g, out, work), g.min()

    def covers(self, g_min: float) -> bool:
        """Is a pass of :meth:`energy_pressure_unchecked` whose smallest gap was ``g_min`` right (no gap
        below g_safe, no NaN)?"""
        return g_min >= self.g_safe

    def pressure(self, g):
        return self.evaluate(g)[1]

    def energy(self, g):
        return self.evaluate(g)[0]

    def energy_at(self, g):
        """Φ at gaps g, the values of :meth:`energy` without its host decision (no sync: the extension
        applied by ``where`` on every gap; for a few gaps, e.g. a weighted sweep's deficit pixels)."""
        return extended(self._raw_np, g, self.g_safe, self._at_safe, np)[0]

    def stiffness(self, g):
        """−dP/dg: the law's, and below g_safe its value at g_safe (P is linear there)."""
        return self.law.stiffness(np.maximum(np.asarray(g, dtype=float), self.g_safe))


def safe(law):
    """``law`` made safe for any trial gap: a :class:`SafeLaw` around a law with ``_raw``; a SafeLaw, or a
    law of one's own without ``_raw``, as it is."""
    if isinstance(law, SafeLaw) or not hasattr(law, "_raw"):
        return law
    return SafeLaw(law)
