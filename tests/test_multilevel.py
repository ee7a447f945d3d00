"""Nested-grid start (tengsim.multilevel): resampling is exact for resolved harmonics, and the nested
solve lands on an equilibrium of the fine problem that satisfies Eq. (9) to the tolerance."""
import numpy as np
import pytest

from tengsim.errors import TengsimError
from tengsim.shapes import random_rough
from tengsim.grid import Grid, fourier_resample
from tengsim.laws import LJ93
from tengsim.kernels import FreeKernel, PeriodicKernel
from tengsim.multilevel import coarse_levels, nested_solve
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
