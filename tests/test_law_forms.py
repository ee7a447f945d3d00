"""Each law's formula is written once (tengsim.laws.lj93's ``powers``/``energy``/``pressure``/``slope``, the
safe extension's tengsim.laws.safe.extended); the other forms the solvers call are checked against it here:
the NumPy solver's in-place hot path (``LJ93.energy_pressure``), the summed form the JAX solver uses
(``energy_sum_xp``), the safe wrapper's three entries (``evaluate``, ``evaluate_xp``, ``energy_at``), and
the array-namespace form traced with jax.numpy against NumPy's.
"""
from __future__ import annotations

import numpy as np
import pytest

from tengsim.laws import LJ93, Exponential, MaugisDugdale, Repulsive, SafeLaw
from tengsim.laws import lj93 as lj93_formula

LAWS = [LJ93(), LJ93(g_safe=0.8), MaugisDugdale(), Exponential(range=0.5, wall_stiffness=50.0), Repulsive()]


def _gaps(seed=0, n=4001):
    """Gaps from deep below g_safe (the line search's trials, g <= 0 excluded for the 1/g laws) to far out."""
    rng = np.random.default_rng(seed)
    return np.concatenate([np.linspace(0.05, 6.0, n), rng.uniform(0.3, 2.0, 999)])


def test_lj93_in_place_path_equals_formula():
    g = _gaps()[None, :].repeat(3, axis=0)          # 2-D, as the solvers' fields are
    law = LJ93()
    out, work = np.empty_like(g), (np.empty_like(g), np.empty_like(g))
    s = law.energy_pressure(g, out, work)
    inv, i2, i8 = lj93_formula.powers(g)
    assert np.array_equal(out, lj93_formula.pressure(inv, i2, i8))            # bit for bit
    assert s == lj93_formula.energy(i8.sum(), i2.sum())                      # the same sums, the same order
    phi, p, _ = law._raw(g)
    assert np.array_equal(out, p)
    assert s == pytest.approx(phi.sum(), rel=1e-12)                           # Σ of Φ: rounding only


def test_lj93_summed_form_equals_formula():
    g = _gaps(1)
    law = LJ93()
    s, p = law.energy_sum_xp(g, np, np.sum)
    phi, p_raw, dp = law._raw(g)
    assert np.array_equal(p, p_raw)
    assert s == pytest.approx(phi.sum(), rel=1e-12)
    assert law._raw(g, need_dp=False)[2] is None
    h = 1e-6                                                                    # dP/dg is P's derivative
    fd = (law._raw(g + h)[1] - law._raw(g - h)[1]) / (2 * h)
    assert np.allclose(dp, fd, rtol=1e-6, atol=1e-6 * np.abs(dp).max())


@pytest.mark.parametrize("law", LAWS, ids=lambda law: type(law).__name__ + f"(g_safe={law.g_safe})")
def test_safe_extension_forms_agree(law):
    g = _gaps(2)
    s = SafeLaw(law)
    phi, p = s.evaluate(g)
    phi_xp, p_xp = s.evaluate_xp(g, np)
    assert np.array_equal(phi, phi_xp) and np.array_equal(p, p_xp)
    assert np.array_equal(s.energy_at(g), phi)
    above = g >= law.g_safe                                                     # the law itself above g_safe
    phi_l, p_l = law.evaluate(g[above])
    assert np.array_equal(phi[above], phi_l) and np.array_equal(p[above], p_l)
    gs = law.g_safe                                                             # below: P linear, Φ its integral
    phs, ps, dps = s._at_safe
    t = g[~above] - gs
    assert np.allclose(p[~above], ps + dps * t, rtol=1e-14, atol=1e-12)
    assert np.allclose(phi[~above], phs - ps * t - 0.5 * dps * t * t, rtol=1e-14, atol=1e-12)
    lo, hi = s.evaluate(np.array([gs - 1e-9, gs + 1e-9]))                      # continuous at g_safe
    assert abs(hi[1] - hi[0]) < 1e-5 * (1 + abs(hi[0])) and abs(lo[1] - lo[0]) < 1e-5 * (1 + abs(lo[0]))


@pytest.mark.parametrize("law", LAWS, ids=lambda law: type(law).__name__ + f"(g_safe={law.g_safe})")
def test_safe_hot_path_equals_evaluate(law):
    """SafeLaw.energy_pressure (the law's in-place path above g_safe, evaluate below) against evaluate."""
    s = SafeLaw(law)
    for g in (np.linspace(law.g_safe, 5.0, 2001), _gaps(3)):
        out, work = np.empty_like(g), (np.empty_like(g), np.empty_like(g))
        e = s.energy_pressure(g, out, work)
        phi, p = s.evaluate(g)
        assert np.array_equal(out, p)
        assert e == pytest.approx(phi.sum(), rel=1e-12, abs=1e-12)


@pytest.mark.parametrize("law", LAWS, ids=lambda law: type(law).__name__ + f"(g_safe={law.g_safe})")
def test_jax_namespace_form_equals_numpy(law):
    jax = pytest.importorskip("jax")
    jax.config.update("jax_enable_x64", True)
    import jax.numpy as jnp

    g = _gaps(4)
    s = SafeLaw(law)
    phi, p = s.evaluate(g)
    phi_j, p_j = s.evaluate_xp(jnp.asarray(g), jnp)
    assert np.allclose(np.asarray(phi_j), phi, rtol=1e-14, atol=1e-14)
    assert np.allclose(np.asarray(p_j), p, rtol=1e-14, atol=1e-14)
    if isinstance(law, LJ93):
        ga = g[g >= law.g_safe]
        sj, pj = law.energy_sum_xp(jnp.asarray(ga), jnp, jnp.sum)
        sn, pn = law.energy_sum_xp(ga, np, np.sum)
        assert float(sj) == pytest.approx(float(sn), rel=1e-13)
        assert np.allclose(np.asarray(pj), pn, rtol=1e-14, atol=0)
