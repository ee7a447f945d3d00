"""Checks of tengsim.references against limits, identities and quadrature."""
import numpy as np
import pytest
from scipy import integrate
from scipy.optimize import brentq

from tengsim import references as ref
from tengsim.errors import TengsimError

R, E, W = 2.0e-3, 1.5e6, 0.05   # m, Pa, J/m^2


def _axisym_force(p, a):
    """2 pi int_0^a r p(r) dr by adaptive quadrature."""
    val, _ = integrate.quad(lambda r: 2 * np.pi * r * p(r), 0.0, a, limit=200, epsabs=0, epsrel=1e-10)
    return val


# --- moduli / Hertz -----------------------------------------------------------

def test_effective_modulus():
    assert ref.effective_modulus(1.0, 0.5) == pytest.approx(1.0 / 0.75)
    assert ref.effective_modulus(2.0, 0.0, 2.0, 0.0) == pytest.approx(1.0)
    with pytest.raises(TengsimError):
        ref.effective_modulus(1.0, 1.0)


def test_hertz_inverse_and_pressure_integrates_to_force():
    d = np.array([1e-7, 3e-6, 4e-5])
    F = ref.hertz_force(d, R, E)
    np.testing.assert_allclose(ref.hertz_indentation(F, R, E), d, rtol=1e-12)
    a = ref.hertz_contact_radius(d, R)
    np.testing.assert_allclose(ref.hertz_contact_radius_from_force(F, R, E), a, rtol=1e-12)
    for ai, Fi in zip(a, F):
        assert _axisym_force(lambda r: ref.hertz_pressure(r, ai, R, E), ai) == pytest.approx(Fi, rel=1e-8)
        assert ref.hertz_peak_pressure(ai, R, E) == pytest.approx(3 * Fi / (2 * np.pi * ai ** 2), rel=1e-12)
    assert ref.hertz_pressure(2 * a[0], a[0], R, E) == 0.0


# --- JKR / DMT ----------------------------------------------------------------

def test_jkr_without_adhesion_is_hertz():
    a = np.linspace(1e-6, 1e-4, 7)
    d = ref.hertz_indentation(ref.jkr_force(a, R, E, 0.0), R, E)
    np.testing.assert_allclose(ref.jkr_force(a, R, E, 0.0), ref.hertz_force(a ** 2 / R, R, E), rtol=1e-12)
    np.testing.assert_allclose(ref.jkr_indentation(a, R, E, 0.0), d, rtol=1e-10)
    F = ref.hertz_force(a ** 2 / R, R, E)
    np.testing.assert_allclose(ref.jkr_contact_radius(F, R, E, 0.0), a, rtol=1e-10)
    # and the small-W limit converges to Hertz
    np.testing.assert_allclose(ref.jkr_force(a, R, E, 1e-20), F, rtol=1e-6)  # converges ~ sqrt(W)


def test_jkr_pulloff_zero_load_and_inverse():
    a = np.linspace(1e-7, 5e-4, 200001)
    F = ref.jkr_force(a, R, E, W)
    po = ref.jkr_pulloff(R, E, W)
    assert po.force == pytest.approx(F.min(), rel=1e-8)
    assert po.force == pytest.approx(-1.5 * np.pi * W * R, rel=1e-12)
    assert po.contact_radius == pytest.approx(a[np.argmin(F)], rel=1e-4)
    a0 = ref.jkr_zero_load_radius(R, E, W)
    assert abs(ref.jkr_force(a0, R, E, W)) < 1e-12 * np.pi * W * R
    assert a0 == pytest.approx(4 ** (1 / 3) * po.contact_radius, rel=1e-12)
    fg = ref.jkr_pulloff_fixed_grips(R, E, W)
    dlt = ref.jkr_indentation(a, R, E, W)
    assert fg.indentation == pytest.approx(dlt.min(), rel=1e-8)
    assert fg.force == pytest.approx(-5 / 6 * np.pi * W * R, rel=1e-12)
    Fs = np.array([po.force * 0.999, -0.3 * np.pi * W * R, 0.0, 1e-3])
    for br in ("stable", "unstable"):
        aa = ref.jkr_contact_radius(Fs[:3], R, E, W, branch=br)
        np.testing.assert_allclose(ref.jkr_force(aa, R, E, W), Fs[:3], atol=1e-12 * np.pi * W * R)
    aa = ref.jkr_contact_radius(Fs, R, E, W)
    assert np.all(aa > po.contact_radius)
    assert np.isnan(ref.jkr_contact_radius(1.01 * po.force, R, E, W))


