"""Laws stiff at the pixel scale (issue 23, item 2): the fast solver's automatic continuation past its
iteration cap (tengsim.continuation.persist).

The stiff equilibrium: the README's topography command (a 30 nm Gaussian bump, 2 µm cell, E* = 1 MPa,
W = 50 mJ/m², ε = 1 nm, periodic) on a 64² height map (31 ε pixels, pixel snap number ≈ 2.2e3), cold
at D = −1.  The fast solver stops there at its 3000-iteration cap (max|r| ≈ 78 ε); continued from where it
stopped it converges (8132 iterations in all)."""
from dataclasses import replace

import numpy as np
import pytest

from tengsim.run.plan import ContactPlan
from tengsim.run.plan import plan_contact
from tengsim.continuation.walker import PERSIST_FACTOR, Walker, persist
from tengsim.kernels import make_kernel
from tengsim.solvers import FastSolver, Problem, State, VSRSolver


def _bump_problem(tmp_path, n, D=-1.0, eps="1nm"):
    x = np.linspace(-1e-6, 1e-6, n)
    X, Y = np.meshgrid(x, x, indexing="ij")
    np.savetxt(tmp_path / "bump.txt", 30e-9 * np.exp(-(X**2 + Y**2) / (0.4e-6) ** 2))
    plan = plan_contact(dict(shape="topography", file=str(tmp_path / "bump.txt"), physical_size="2um,2um",
                             E_star="1MPa", W="50mJ/m2", eps=eps, boundary="periodic"))
    grid = plan.shape.grid(plan.dx)
    U0 = plan.shape.gap(grid)
    kernel = make_kernel("periodic", grid, plan.tabor**1.5)
    return U0, plan.law, kernel, Problem(U0 - D + 1.0, plan.law, kernel)


def _eq9_residual(problem, eq, D):
    """max|H − (−D + U0 + K P(H))| computed afresh from H alone (Eq. 9), in ε."""
    U0 = problem.g0 + D - 1.0
    _, P = problem.law.evaluate(eq.H + 1.0)
    return float(np.max(np.abs(eq.H - (-D + U0 + problem.kernel.apply(P)))))


@pytest.mark.slow
def test_stiff_bump_equilibrium_converges_and_satisfies_eq9(tmp_path):
    """The first failing equilibrium of the README command at ε = 1 nm (~6 s)."""
    U0, law, kernel, problem = _bump_problem(tmp_path, 64)
    fast = FastSolver(tol=1e-6)
    eq = fast.solve(problem, State.zero(U0.shape))
    assert not eq.converged and eq.iterations == 3000  # the failure the issue reports
    out = persist(fast, problem, eq)
    assert out.converged and out.residual <= 1e-6
    assert out.iterations > 3000 and "after the cap" in out.message
    assert _eq9_residual(problem, out, -1.0) <= 2e-6  # independent of the solver's own bookkeeping
    # the branch walker applies it by itself
    br = Walker(U0, law, kernel, fast)
    again = br.solve(-1.0, State.zero(U0.shape))
    assert again.converged and again.iterations == out.iterations
    assert np.array_equal(again.H, out.H)


def test_converged_solve_is_untouched(tmp_path):
    """An equilibrium that converges within the cap is returned as it is: bit for bit."""
    U0, law, kernel, problem = _bump_problem(tmp_path, 16, D=-1.0, eps="20nm")
    fast = FastSolver(tol=1e-8)
    eq = fast.solve(problem, State.zero(U0.shape))
    assert eq.converged
    assert persist(fast, problem, eq) is eq
    br = Walker(U0, law, kernel, fast)
    eq2 = br.solve(-1.0, State.zero(U0.shape))
    assert np.array_equal(eq2.H, eq.H) and eq2.iterations == eq.iterations and eq2.n_conv == eq.n_conv


