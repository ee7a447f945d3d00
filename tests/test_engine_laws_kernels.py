"""Engine checks: interaction laws (P = −dΦ/dg, LJ93 normalisation, safe extension) and the
elastic kernels (free kernel = direct O(n²) sum of the pixel influence coefficients; Love's
uniformly loaded square; periodic kernel = 2κ/|q| on a single Fourier mode).

Tolerances are stated per assertion; see docs/validation.md for the measured numbers.
"""
from __future__ import annotations

import numpy as np
import pytest
from conftest import registered

from tengsim import references as ref
from tengsim.grid import Grid
from tengsim.laws import LJ93, Repulsive, SafeLaw
from tengsim.plugins import LAWS as LAWS_REGISTERED
from tengsim.kernels import FreeKernel, PeriodicKernel, pixel_influence

# every registered law with its defaults (a plugin's law is checked too), and one other parameter set
LAWS = [LAWS_REGISTERED.get(name)() for name in LAWS_REGISTERED.names()] + [Repulsive(scale=2.0, exponent=4.0, g_safe=0.5)]


# ---------------------------------------------------------------------------------------------
# laws
# ---------------------------------------------------------------------------------------------

@pytest.mark.parametrize("law", LAWS, ids=lambda l: type(l).__name__ + str(getattr(l, "exponent", "")))
def test_pressure_is_minus_energy_derivative(law):
    """P = −dΦ/dg by central differences (relative 1e-7) on both sides of g_safe (the law as a solve
    evaluates it: wrapped in its safe extension)."""
    law = SafeLaw(law)
    g = np.concatenate([np.linspace(-1.0, law.g_safe - 1e-3, 40), np.linspace(law.g_safe + 1e-3, 6.0, 200)])
    h = 1e-6
    dphi = (law.energy(g + h) - law.energy(g - h)) / (2 * h)
    P = law.pressure(g)
    scale = np.maximum(np.abs(P), 1.0)
    assert np.max(np.abs(P + dphi) / scale) < 1e-7


@pytest.mark.parametrize("law", LAWS, ids=lambda l: type(l).__name__ + str(getattr(l, "exponent", "")))
def test_stiffness_is_minus_pressure_derivative(law):
    """Φ'' = −dP/dg = law.stiffness(g) above g_safe (relative 1e-6)."""
    g = np.linspace(law.g_safe + 1e-3, 6.0, 300)
    h = 1e-6
    dP = (law.pressure(g + h) - law.pressure(g - h)) / (2 * h)
    k = law.stiffness(g)
    assert np.max(np.abs(k + dP) / np.maximum(np.abs(k), 1.0)) < 1e-6


def test_lj93_normalisation():
    """Φ(1) = −1 (work of adhesion), P(1) = 0, tensile peak −(16/9)/√3 at g = 3^{1/6} (Greenwood's σ0)."""
    law = LJ93()
    assert law.energy(np.array([1.0]))[0] == pytest.approx(-1.0, abs=1e-14)
    assert law.pressure(np.array([1.0]))[0] == pytest.approx(0.0, abs=1e-14)
    g = np.linspace(1.0, 2.0, 200001)
    P = law.pressure(g)
    i = np.argmin(P)
    assert g[i] == pytest.approx(3 ** (1 / 6), abs=1e-5)
    assert P[i] == pytest.approx(-16 / (9 * np.sqrt(3)), rel=1e-9)
    # ∫_1^∞ P dg = Φ(∞) − ... = −Φ(1)... i.e. W: the work to separate equals the adhesion energy
    gg = np.geomspace(1.0, 400.0, 400_001)
    work = np.trapezoid(law.pressure(gg), gg) if hasattr(np, "trapezoid") else np.trapz(law.pressure(gg), gg)
    assert work == pytest.approx(-1.0, abs=2e-5)


def test_repulsive_is_repulsive_half_of_lj93():
    g = np.linspace(0.7, 5.0, 50)
    assert np.allclose(Repulsive().pressure(g), (8 / 3) * g**-9, rtol=1e-13, atol=0)
    assert np.allclose(Repulsive().energy(g), (1 / 3) * g**-8, rtol=1e-13, atol=0)


