"""Each law's declared numbers (tengsim.laws.Law: max_tension, g_peak, g_zero, work, cohesive_range,
max_softening, g_safe) against a dense numerical evaluation of its own ``evaluate``, done here.

Every registered law (tengsim.plugins fills the registry) with its defaults and a few other
parameters.  Tolerances: REL = 1e-6 relative for tensions, works, ranges and slopes, GAP = 1e-6
absolute for gaps (all of order 1).  The reference: P on 400,001 points of [g_safe, 10] (and 20,001
geometric ones on [10, 1000]), the extremum refined on 2,001 points between its neighbours; P = 0 by
root finding; max dP/dg as the largest secant slope, refined the same way.
"""
from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq

from tengsim.laws import LJ93, Exponential, Law, MaugisDugdale, Repulsive, SafeLaw, safe
from tengsim.plugins import LAWS

REL = 1e-6
GAP = 1e-6
NUMBERS = ("max_tension", "g_peak", "g_zero", "work", "cohesive_range", "max_softening")
DECLARED = ("max_tension", "g_peak", "g_zero", "work", "max_softening")  # cohesive_range = work/σ0 in Law

OTHER_PARAMETERS = [MaugisDugdale(smoothing=0.4), MaugisDugdale(wall_stiffness=1e4),
                    MaugisDugdale(tension=2.0, smoothing=0.1, wall_stiffness=30.0),
                    Exponential(range=0.5), Exponential(range=2.0, wall_stiffness=1e4),
                    Exponential(range=0.5, wall_stiffness=50.0), LJ93(g_safe=0.9),
                    Repulsive(scale=1.0, exponent=4.0)]


class HalfLJ(Law):
    """A plugin's law (as tests/test_registry.py's half_lj) declaring nothing: the base class's search."""

    g_safe = 0.6
    calls = [0]

    def _raw(self, g, need_dp=True):
        self.calls[0] += 1
        phi, p, dp = LJ93()._raw(g, need_dp)
        return 0.5 * phi, 0.5 * p, None if dp is None else 0.5 * dp


def _laws():
    out = [pytest.param(LAWS.get(name)(), id=f"{name}-default") for name in LAWS.names()]
    out += [pytest.param(law, id=f"{type(law).__name__}-{i}") for i, law in enumerate(OTHER_PARAMETERS)]
    return out + [pytest.param(HalfLJ(), id="plugin-half_lj")]


def _P(law, g):
    return np.asarray(law.evaluate(np.asarray(g, dtype=float))[1], dtype=float)


def _refined_argmin(f, g, i):
    """Refine the sampled minimum g[i] of f on 2001 points between its neighbours (first of equals)."""
    gf = np.linspace(g[max(i - 1, 0)], g[min(i + 1, len(g) - 1)], 2001)
    v = f(gf)
    j = int(np.argmin(v))
    return float(gf[j]), float(v[j])


def dense_numbers(law) -> dict:
    """The law's numbers found numerically from ``law.evaluate`` alone (None for a law without tension)."""
    g = np.concatenate([np.linspace(law.g_safe, 10.0, 400001), np.geomspace(10.0, 1000.0, 20001)[1:]])
    p = _P(law, g)
    i = int(np.argmin(p))
    if not p[i] < 0:
        return None
    g_peak, p_min = _refined_argmin(lambda x: _P(law, x), g, i)
    j = int(np.flatnonzero(p[:i] > 0)[-1])                      # the last sign change below the peak
    g0 = brentq(lambda x: float(_P(law, [x])[0]), g[j], g[j + 1], xtol=1e-15)
    work = -float(law.evaluate(np.array([g0]))[0][0])
    sigma0 = -p_min
    h0 = work / sigma0
    gs = np.linspace(g_peak, g0 + 2.0 * h0, 400001)              # the softening window

    def minus_slope(x):                                          # −(secant slopes), at the left ends
        q = _P(law, x)
        return np.append(-np.diff(q) / np.diff(x), np.inf)

    k = int(np.argmin(minus_slope(gs)))
    _, s = _refined_argmin(minus_slope, gs, k + 1 if k + 1 < len(gs) else k)
    return {"max_tension": sigma0, "g_peak": g_peak, "g_zero": g0, "work": work, "cohesive_range": h0,
            "max_softening": max(-s, 0.0)}


@pytest.mark.parametrize("law", _laws())
def test_declared_numbers_match_dense_evaluation(law):
    ref = dense_numbers(law)
    got = {name: getattr(law, name) for name in NUMBERS}
    if ref is None:                                              # no tension: a clear "none"
        assert got == {"max_tension": 0.0, "g_peak": None, "g_zero": None, "work": 0.0,
                       "cohesive_range": None, "max_softening": 0.0}
        return
    for name in ("g_peak", "g_zero"):
        assert abs(got[name] - ref[name]) <= GAP, (name, got[name], ref[name])
    for name in ("max_tension", "work", "cohesive_range", "max_softening"):
        assert got[name] == pytest.approx(ref[name], rel=REL), name
    # the declarations are consistent with the law at the declared gaps themselves
    phi, p = law.evaluate(np.array([law.g_peak, law.g_zero]))
    assert p[0] == pytest.approx(-law.max_tension, rel=1e-12)
    assert abs(p[1]) <= 1e-9 * law.max_tension
    assert -phi[1] == pytest.approx(law.work, rel=1e-12)
    assert law.cohesive_range == pytest.approx(law.work / law.max_tension, rel=1e-15)
    assert law.g_safe < law.g_zero        # the contact gap is the physical law's, not the safe extension's


