"""The 'pk' solver's contact solve compiled with JAX ('pk-jax', tengsim.solvers._pk_jax) against the NumPy one
('pk'), on JAX's CPU backend in float64: the same pressures, forces and gaps to round-off (never iteration
counts), for the hard wall (displacement and load control, free and periodic kernels) and a Maugis–Dugdale
sphere (the cohesive zone's outer updates on the host around the compiled solve: pk-jax's only zone loop)."""
from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("jax")

import tengsim.plugins  # noqa: E402,F401  (every built-in, in the registry's order, before pk is imported alone)
from tengsim.errors import TengsimError  # noqa: E402
from tengsim.kernels import FreeKernel  # noqa: E402
from tengsim.laws import MaugisDugdale, Repulsive  # noqa: E402
from tengsim.shapes import Paraboloid  # noqa: E402
from tengsim.solvers import Problem, State, make_solver  # noqa: E402
from tengsim.solvers.pk import PKJaxSolver, PKSolver  # noqa: E402
from conftest import rough_cell  # noqa: E402



def _sphere(dx=0.3):
    shape = Paraboloid(1.0, 9.0)
    grid = shape.grid(dx)
    return grid, shape.gap(grid)


def _rough(n=32):
    return rough_cell(n, 5)


def _same(a, b, rel=1e-9):
    """Pressures to ``rel`` of the peak, the force and the gap over the cell to ``rel``."""
    assert a.converged and b.converged, (a.message, b.message)
    scale = np.abs(a.P).max()
    assert np.abs(a.P - b.P).max() <= rel * scale
    assert b.P.sum() == pytest.approx(a.P.sum(), rel=rel)
    assert np.abs(a.H - b.H).max() <= rel * max(1.0, np.abs(a.H).max())


def test_registered_and_refuses_a_bad_device():
    assert isinstance(make_solver("pk-jax", tol=1e-6, device="cpu"), PKJaxSolver)
    with pytest.raises(TengsimError, match="device"):
        PKJaxSolver(device="tpu")


@pytest.mark.parametrize("load", [None, 0.05])
def test_hertz_equals_numpy(load):
    grid, U0 = _sphere()
    pr = Problem(U0 - 3.0 + 1.0, Repulsive(), FreeKernel(grid, 1.0))
    if load is None:
        a = PKSolver(1e-9).solve(pr, State.zero(U0.shape))
        b = PKJaxSolver(1e-9, device="cpu").solve(pr, State.zero(U0.shape))
    else:
        (a, da), (b, db) = (s.solve_load(pr, load) for s in (PKSolver(1e-9), PKJaxSolver(1e-9, device="cpu")))
        assert db == pytest.approx(da, abs=1e-9)
        assert b.P.mean() == pytest.approx(load, rel=1e-12)
    _same(a, b)
    assert (b.P > 0).sum() > 10           # a contact of many pixels, not a trivial case


def test_rough_hard_wall_equals_numpy():
    grid, g0, K = _rough()
    pr = Problem(g0, Repulsive(), K)
    a = PKSolver(1e-9).solve(pr, State.zero(g0.shape))
    b = PKJaxSolver(1e-9, device="cpu").solve(pr, State.zero(g0.shape))
    _same(a, b, rel=1e-8)
    assert 0.01 < np.mean(b.P > 0) < 0.5
    assert b.H.min() > -1e-8


def test_maugis_dugdale_sphere_equals_numpy():
    """pk-jax keeps the outer zone loop (its contact solve compiled): equal to pk's outer loop to round-off, and to
    pk's default inner loop at the solver's tolerance (1e-8 ε in the gap: ∬P within 1e-6, measured 4e-9); pk-jax
    refuses the inner loop in one line."""
    grid, U0 = _sphere()
    pr = Problem(U0, MaugisDugdale(), FreeKernel(grid, 1.0))
    a = PKSolver(1e-8, zone="outer").solve(pr, State.zero(U0.shape))
    b = PKJaxSolver(1e-8, device="cpu").solve(pr, State.zero(U0.shape))
    _same(a, b, rel=1e-8)
    assert b.P.min() < 0 < b.P.max()      # tension in the zone, compression in the contact
    c = PKSolver(1e-8).solve(pr, State.zero(U0.shape))
    assert c.converged and "contact's loop" in c.message
    assert c.P.sum() == pytest.approx(b.P.sum(), rel=1e-6)
    with pytest.raises(TengsimError, match="outer fixed point only"):
        PKJaxSolver(device="cpu", zone="inner")


def test_refuses_a_smooth_law_naming_itself(tmp_path, capsys, monkeypatch):
    """`contact ... --solver pk-jax` with LJ 9-3: one line naming pk-jax (not pk) and the solver that can, exit 2,
    nothing written."""
    from tengsim.cli.main import main

    monkeypatch.chdir(tmp_path)
    rc = main(["contact", "pyramid", "--pitch", "2um", "--base", "1um", "--height", "0.7um", "--E-star", "0.59MPa",
               "--W", "54mJ/m2", "--tabor", "0.5", "--solver", "pk-jax", "--out", "x.csv"])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(err) == 1 and "solver 'pk-jax' solves hard walls only" in err[0] and "'fast'" in err[0]
    assert list(tmp_path.iterdir()) == []
