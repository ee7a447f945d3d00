"""Nested-grid start (tengsim.solvers.multilevel): resampling is exact for resolved harmonics, and the nested
solve lands on an equilibrium of the fine problem that satisfies Eq. (9) to the tolerance."""
import numpy as np
import pytest

from tengsim.errors import TengsimError
from tengsim.shapes import random_rough
from tengsim.grid import Grid, fourier_resample
from tengsim.laws import LJ93
from tengsim.kernels import FreeKernel, PeriodicKernel
from tengsim.solvers.multilevel import coarse_levels, nested_solve
from tengsim.solvers import FastSolver, Problem, State


def _field(n, L=10.0):
    x = np.arange(n) * L / n
    X, Y = np.meshgrid(x, x, indexing="ij")
    k = 2 * np.pi / L
    return 0.7 + np.cos(k * X) + 0.3 * np.sin(3 * k * Y) + 0.2 * np.cos(2 * k * X + 5 * k * Y)


@pytest.mark.parametrize("n,m", [(64, 32), (32, 64), (48, 96), (64, 64)])
def test_fourier_resample_exact_for_resolved_harmonics(n, m):
    out = fourier_resample(_field(n), (m, m))
    assert out.shape == (m, m)
    assert np.max(np.abs(out - _field(m))) < 1e-12


def test_fourier_resample_drops_unresolved_and_keeps_mean():
    n = 64
    x = np.arange(n) * 2 * np.pi / n
    a = 2.0 + np.cos(20 * x)[:, None] * np.ones(n)  # wavenumber 20 > 16 = Nyquist of 32
    b = fourier_resample(a, (32, 32))
    assert np.allclose(b, 2.0, atol=1e-12)


def test_coarse_levels():
    assert coarse_levels((512, 512), min_size=128) == [(128, 128), (256, 256), (512, 512)]
    assert coarse_levels((512, 512), min_size=128, levels=1) == [(256, 256), (512, 512)]
    assert coarse_levels((96, 96), min_size=16) == [(24, 24), (48, 48), (96, 96)]  # 12 < 16
    assert coarse_levels((99, 99), min_size=16) == [(99, 99)]  # odd: no coarser level
    # never coarser than max_dx: from dx = 0.25, pixels 0.5 and 1.0 are allowed, 2.0 is not
    assert coarse_levels((512, 512), min_size=16, dx=0.25, max_dx=1.0) == [(128, 128), (256, 256), (512, 512)]
    assert coarse_levels((512, 512), min_size=16, dx=0.25, max_dx=0.5) == [(256, 256), (512, 512)]


def _rough_problem(n=128):
    surf = random_rough(n, n * 0.25, hurst=0.8, rms_height=1.0, short_cutoff=2.0, seed=3)
    grid = surf.grid()
    U0 = surf.gap(grid)
    D = float(np.quantile(U0, 0.05))
    return U0 - D + 1.0, PeriodicKernel(grid, 0.5 ** 1.5)


def test_nested_solve_is_an_equilibrium_of_the_fine_problem():
    g0, K = _rough_problem()
    solver = FastSolver(tol=1e-7)
    ns = nested_solve(solver, g0, LJ93(), K, min_size=32, max_dx=1.0)
    eq = ns.equilibrium
    assert [lv.shape for lv in ns.levels] == [(32, 32), (64, 64), (128, 128)]
    assert eq.converged and eq.residual <= 1e-7
    # the reported state satisfies Eq. (9) on the fine grid, re-checked from scratch
    H = eq.H
    r = H - (g0 - 1.0 + K.apply(LJ93().pressure(H + 1.0)))
    assert np.max(np.abs(r)) < 1.01e-7
    # costs are recorded coarsest first; a coarse convolution counts a quarter per halving
    assert ns.n_conv == sum(lv.n_conv for lv in ns.levels)
    assert ns.fine_equivalent_conv < ns.n_conv
    assert eq.n_conv == ns.levels[-1].n_conv
    # on this surface it is the same stable equilibrium as the cold start's (energy to 1e-9)
    cold = solver.solve(Problem(g0, LJ93(), K), State.zero(g0.shape))
    assert cold.converged
    assert abs(eq.energy - cold.energy) <= 1e-9 * abs(cold.energy)


def test_nested_solve_rejects_free_kernel_and_bad_shape():
    g0, K = _rough_problem(64)
    with pytest.raises(TengsimError, match="periodic"):
        nested_solve(FastSolver(), g0, LJ93(), FreeKernel(Grid(64, 64, 0.25, 0.25), 0.35))
    with pytest.raises(TengsimError, match="shape"):
        nested_solve(FastSolver(), g0[:32, :32], LJ93(), K)


def _rough_periodic(n, seed=3):
    """A smooth random periodic surface (a few long wavelengths), heights in ε."""
    rng = np.random.default_rng(seed)
    k = np.fft.fftfreq(n, 1.0 / n)
    K = np.hypot(*np.meshgrid(k, k, indexing="ij"))
    c = np.where((K >= 1) & (K <= 6), np.maximum(K, 1.0) ** -1.8, 0.0) * np.exp(2j * np.pi * rng.random((n, n)))
    h = np.real(np.fft.ifft2(c))
    return 3.0 * h / h.std()


@pytest.mark.parametrize("prolong", ["block", "fourier"])
def test_nested_pk_under_load_lands_on_the_cold_equilibrium(prolong):
    """Hard wall, load control: the nested start (block or Fourier prolongation) ends on the fine grid's own
    equilibrium: the same contact set to a pixel in 10⁴, pressures to the solver's tolerance."""
    from tengsim.laws import Repulsive
    from tengsim.solvers.pk import PKSolver

    n, load = 128, 0.05
    h = _rough_periodic(n)
    k = PeriodicKernel(Grid(n, n, 0.5, 0.5), 1.0)
    g0 = 1.0 + h.max() - h
    solver = PKSolver(tol=1e-8, max_iter=2000)
    cold, dD = solver.solve_load(Problem(g0, Repulsive(), k), load)
    ns = nested_solve(solver, g0, Repulsive(), k, min_size=32, max_dx=4.0, coarse_tol=None, load=load,
                      prolong=prolong)
    eq = ns.equilibrium
    assert cold.converged and eq.converged
    assert [s.shape for s in ns.levels] == [(32, 32), (64, 64), (128, 128)]
    assert eq.P.mean() == pytest.approx(load, rel=1e-9)
    assert np.mean((eq.P > 0) != (cold.P > 0)) < 1e-4
    assert np.max(np.abs(eq.P - cold.P)) < 1e-5 * np.max(cold.P)
    assert ns.approach == pytest.approx(dD, abs=1e-6)


def test_nested_refuses_an_unknown_prolongation_and_load_without_solve_load():
    n = 32
    k = PeriodicKernel(Grid(n, n, 0.5, 0.5), 1.0)
    with pytest.raises(TengsimError, match="prolong"):
        nested_solve(FastSolver(), np.ones((n, n)) * 2, LJ93(), k, prolong="cubic")
    with pytest.raises(TengsimError, match="solve_load"):
        nested_solve(FastSolver(), np.ones((n, n)) * 2, LJ93(), k, load=0.1)
