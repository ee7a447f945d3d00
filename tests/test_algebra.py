"""The fast solver's shared algebra (tengsim.solvers._algebra): the compact L-BFGS form against the classical
two-loop recursion, the new pair's row against its definition, the line search's bracketing against its
rules, and the same numbers from every namespace (NumPy arrays, host floats, jax.numpy)."""
import numpy as np
import pytest

from tengsim import backend
from tengsim.solvers import _algebra
from tengsim.solvers._algebra import HOST
from tengsim.solvers._constants import C1, C2, GROW, SAFEGUARD


def _pairs(rng, m, n):
    """m pairs (s_i, y_i = A s_i), A symmetric positive definite (so <s_i, y_i> > 0), oldest first."""
    Q = rng.standard_normal((n, n))
    A = Q @ Q.T / n + np.eye(n)
    S = rng.standard_normal((m, n))
    return S, S @ A


def _two_loop(S, Y, G):
    """H G by the classical two-loop recursion (Nocedal 1980), γ = <s, y>/<y, y> of the newest pair."""
    rho = 1.0 / np.einsum("ij,ij->i", S, Y)
    q = G.copy()
    a = np.zeros(len(S))
    for i in reversed(range(len(S))):
        a[i] = rho[i] * (S[i] @ q)
        q -= a[i] * Y[i]
    r = (S[-1] @ Y[-1]) / (Y[-1] @ Y[-1]) * q
    for i in range(len(S)):
        b = rho[i] * (Y[i] @ r)
        r += S[i] * (a[i] - b)
    return r


def _compact(xp, solve_upper, S, Y, G):
    SY, YY = S @ Y.T, Y @ Y.T
    gamma = _algebra.newest_gamma(xp, SY[-1, -1], YY[-1, -1])
    cS, cY = _algebra.compact_coefficients(xp, solve_upper, xp.asarray(SY), xp.asarray(YY), xp.asarray(S @ G),
                                           xp.asarray(Y @ G), gamma)
    return gamma, cS, cY


@pytest.mark.parametrize("m", [1, 2, 5, 10])
def test_compact_form_is_the_two_loop_recursion(m):
    rng = np.random.default_rng(m)
    S, Y = _pairs(rng, m, 40)
    G = rng.standard_normal(40)
    gamma, cS, cY = _compact(np, backend.solve_upper, S, Y, G)
    HG = gamma * G + cS @ S + cY @ Y
    ref = _two_loop(S, Y, G)
    assert np.max(np.abs(HG - ref)) <= 1e-12 * np.max(np.abs(ref))


def test_compact_solve_reads_only_the_upper_triangle():
    rng = np.random.default_rng(7)
    S, Y = _pairs(rng, 4, 12)
    G = rng.standard_normal(12)
    SY, YY = S @ Y.T, Y @ Y.T
    junk = SY + np.tril(rng.standard_normal((4, 4)), -1) * 1e3
    gamma = _algebra.newest_gamma(np, SY[-1, -1], YY[-1, -1])
    a = _algebra.compact_coefficients(np, backend.solve_upper, SY, YY, S @ G, Y @ G, gamma)
    b = _algebra.compact_coefficients(np, backend.solve_upper, junk, YY, S @ G, Y @ G, gamma)
    assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1])


def test_newest_gamma_without_curvature_is_one():
    assert _algebra.newest_gamma(np, 2.0, 4.0) == 0.5
    assert _algebra.newest_gamma(np, 2.0, 0.0) == 1.0
    assert _algebra.newest_gamma(np, -1.0, -3.0) == 1.0


def test_new_pair_row_is_d_dot_y():
    rng = np.random.default_rng(3)
    S, Y = _pairs(rng, 6, 30)
    G = rng.standard_normal(30)
    gamma, cS, cY = _compact(np, backend.solve_upper, S, Y, G)
    d = -(gamma * G + cS @ S + cY @ Y)
    row = _algebra.new_pair_row(gamma, cS, cY, S @ Y.T, Y @ Y.T, Y @ G)
    assert np.allclose(row, Y @ d, rtol=0, atol=1e-12 * np.max(np.abs(Y @ d)))


def test_curvature_test():
    assert _algebra.stores_pair(HOST, 1.0, 1.0, 1.0)
    assert not _algebra.stores_pair(HOST, 1e-15, 1.0, 1.0)     # <s, y> below CURVATURE_EPS |<s, K s>|
    assert not _algebra.stores_pair(HOST, 1.0, 0.0, 1.0)       # <y, y> = 0
    assert _algebra.stores_pair(HOST, 1e-310, 1.0, 0.0)        # sks = 0: any positive <s, y>
    assert not _algebra.stores_pair(HOST, 0.0, 1.0, 0.0)


def test_next_trial_grows_until_bracketed():
    assert _algebra.next_trial(HOST, 0.5, 0.5, -1.0, 0.0, 0.0, False, False) == GROW * 0.5


def test_next_trial_secant_finds_a_linear_slopes_zero():
    # E'(α) = α − 0.35 on the bracket [0.2, 1]: the secant step is its zero (inside the safeguards)
    lo, hi = 0.2, 1.0
    a = _algebra.next_trial(HOST, hi, lo, lo - 0.35, hi, hi - 0.35, True, True)
    assert a == pytest.approx(0.35, rel=1e-14)