@pytest.mark.parametrize("law", _laws())
def test_safe_extension_starts_at_the_declared_g_safe(law):
    """Wrapped (SafeLaw, as the solvers evaluate a law): below g_safe, P continues linearly (C¹ at
    g_safe); above it, it is the law's own ``_raw``.  The law itself stays its formula everywhere."""
    gs, h = law.g_safe, 1e-7
    wrapped = safe(law)
    assert isinstance(wrapped, SafeLaw) and safe(wrapped) is wrapped and wrapped.law is law
    below = np.linspace(gs - 0.5, gs, 1001)
    p = _P(wrapped, below)
    scale = max(1.0, float(np.max(np.abs(p))))
    assert np.max(np.abs(np.diff(p, 2))) <= 1e-11 * scale        # linear
    up = (_P(wrapped, [gs + h])[0] - _P(wrapped, [gs])[0]) / h
    down = (_P(wrapped, [gs])[0] - _P(wrapped, [gs - h])[0]) / h
    assert up == pytest.approx(down, rel=1e-4, abs=1e-6)
    above = np.linspace(gs, gs + 0.3, 301)
    np.testing.assert_allclose(_P(wrapped, above), law._raw(above)[1], rtol=1e-15, atol=0)
    pure = np.linspace(gs - 0.3, gs, 31)                         # the law alone: no extension
    raw = _P(law, pure)
    np.testing.assert_array_equal(raw, law._raw(pure, need_dp=False)[1])
    if np.max(np.abs(np.diff(raw, 2))) > 1e-9 * np.max(np.abs(raw)):  # curved there (no linear wall):
        assert not np.allclose(raw[:-1], _P(wrapped, pure[:-1]))       # the extension differs from it
    # the wrapper is the law for everything else: its numbers, fields and parameters
    assert wrapped.params() == law.params() and wrapped.g_safe == gs
    for name in NUMBERS:
        assert getattr(wrapped, name) == getattr(law, name), name


@pytest.mark.parametrize("law", [LAWS.get(name)() for name in LAWS.names()] + OTHER_PARAMETERS,
                         ids=lambda law: type(law).__name__)
def test_builtin_laws_declare_closed_forms(law):
    """The built-in laws override every number (no numerical search: nothing is cached on the law)."""
    for name in DECLARED:
        assert getattr(type(law), name) is not getattr(Law, name), name
        getattr(law, name)
    law.cohesive_range
    assert "_numeric_window" not in vars(law) and "_numeric_softening" not in vars(law)


def test_closed_forms():
    s0 = 16 / (9 * np.sqrt(3))
    lj = LJ93()
    assert (lj.g_peak, lj.max_tension, lj.g_zero, lj.work) == pytest.approx((3 ** (1 / 6), s0, 1.0, 1.0),
                                                                           rel=1e-15)
    assert lj.cohesive_range == pytest.approx(9 * np.sqrt(3) / 16, rel=1e-15)
    g_inflection = 7.5 ** (1 / 6)                                 # d²P/dg² = 0
    assert lj.max_softening == pytest.approx(-float(lj.stiffness(np.array([g_inflection]))[0]), rel=1e-14)
    md = MaugisDugdale(smoothing=0.4, wall_stiffness=1e4)
    assert md.max_softening == pytest.approx(1.5 * md.tension / 0.4, rel=1e-15)
    assert md.max_softening == pytest.approx(-float(md.stiffness(np.array([1.0 + md.range]))[0]), rel=1e-14)
    assert (md.g_peak, md.g_zero, md.work) == pytest.approx((1.0, 1.0 - md.tension / 1e4, 1.0), rel=1e-14)
    ex = Exponential(range=0.5)
    assert ex.max_softening == pytest.approx(ex.amplitude / 0.25, rel=1e-15)
    assert (ex.g_peak, ex.max_tension, ex.work) == pytest.approx((1.0, ex.amplitude / 0.5, 1.0), rel=1e-14)
    assert Repulsive().max_tension == 0.0 and Repulsive().cohesive_range is None


def test_plugin_law_numbers_are_found_once_and_cached():
    law = HalfLJ()
    lj = LJ93()
    first = {name: getattr(law, name) for name in NUMBERS}
    for name, factor in (("max_tension", 0.5), ("work", 0.5), ("max_softening", 0.5), ("g_peak", 1.0),
                         ("g_zero", 1.0), ("cohesive_range", 1.0)):
        assert first[name] == pytest.approx(factor * getattr(lj, name), rel=1e-9), name
    n = HalfLJ.calls[0]
    assert {name: getattr(law, name) for name in NUMBERS} == first
    assert HalfLJ.calls[0] == n                                   # no second search