def test_continued_solve_matches_an_uncapped_one(tmp_path):
    """Easy problem: a solve capped early and continued lands on the uncapped solve's equilibrium
    (tol 1e-10: the two agree to 1e-8 relative in H and energy)."""
    U0, law, kernel, problem = _bump_problem(tmp_path, 16, D=-1.0, eps="20nm")
    ref = FastSolver(tol=1e-10).solve(problem, State.zero(U0.shape))
    assert ref.converged and ref.iterations > 10
    cap = max(ref.iterations // 3, 2)
    capped = FastSolver(tol=1e-10, max_iter=cap)
    eq = capped.solve(problem, State.zero(U0.shape))
    assert not eq.converged
    out = persist(capped, problem, eq)
    assert out.converged and out.iterations > cap
    scale = float(np.max(np.abs(ref.H)))
    assert float(np.max(np.abs(out.H - ref.H))) <= 1e-8 * scale
    assert out.energy == pytest.approx(ref.energy, rel=1e-8)


def test_other_failures_and_other_solvers_are_not_retried(tmp_path):
    U0, law, kernel, problem = _bump_problem(tmp_path, 16, D=-1.0, eps="20nm")
    vsr = VSRSolver(tol=1e-6, max_iter=3)
    eq = vsr.solve(problem, State.zero(U0.shape))
    assert not eq.converged and persist(vsr, problem, eq) is eq
    fast = FastSolver(tol=1e-6, max_iter=2)
    eq = fast.solve(problem, State.zero(U0.shape))
    failed = replace(eq, message="line search failed", capped=False)  # a stop other than the cap
    assert persist(fast, problem, failed) is failed
    assert PERSIST_FACTOR >= 2


def test_stiff_small_rough_surface_converges():
    """A small periodic rough surface with a law stiff at the pixel (snap number > 1) converges."""
    from tengsim.grid import Grid
    from tengsim.laws import LJ93
    from tengsim.status import pixel_snap_number
    rng = np.random.default_rng(3)
    n, dx = 32, 2.0
    k = np.fft.fftfreq(n, d=dx)
    kk = np.hypot(k[:, None], k[None, :])
    kk[0, 0] = np.inf
    h = np.real(np.fft.ifft2(np.fft.fft2(rng.standard_normal((n, n))) * kk ** (-1.8)))
    h *= 0.2 / np.sqrt(np.mean(np.gradient(h, dx)[0] ** 2 + np.gradient(h, dx)[1] ** 2))
    U0 = h.max() - h
    grid = Grid(n, n, dx, dx)
    law = LJ93()
    kernel = make_kernel("periodic", grid, 2.0 ** 1.5)
    assert pixel_snap_number(law, kernel) > 1
    problem = Problem(U0 - 0.5 + 1.0, law, kernel)
    fast = FastSolver(tol=1e-6)
    eq = persist(fast, problem, fast.solve(problem, State.zero(U0.shape)))
    assert eq.converged
    assert _eq9_residual(problem, eq, 0.5) <= 2e-6


def test_simulate_continues_capped_solves_also_on_the_mirror_block():
    """Through simulate (sphere: the mirror-reduced solve, MirrorSolver around the fast solver): with a
    cap far too small every row still converges, and F(D) equals the uncapped run's to 1e-6 relative."""
    from tengsim.run.simulate import simulate
    from tengsim.continuation import PathSpec
    from tengsim.shapes.axisymmetric import Paraboloid
    shape = Paraboloid(radius=1.0, cell=6.0)
    path = PathSpec(d_min=-1.0, d_max=0.5, d_step=0.5)
    ref = simulate(ContactPlan(shape, 1.0, 0.25, path, boundary="free", solver=FastSolver(tol=1e-8)))
    capped = simulate(ContactPlan(shape, 1.0, 0.25, path, boundary="free", solver=FastSolver(tol=1e-8, max_iter=15)))
    assert str(capped.params["symmetry"]).startswith("x")  # the mirror block was used
    assert bool(np.all(capped.table["converged"])) and int(np.max(capped.table["iterations"])) > 15
    F0, F1 = np.asarray(ref.table["F"]), np.asarray(capped.table["F"])
    assert F1.shape == F0.shape
    assert np.max(np.abs(F1 - F0)) <= 1e-6 * np.max(np.abs(F0))