@pytest.mark.parametrize("law", LAWS, ids=lambda l: type(l).__name__ + str(getattr(l, "exponent", "")))
def test_safe_extension_continuous_and_finite(law):
    """P, Φ (and the stiffness) continuous at g_safe to O(h); finite, monotone P for g <= 0."""
    law = SafeLaw(law)
    gs, h = law.g_safe, 1e-9
    below, above = np.array([gs - h]), np.array([gs + h])
    for f in (law.pressure, law.energy, law.stiffness):
        a, b = f(below)[0], f(above)[0]
        assert abs(a - b) <= 1e-6 * max(1.0, abs(a)), f.__name__
    g = np.array([-1e3, -10.0, -1.0, 0.0, 0.3 * gs])
    for f in (law.pressure, law.energy, law.stiffness):
        assert np.all(np.isfinite(f(g)))
    assert np.all(np.diff(law.pressure(g)) < 0)  # still pushes the surfaces apart harder as g drops


# ---------------------------------------------------------------------------------------------
# kernels
# ---------------------------------------------------------------------------------------------

def _direct_free(p, grid, coupling):
    """w_i = (κ/π) Σ_j c(x_i − x_j, y_i − y_j) p_j: the O(n²) sum of exact pixel coefficients."""
    X, Y = grid.mesh()
    x, y = X.ravel(), Y.ravel()
    C = pixel_influence(x[:, None] - x[None, :], y[:, None] - y[None, :], grid.dx, grid.dy)
    return (coupling / np.pi) * (C @ p.ravel()).reshape(grid.shape)


@pytest.mark.parametrize("shape,dx,dy", [((9, 9), 0.3, 0.3), ((11, 8), 0.25, 0.4), ((7, 13), 1.0, 0.5)])
def test_free_kernel_equals_direct_sum(shape, dx, dy):
    grid = Grid(shape[0], shape[1], dx, dy)
    rng = np.random.default_rng(1)
    p = rng.normal(size=shape)
    K = FreeKernel(grid, 0.7)
    w_fft = K.apply(p)
    w_dir = _direct_free(p, grid, 0.7)
    assert np.max(np.abs(w_fft - w_dir)) < 1e-12 * np.max(np.abs(w_dir))


def test_pixel_influence_symmetric_and_far_field():
    """Coefficients are even in x and y; far away they tend to dx·dy/r (point load)."""
    dx, dy = 0.2, 0.3
    for x, y in [(0.0, 0.0), (0.7, 0.1), (2.0, -1.3)]:
        c = pixel_influence(np.array(x), np.array(y), dx, dy)
        for sx, sy in [(-1, 1), (1, -1), (-1, -1)]:
            assert pixel_influence(np.array(sx * x), np.array(sy * y), dx, dy) == pytest.approx(c, rel=1e-13)
    r = 50.0
    assert pixel_influence(np.array(r), np.array(0.0), dx, dy) == pytest.approx(dx * dy / r, rel=1e-4)


@pytest.mark.parametrize("coupling", [0.3, 2.0])
def test_uniform_square_centre_displacement(coupling):
    """Uniform p on a square of half-width a: centre w = (8pa/(πE*)) ln(1+√2), E* = 1/κ (Love 1929);
    exact for pixel-aligned squares, and the full displacement field matches the rectangle formula."""
    a, p = 1.5, 0.8
    grid = Grid(31, 31, 0.1, 0.1)  # the pressure patch: every pixel of [-a, a]^2 (31 pixels of 0.1 → a = 1.55)
    a = grid.lx / 2
    K = FreeKernel(grid, coupling)
    w = K.apply(np.full(grid.shape, p))
    centre = w[15, 15]
    expect = 8 * p * a / (np.pi * (1 / coupling)) * np.log(1 + np.sqrt(2))
    assert centre == pytest.approx(expect, rel=1e-12)
    assert centre == pytest.approx(ref.rectangle_displacement(0.0, 0.0, a, a, p, 1 / coupling), rel=1e-12)
    X, Y = grid.mesh()
    assert np.allclose(w, ref.rectangle_displacement(X, Y, a, a, p, 1 / coupling), rtol=1e-12, atol=0)


def test_uniform_square_patch_inside_larger_grid():
    """A pressure patch [-a, a]² inside a bigger free cell: displacement at the centre and outside."""
    grid = Grid(61, 61, 0.1, 0.1)
    X, Y = grid.mesh()
    a = 1.05  # 21 pixels wide
    p = np.where((np.abs(X) < a) & (np.abs(Y) < a), 1.0, 0.0)
    K = FreeKernel(grid, 1.0)
    w = K.apply(p)
    assert np.allclose(w, ref.rectangle_displacement(X, Y, a, a, 1.0, 1.0), rtol=1e-11, atol=1e-13)
    assert w[30, 30] == pytest.approx(8 * a / np.pi * np.log(1 + np.sqrt(2)), rel=1e-12)