def test_dmt():
    assert ref.dmt_force(0.0, R, E, W) == pytest.approx(ref.dmt_pulloff_force(R, W))
    assert ref.dmt_pulloff_force(R, W) == pytest.approx(-2 * np.pi * R * W)
    d = 2e-6
    F = ref.dmt_force(d, R, E, W)
    assert F == pytest.approx(ref.hertz_force(d, R, E) - 2 * np.pi * R * W)
    assert ref.dmt_contact_radius(F, R, E, W) == pytest.approx(np.sqrt(R * d), rel=1e-12)


# --- Maugis-Dugdale -------------------------------------------------------------

def test_md_pulloff_limits_and_monotonic():
    assert ref.maugis_dugdale_pulloff(0.01) == pytest.approx(2.0, rel=2e-3)
    assert ref.maugis_dugdale_pulloff(0.05) == pytest.approx(2.0, rel=1.5e-2)
    assert ref.maugis_dugdale_pulloff(20.0) == pytest.approx(1.5, rel=2e-3)
    assert ref.maugis_dugdale_pulloff(1000.0) == pytest.approx(1.5, rel=1e-6)
    lams = [0.05, 0.1, 0.3, 0.5, 1.0, 2.0, 3.5, 10.0]
    vals = [ref.maugis_dugdale_pulloff(x) for x in lams]
    assert np.all(np.diff(vals) < 0)
    assert 1.55 < ref.maugis_dugdale_pulloff(1.0) < 1.65
    # JKR pull-off contact radius A^3 = 3/2 in the large-lambda limit
    assert ref.maugis_dugdale_pulloff_point(1000.0).A == pytest.approx(1.5 ** (1 / 3), rel=1e-4)


def test_md_pulloff_is_curve_minimum():
    for lam in (0.3, 1.0, 3.0):
        c = ref.maugis_dugdale_curve(lam, A_max=3.0, n=3000)
        pt = ref.maugis_dugdale_pulloff_point(lam)
        assert -pt.P >= -c.P.min() - 1e-12
        assert -pt.P == pytest.approx(-c.P.min(), rel=1e-5)


def test_md_curve_solves_maugis_equations_independently():
    lam = 0.8
    c = ref.maugis_dugdale_curve(lam, A_max=2.5, n=25, A_min=0.05)

    def eq3(m, A):
        s = np.sqrt(m * m - 1)
        t = np.arctan(s)
        return (lam * A * A / 2 * (s + (m * m - 2) * t)
                + 4 * lam ** 2 * A / 3 * (s * t - m + 1) - 1)

    for A, P, D, m in zip(c.A, c.P, c.D, c.m):
        m_ref = brentq(eq3, 1 + 1e-14, 1e6, args=(A,), xtol=1e-15, rtol=1e-14)
        s = np.sqrt(m_ref ** 2 - 1)
        assert m == pytest.approx(m_ref, rel=1e-9)
        assert P == pytest.approx(A ** 3 - lam * A ** 2 * (s + m_ref ** 2 * np.arctan(s)), rel=1e-7, abs=1e-9)
        assert D == pytest.approx(A ** 2 - 4 / 3 * A * lam * s, rel=1e-7, abs=1e-9)
    np.testing.assert_allclose(ref.maugis_dugdale_m(lam, c.A), c.m, rtol=1e-12)


def test_md_curve_limits_jkr_and_dmt():
    c = ref.maugis_dugdale_curve(1e4, A_max=3.0, n=50, A_min=0.3)
    np.testing.assert_allclose(c.P, c.A ** 3 - np.sqrt(6 * c.A ** 3), rtol=1e-3, atol=1e-3)
    np.testing.assert_allclose(c.D, c.A ** 2 - np.sqrt(8 * c.A / 3), rtol=1e-3, atol=1e-3)
    c = ref.maugis_dugdale_curve(1e-4, A_max=3.0, n=50, A_min=0.3)
    np.testing.assert_allclose(c.P, c.A ** 3 - 2.0, rtol=2e-3, atol=2e-3)
    # the indentation converges only like sqrt(lambda) (adhesive-zone term (4/3) A lam s ~ sqrt(lam))
    c = ref.maugis_dugdale_curve(1e-8, A_max=3.0, n=50, A_min=0.3)
    np.testing.assert_allclose(c.D, c.A ** 2, rtol=1e-3, atol=3e-4)
    np.testing.assert_allclose(c.P, c.A ** 3 - 2.0, rtol=1e-4, atol=1e-4)