@pytest.mark.parametrize("has_de_hi, de_hi", [(False, 3.0), (True, -2.0)])
def test_next_trial_bisects_without_a_usable_slope(has_de_hi, de_hi):
    # hi's slope unusable, or not above lo's: bisection
    assert _algebra.next_trial(HOST, 1.0, 0.2, -1.0, 1.0, de_hi, True, has_de_hi) == pytest.approx(0.6)


def test_next_trial_keeps_inside_the_safeguards():
    lo, hi = 0.0, 1.0
    near_lo = _algebra.next_trial(HOST, hi, lo, -1e-9, hi, 1.0, True, True)      # the secant's zero near lo
    near_hi = _algebra.next_trial(HOST, hi, lo, -1.0, hi, 1e-9, True, True)      # ... near hi
    assert near_lo == pytest.approx(lo + SAFEGUARD * (hi - lo))
    assert near_hi == pytest.approx(hi - SAFEGUARD * (hi - lo))


def test_accepts_wolfe_and_approximate():
    E0, slope0, eps_E = 1.0, -1.0, 1e-11
    assert _algebra.accepts(0.5, -0.1, 1.0, E0, E0, slope0, eps_E, C1, C2)          # strong Wolfe
    assert not _algebra.accepts(0.5, -0.95, 1.0, E0, E0, slope0, eps_E, C1, C2)     # slope still steep
    assert not _algebra.accepts(E0 + 1e-3, -0.1, 1.0, E0, E0, slope0, eps_E, C1, C2)    # no decrease
    # approximate Wolfe: E at the reference within the slack, 0.9 E'(0) <= E' <= −0.8 E'(0)
    assert _algebra.accepts(E0 + 0.5 * eps_E, 0.5, 1e-3, E0, E0, slope0, eps_E, C1, C2)
    assert not _algebra.accepts(E0 + 2 * eps_E, 0.5, 1e-3, E0, E0, slope0, eps_E, C1, C2)


def _scalar_cases(rng, n=200):
    """Random line-search states (a, lo, de_lo, hi, de_hi, has_hi, has_de_hi) and trials (e, de)."""
    for _ in range(n):
        lo = rng.uniform(0, 1)
        hi = lo + rng.uniform(1e-3, 2)
        yield (float(rng.uniform(lo, hi)), lo, -float(rng.uniform(0, 2)), hi, float(rng.uniform(-2, 2)),
               bool(rng.integers(2)), bool(rng.integers(2)), float(rng.uniform(0.5, 1.5)), float(rng.uniform(-2, 2)))


def test_host_floats_equal_numpy_arrays():
    rng = np.random.default_rng(11)
    for a, lo, de_lo, hi, de_hi, has_hi, has_de_hi, e, de in _scalar_cases(rng):
        x = _algebra.next_trial(HOST, a, lo, de_lo, hi, de_hi, has_hi, has_de_hi)
        y = _algebra.next_trial(np, np.float64(a), np.float64(lo), np.float64(de_lo), np.float64(hi),
                                np.float64(de_hi), np.bool_(has_hi), np.bool_(has_de_hi))
        assert x == float(y)
        args = (e, de, a, 1.0, 0.9, -1.0, 1e-11)
        assert bool(_algebra.accepts(*args, C1, C2)) == bool(_algebra.accepts(*map(np.float64, args), C1, C2))


def test_jax_numpy_equals_numpy():
    jnp = pytest.importorskip("jax.numpy")
    import jax
    jax.config.update("jax_enable_x64", True)
    from tengsim.solvers._jax_loop import solve_upper
    rng = np.random.default_rng(5)
    for m in (1, 3, 10):
        S, Y = _pairs(rng, m, 25)
        G = rng.standard_normal(25)
        g1, s1, y1 = _compact(np, backend.solve_upper, S, Y, G)
        g2, s2, y2 = _compact(jnp, solve_upper, S, Y, G)
        assert float(g2) == float(g1)
        for p, q in ((s1, s2), (y1, y2)):
            assert np.allclose(np.asarray(q), p, rtol=1e-12, atol=1e-12 * np.max(np.abs(p)))
    for a, lo, de_lo, hi, de_hi, has_hi, has_de_hi, e, de in _scalar_cases(rng, 50):
        x = _algebra.next_trial(HOST, a, lo, de_lo, hi, de_hi, has_hi, has_de_hi)
        y = _algebra.next_trial(jnp, jnp.float64(a), lo, de_lo, hi, de_hi, jnp.bool_(has_hi), jnp.bool_(has_de_hi))
        assert x == float(y)
        for f, args in ((_algebra.accepts, (e, de, a, 1.0, 0.9, -1.0, 1e-11, C1, C2)),
                        (_algebra.overshoots, (e, de, a, 1.0, -1.0, 1e-11, C1)),
                        (_algebra.slope_usable, (e, de, 1.0, 1e-11))):
            assert bool(f(*args)) == bool(f(*(jnp.float64(v) for v in args)))
