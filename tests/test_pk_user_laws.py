"""'pk' asks a law for its hard-wall limit (tengsim.laws.cohesive), never its class: a subclass of a built-in
law and a user's cohesive law defined here (one class, nothing registered elsewhere) are solved, and give the
built-in law's answer or a reference's; the design asks the law's limit which solver it prefers."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest

from tengsim.errors import TengsimError
from tengsim.kernels import FreeKernel
from tengsim.laws import Exponential, Law, MaugisDugdale
from tengsim.laws.cohesive import CohesiveFunctions, CohesiveLimit
from tengsim.shapes import Paraboloid
from tengsim.solvers import Problem, State
from tengsim.solvers.pk import PKSolver, supports
from tengsim.solvers.ram import RAMSolver

from _user_laws import LinearSoftening


@dataclass(frozen=True)
class MyDugdale(MaugisDugdale):
    """A user's subclass of the built-in Maugis–Dugdale law (a new name, the same law)."""

    note: str = "mine"


@dataclass(frozen=True)
class DecayLimit(CohesiveLimit):
    """A user's hard-wall limit, written from scratch: t = −(W/ρ) e^{−u/ρ} (the exponential law's)."""

    work: float = 1.0
    length: float = 1.0

    @property
    def tension(self) -> float:
        return self.work / self.length

    def traction(self, u, xp=np):
        return -(self.work / self.length) * xp.exp(-xp.maximum(u, 0.0) / self.length)

    def energy(self, u, xp=np):
        return -self.work * xp.exp(-xp.maximum(u, 0.0) / self.length)

    def curvature(self, u, xp=np):
        return -(self.work / self.length**2) * xp.exp(-xp.maximum(u, 0.0) / self.length)


@dataclass(frozen=True)
class MyExponential(Law):
    """A user's cohesive law: its soft form for the soft solvers is the built-in's, its hard-wall limit its own."""

    range: float = 0.8
    g_safe: float = 0.6

    def _raw(self, g, need_dp=True, xp=np):
        return Exponential(range=self.range)._raw(g, need_dp, xp)

    def hard_wall(self):
        return DecayLimit(float(Exponential(range=self.range).work), float(self.range))


@dataclass(frozen=True)
class Jump(Law):
    """A user's limit whose traction jumps without being a Dugdale zone: not 'pk''s (it says 'ram')."""

    g_safe: float = 0.6

    def _raw(self, g, need_dp=True, xp=np):  # pragma: no cover - not solved
        raise NotImplementedError

    def hard_wall(self):
        return CohesiveFunctions(t=lambda u, xp: xp.where(u < 1.0, -1.0 + 0.5 * u, 0.0),
                                 phi=lambda u, xp: xp.zeros_like(u), d2phi=lambda u, xp: xp.zeros_like(u),
                                 smooth=False)


def _sphere(dx=0.2, size=9.0):
    shape = Paraboloid(1.0, size)
    grid = shape.grid(dx)
    return shape.gap(grid), FreeKernel(grid, 1.0), grid


@pytest.mark.parametrize("solver", [PKSolver(1e-7), PKSolver(1e-7, zone="outer"), PKSolver(1e-7, md_zone="sharp")])
def test_a_subclass_of_maugis_dugdale_is_the_same_law(solver):
    """A subclass of MaugisDugdale (refused when 'pk' asked for the class name) is accepted and its path
    (approach to 0.5 ε, retraction to −2 ε, warm-started) is the base law's, bit for bit."""
    U0, K, _ = _sphere()
    assert supports(MyDugdale())
    out = {}
    for law in (MaugisDugdale(), MyDugdale()):
        st, out[law.__class__] = State.zero(U0.shape), []
        for D in (-1.0, 0.0, 0.5, -0.5, -2.0):
            eq = solver.solve(Problem(U0 - D + 1.0, law, K), st)
            assert eq.converged, eq.message
            st = eq.state
            out[law.__class__].append(eq)
    for a, b in zip(out[MaugisDugdale], out[MyDugdale]):
        assert np.array_equal(a.P, b.P) and np.array_equal(a.H, b.H) and a.message == b.message


def test_a_users_cohesive_law_is_solved_as_its_limit_says():
    """A user's law with its own limit (the exponential traction written afresh): 'pk' solves it, its path
    (approach, retraction, warm-started; tol 1e-8 ε) gives the built-in Exponential's ∬P within 1e-10 of the
    largest |∬P| (measured 1e-15: the same formula, other round-off), and its P = t(H) off the contact to 1e-6."""
    U0, K, grid = _sphere()
    law, ref = MyExponential(), Exponential(range=0.8)
    assert supports(law)
    solver = PKSolver(1e-8)
    F = {0: [], 1: []}
    for i, lw in enumerate((ref, law)):
        st = State.zero(U0.shape)
        for D in (-0.5, 0.0, 0.5, 0.0, -1.0):
            eq = solver.solve(Problem(U0 - D + 1.0, lw, K), st)
            assert eq.converged, eq.message
            st = eq.state
            F[i].append(float(eq.P.sum()) * grid.area)
    off = eq.H > 0
    assert np.abs(eq.P[off] - law.hard_wall().traction(eq.H[off])).max() < 1e-6
    F0, F1 = np.array(F[0]), np.array(F[1])
    assert np.abs(F0 - F1).max() <= 1e-10 * np.abs(F0).max()


def test_a_users_smooth_limit_on_pk_meets_ram():
    """A user's limit of three callables (linear softening), sphere D = 0.5 ε cold: 'pk''s outer fixed point and
    'ram''s descent (the reference: its equilibrium checked in tests/test_ram_solver.py) give ∬P within 1e-7 (measured
    2e-10)."""
    U0, K, grid = _sphere(0.2, 9.6)
    pr = Problem(U0 - 0.5 + 1.0, LinearSoftening(), K)
    a = PKSolver(1e-9).solve(pr, State.zero(U0.shape))
    b = RAMSolver(1e-9).solve(pr, State.zero(U0.shape))
    assert a.converged and b.converged, (a.message, b.message)
    assert float(a.P.sum()) == pytest.approx(float(b.P.sum()), rel=1e-7)


def test_pk_refuses_a_jump_that_is_not_a_dugdale_zone():
    """A limit whose traction jumps but is not a plateau is refused in one line naming 'ram'."""
    U0, K, _ = _sphere()
    assert not supports(Jump())
    with pytest.raises(TengsimError, match="use solver 'ram'"):
        PKSolver().solve(Problem(U0 + 1.0, Jump(), K), State.zero(U0.shape))


def test_the_design_asks_the_limit_which_solver_it_prefers():
    """The limit's ``solver``: 'pk' for the Dugdale zone (a subclass's too) and the exponential, 'ram' for a
    user's limit that does not say; none for a law without adhesion or without a limit."""
    from tengsim.design.plan import constrained_solver

    assert constrained_solver(MaugisDugdale()) == "pk" and constrained_solver(MyDugdale()) == "pk"
    assert constrained_solver(Exponential()) == "pk" and constrained_solver(LinearSoftening()) == "ram"
    from tengsim.laws import LJ93, Repulsive

    assert constrained_solver(LJ93()) is None and constrained_solver(Repulsive()) is None