def test_md_dimensional_jkr_limit():
    sc = ref.md_scales(R, E, W)
    assert sc.force == pytest.approx(np.pi * W * R)
    po = ref.jkr_pulloff(R, E, W)
    pt = ref.maugis_dugdale_pulloff_point(1e4)
    assert pt.A * sc.length == pytest.approx(po.contact_radius, rel=1e-5)
    assert pt.D * sc.indentation == pytest.approx(po.indentation, rel=1e-4)


def test_tabor_and_lambda():
    assert ref.md_lambda_from_tabor(1.0) == pytest.approx(1.157, abs=5e-4)
    eps = 0.3e-9
    mu = ref.tabor_parameter(R, W, E, eps)
    assert mu == pytest.approx((R * W ** 2 / (E ** 2 * eps ** 3)) ** (1 / 3))
    sigma_lj = 16 * W / (9 * np.sqrt(3) * eps)      # max stress of the LJ 9-3 law
    assert ref.md_lambda(R, E, W, sigma_lj) == pytest.approx(ref.md_lambda_from_tabor(mu), rel=1e-12)
    assert ref.maugis_dugdale_pulloff_from_tabor(1.0) == pytest.approx(
        ref.maugis_dugdale_pulloff(1.157), rel=1e-3)


# --- cone, flat punch -----------------------------------------------------------

def test_cone_pressure_integrates_to_force():
    theta = ref.cone_theta_from_half_angle(np.deg2rad(70.0))
    assert theta == pytest.approx(np.deg2rad(20.0))
    d = 1e-5
    a = ref.sneddon_cone_contact_radius(d, theta)
    assert ref.sneddon_cone_indentation(a, theta) == pytest.approx(d, rel=1e-12)
    F = ref.sneddon_cone_force(d, E, theta)
    assert F == pytest.approx(np.pi / 2 * E * a ** 2 * np.tan(theta), rel=1e-12)
    assert _axisym_force(lambda r: ref.sneddon_cone_pressure(r, a, E, theta), a) == pytest.approx(F, rel=1e-7)
    assert ref.sneddon_cone_pressure(1.1 * a, a, E, theta) == 0.0
    with pytest.raises(TengsimError):
        ref.sneddon_cone_force(d, E, np.pi / 2)


def test_flat_punch_pressure_integrates_to_force():
    a, d = 1e-4, 2e-6
    F = ref.flat_punch_force(d, a, E)
    assert F == pytest.approx(2 * a * E * d)
    assert _axisym_force(lambda r: ref.flat_punch_pressure(r, a, F), a) == pytest.approx(F, rel=1e-7)
    assert ref.flat_punch_pressure(a, a, F) == 0.0


# --- Westergaard / Johnson sinusoid ------------------------------------------------

WL, AMP = 1e-4, 2e-6


def _period_mean(fun):
    val, _ = integrate.quad(fun, -WL / 2, WL / 2, limit=400, epsabs=0, epsrel=1e-11, points=[0.0])
    return val / WL


@pytest.mark.parametrize("frac", [0.05, 0.4, 0.9, 1.0, 1.3])
def test_westergaard_mean_pressure(frac):
    ps = ref.westergaard_complete_contact_pressure(WL, AMP, E)
    assert ps == pytest.approx(np.pi * E * AMP / WL)
    pm = frac * ps
    assert _period_mean(lambda x: ref.westergaard_pressure(x, pm, WL, AMP, E)) == pytest.approx(pm, rel=1e-7)
    a = ref.westergaard_contact_half_width(pm, WL, AMP, E)
    assert ref.westergaard_mean_pressure(a, WL, AMP, E) == pytest.approx(min(pm, ps), rel=1e-12)
    if frac < 1:
        x = np.linspace(-WL / 2, WL / 2, 2001)
        p = ref.westergaard_pressure(x, pm, WL, AMP, E)
        assert np.all(p[np.abs(x) > a * (1 + 1e-9)] == 0) and np.all(p[np.abs(x) < a] > 0)
    # periodic
    assert ref.westergaard_pressure(0.3 * WL, pm, WL, AMP, E) == pytest.approx(
        ref.westergaard_pressure(1.3 * WL, pm, WL, AMP, E), rel=1e-9)


def test_westergaard_continuous_at_full_contact():
    ps = ref.westergaard_complete_contact_pressure(WL, AMP, E)
    x = np.linspace(-0.49 * WL, 0.49 * WL, 11)
    np.testing.assert_allclose(ref.westergaard_pressure(x, ps * (1 - 1e-12), WL, AMP, E),
                               ref.westergaard_pressure(x, ps, WL, AMP, E), rtol=1e-5, atol=1e-6 * ps)