def test_periodic_kernel_single_mode_and_zero_mean():
    """cos(qx) pressure gives w = (2κ/q) cos(qx) (Johnson §13.2 with E* = 1/κ); the mean is removed."""
    grid = Grid(64, 16, 0.125, 0.125)
    X, Y = grid.mesh()
    q = 2 * np.pi * 3 / grid.lx
    kappa = 0.9
    w = PeriodicKernel(grid, kappa).apply(np.cos(q * X) + 5.0)
    assert np.allclose(w, 2 * kappa / q * np.cos(q * X), rtol=0, atol=1e-12)
    assert abs(w.mean()) < 1e-13


def test_periodic_kernel_is_sum_of_images_up_to_a_constant():
    """For a smooth zero-mean load, the periodic kernel equals the free-space response of the
    periodic array of images (truncated lattice sum, exact pixel coefficients) up to a constant;
    agreement to 1 % of max|w| (the spectral 2κ/|q| and the pixel-averaged kernel differ only at
    high q, which a smooth load does not excite)."""
    n, dx = 24, 0.25
    grid = Grid(n, n, dx, dx)
    X, Y = grid.mesh()
    p = np.exp(-(X**2 + Y**2) / 0.8) - 0.5 * np.exp(-((X - 1.0) ** 2 + (Y + 0.5) ** 2) / 0.5)
    p -= p.mean()
    wp = PeriodicKernel(grid, 1.0).apply(p)
    # images: the load tiled on a (2m+1)² block, free (isolated) kernel, centre block kept
    m = 8
    big = Grid((2 * m + 1) * n, (2 * m + 1) * n, dx, dx)
    wbig = FreeKernel(big, 1.0).apply(np.tile(p, (2 * m + 1, 2 * m + 1)))
    w = wbig[m * n:(m + 1) * n, m * n:(m + 1) * n]
    diff = (w - w.mean()) - wp
    assert np.max(np.abs(diff)) < 1e-2 * np.max(np.abs(wp))


@pytest.mark.parametrize("law", [LJ93(), Repulsive(), SafeLaw(LJ93()), SafeLaw(Repulsive())], ids=repr)
def test_energy_pressure_in_place_equals_evaluate(law):
    """The solvers' hot path (in place, scratch buffers) gives evaluate's values, also below g_safe
    (the law's formula, or its safe extension when wrapped)."""
    rng = np.random.default_rng(5)
    for g in (0.8 + 3 * rng.random(1000), np.linspace(-0.5, 4.0, 1001)):
        phi, p = law.evaluate(g)
        out = np.full_like(g, np.nan)
        work = (np.empty_like(g), np.empty_like(g))
        s = law.energy_pressure(g, out, work)
        assert np.allclose(out, p, rtol=1e-13, atol=1e-13)
        assert s == pytest.approx(phi.sum(), rel=1e-12)


@pytest.mark.parametrize("boundary", registered("boundary"))
def test_direct_fft_path_equals_public_scipy_fft(boundary):
    """The kernels run on scipy's pocketfft binding with preallocated buffers where it exists; it
    must agree with the public scipy.fft path to round-off, with and without ``out``, and the
    public fallback must give the same numbers (an old or new scipy may lack the binding)."""
    import pickle

    from tengsim.kernels import make_kernel

    grid = Grid(23, 17, 0.2, 0.3)
    p = np.random.default_rng(3).standard_normal(grid.shape)
    K = make_kernel(boundary, grid, 0.8)
    conv = K._conv
    w_pub = np.asarray(conv._apply_public(p))
    w = K.apply(p)
    assert w.shape == grid.shape and w.flags["C_CONTIGUOUS"]
    assert np.allclose(w, w_pub, rtol=0, atol=1e-13 * np.abs(w_pub).max())
    out = np.full(grid.shape, np.nan)
    assert K.apply(p, out=out) is out and np.array_equal(out, w)
    w2 = K.apply(2 * p)  # a second call must not change the first result (no shared buffer returned)
    assert np.array_equal(out, w) and np.allclose(w2, 2 * w, rtol=1e-13, atol=1e-15)
    K2 = pickle.loads(pickle.dumps(K))
    assert np.array_equal(K2.apply(p), w)
    conv._direct = False  # the public fallback
    assert np.allclose(K.apply(p), w, rtol=0, atol=1e-13 * np.abs(w).max())
    assert np.allclose(K.apply(p, out=out), w, rtol=0, atol=1e-13 * np.abs(w).max())