def _edge_K(p_adh, a, h=1e-9):
    """Mode-I stress intensity at the contact edge: lim sqrt(2 pi xi) (-p(a - xi)) (Richardson in xi)."""
    k1 = np.sqrt(2 * np.pi * h * a) * -p_adh(a - h * a)
    k2 = np.sqrt(2 * np.pi * 2 * h * a) * -p_adh(a - 2 * h * a)
    return 2 * k1 - k2


def test_jkr_griffith_convention():
    """K^2/(2E*) = W for the JKR flat-punch term: fixes the convention used below."""
    a = 5e-5
    P1 = ref.jkr_force(a, R, E, W) - ref.hertz_force(a ** 2 / R, R, E)
    K = _edge_K(lambda r: ref.flat_punch_pressure(r, a, P1), a)
    assert K ** 2 / (2 * E) == pytest.approx(W, rel=1e-6)


@pytest.mark.parametrize("frac", [0.1, 0.3, 0.45])
def test_johnson_sinusoid_griffith(frac):
    a = frac * WL
    ps = ref.westergaard_complete_contact_pressure(WL, AMP, E)
    assert ref.johnson_sinusoid_mean_pressure(a, WL, AMP, E, 0.0) == pytest.approx(
        ref.westergaard_mean_pressure(a, WL, AMP, E), rel=1e-12)
    p_adh = ref.johnson_sinusoid_mean_pressure(a, WL, AMP, E, W) - ps * np.sin(np.pi * a / WL) ** 2
    assert p_adh < 0
    S2 = np.sin(np.pi * a / WL) ** 2

    def punch(x):
        q = S2 - np.sin(np.pi * x / WL) ** 2
        return np.where(q > 0, p_adh * np.cos(np.pi * x / WL) / np.sqrt(np.where(q > 0, q, 1.0)), 0.0)

    m, _ = integrate.quad(punch, -a, a, limit=400, epsabs=0, epsrel=1e-10, points=[0.0])
    assert m / WL == pytest.approx(p_adh, rel=1e-7)          # term carries mean p_adh
    K = _edge_K(lambda x: float(punch(x)), a)
    assert K ** 2 / (2 * E) == pytest.approx(W, rel=1e-6)     # Griffith at the edge
    assert ref.johnson_sinusoid_alpha(WL, AMP, E, W) == pytest.approx(
        np.sqrt(2 * W * WL / (np.pi ** 2 * E * AMP ** 2)))


# --- rectangle on a half-space ------------------------------------------------------

def _rect_quad(x, y, a, b):
    """int int 1/r over [-a,a]x[-b,b] seen from (x,y), split so (x,y) sits on sub-rectangle corners."""
    xs = sorted({-a, a, min(max(x, -a), a)})
    ys = sorted({-b, b, min(max(y, -b), b)})
    tot = 0.0
    for x0, x1 in zip(xs[:-1], xs[1:]):
        for y0, y1 in zip(ys[:-1], ys[1:]):
            v, _ = integrate.dblquad(lambda t, s: 1 / np.hypot(s - x, t - y), x0, x1, y0, y1,
                                     epsabs=0, epsrel=1e-11)
            tot += v
    return tot


@pytest.mark.parametrize("x,y", [(0.0, 0.0), (0.3, -0.2), (0.9, 0.45), (1.0, 0.2),
                                 (-1.7, 0.3), (2.5, -1.9), (0.2, 3.0)])
def test_rectangle_displacement_vs_quadrature(x, y):
    a, b, p, Es = 1.0, 0.5, 3.0, 2.0
    u = ref.rectangle_displacement(x, y, a, b, p=p, E_star=Es)
    assert u == pytest.approx(p / (np.pi * Es) * _rect_quad(x, y, a, b), rel=1e-6)


def test_rectangle_square_centre_and_far_field():
    a, p, Es = 0.7, 2.0, 5.0
    u0 = ref.rectangle_displacement(0.0, 0.0, a, a, p=p, E_star=Es)
    assert u0 == pytest.approx(8 * p * a / (np.pi * Es) * np.log(1 + np.sqrt(2)), rel=1e-13)
    r = 300.0
    assert ref.rectangle_displacement(r, 0.0, a, a, p=p, E_star=Es) == pytest.approx(
        p * 4 * a * a / (np.pi * Es * r), rel=1e-5)
    # symmetry
    assert ref.rectangle_displacement(0.3, 0.2, a, 2 * a) == pytest.approx(
        ref.rectangle_displacement(-0.3, -0.2, a, 2 * a), rel=1e-14)
