"""Engine checks against non-adhesive elastic references (Repulsive law = the (8/3)g⁻⁹ wall):
Hertz (paraboloid), Boussinesq flat punch, Sneddon cone (free kernel) and Westergaard's 1-D
sinusoid (periodic kernel).  E*_eff = 1/κ.

The wall is soft on the scale ε, so indentations are chosen ≫ 1 (tens of ε) and the rigid
indentation is δ = D − H(apex) (the wall's own compression at the apex is removed).  Contact radii
are taken from the second moment of the pressure, a ∝ sqrt(⟨r²⟩_P), scaled with the same moment of
the reference pressure profile (Hertz ⟨r²⟩ = 2a²/5, cone a²/3, Westergaard numerically): a smooth
measure, free of the pixel-threshold noise of "P > 0" areas.
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np
import pytest

from tengsim import references as ref
from tengsim.shapes import Cone, FlatPunch, Paraboloid, Sinusoid1D
from tengsim.grid import Grid
from tengsim.laws import Repulsive
from tengsim.kernels import FreeKernel, PeriodicKernel
from tengsim.solvers import FastSolver, Problem, State

LAW = Repulsive()
TOL = 1e-5  # see test_engine_solvers.py: FastSolver's line search stalls near 1e-6 at these loads


def _solve(U0, kernel, Ds):
    st, out = State.zero(U0.shape), []
    for D in Ds:
        eq = FastSolver(TOL).solve(Problem(U0 - D + 1.0, LAW, kernel), st)
        assert eq.converged, eq.message
        st = eq.state
        out.append(eq)
    return out


def _r2_moment(P, grid):
    X, Y = grid.mesh()
    return float((P * (X**2 + Y**2)).sum() / P.sum())


# ---------------------------------------------------------------------------------------------
# Hertz: R = 0.1, κ = 10 (E* = 0.1), D = 60, 90 → a ≈ 2.45, 3.00, p0 ≈ 1.6–1.9
# ---------------------------------------------------------------------------------------------
R_H, K_H = 0.1, 10.0


@lru_cache(maxsize=None)
def hertz(dx):
    shape = Paraboloid(R_H, 9.0)
    grid = shape.grid(dx)
    eqs = _solve(shape.gap(grid), FreeKernel(grid, K_H), (60.0, 90.0))
    c = grid.nx // 2
    out = []
    for D, eq in zip((60.0, 90.0), eqs):
        delta = D - eq.H[c, c]
        F = eq.P.sum() * grid.area
        a = np.sqrt(2.5 * _r2_moment(eq.P, grid))
        out.append((delta, F, a))
    return out


def test_hertz_force_and_radius():
    """dx = 0.1: ∬P within 1 % of (4/3)E*R^½δ^{3/2}; radius within 2 % of sqrt(Rδ) and of (3FR/4E*)^⅓."""
    for delta, F, a in hertz(0.1):
        assert F == pytest.approx(ref.hertz_force(delta, R_H, 1 / K_H), rel=0.01)
        assert a == pytest.approx(ref.hertz_contact_radius(delta, R_H), rel=0.02)
        assert a == pytest.approx(ref.hertz_contact_radius_from_force(F, R_H, 1 / K_H), rel=0.02)


def test_hertz_force_error_decreases_with_dx():
    """Force error at D = 90 for dx = 0.4, 0.2, 0.1 decreases monotonically (0.42 %, 0.37 %, 0.35 %;
    the floor is the wall's finite range, not the grid)."""
    errs = []
    for dx in (0.4, 0.2, 0.1):
        delta, F, _ = hertz(dx)[1]
        errs.append(abs(F / ref.hertz_force(delta, R_H, 1 / K_H) - 1))
    assert errs[0] > errs[1] > errs[2]
    # and the grid part of the error (against dx = 0.1) roughly halves or better per halving
    F = [hertz(dx)[1][1] for dx in (0.4, 0.2, 0.1)]
    assert abs(F[1] - F[2]) < 0.6 * abs(F[0] - F[2])


def test_hertz_larger_indentation_is_more_accurate():
    """The soft-wall error shrinks as δ/ε grows (D = 60 → 90)."""
    (d1, F1, _), (d2, F2, _) = hertz(0.1)
    e1 = abs(F1 / ref.hertz_force(d1, R_H, 1 / K_H) - 1)
    e2 = abs(F2 / ref.hertz_force(d2, R_H, 1 / K_H) - 1)
    assert e2 < e1


# ---------------------------------------------------------------------------------------------
# Flat punch: a = 2, κ = 10
# ---------------------------------------------------------------------------------------------

@pytest.mark.parametrize("dx", [0.1, 0.05])
def test_flat_punch_force_and_stiffness(dx):
    """F = 2aE*δ within 1 % at D = 40, 60; stiffness dF/dδ within 1.5 % (pixelated disc area: 0.5 %)."""
    a, kappa = 2.0, 10.0
    shape = FlatPunch(a, 6.0, 200.0)
    grid = shape.grid(dx)
    Ds = (40.0, 60.0)
    eqs = _solve(shape.gap(grid), FreeKernel(grid, kappa), Ds)
    c = grid.nx // 2
    F = [eq.P.sum() * grid.area for eq in eqs]
    d = [D - eq.H[c, c] for D, eq in zip(Ds, eqs)]
    for f, dd in zip(F, d):
        assert f == pytest.approx(ref.flat_punch_force(dd, a, 1 / kappa), rel=0.01)
    k = (F[1] - F[0]) / (d[1] - d[0])
    assert k == pytest.approx(2 * a / kappa, rel=0.015)


# ---------------------------------------------------------------------------------------------
# Sneddon cone: slope tanθ = 10, κ = 10
# ---------------------------------------------------------------------------------------------

def test_sneddon_cone_force_and_radius():
    """Cone at D = 45, 60 (a ≈ 2.9, 3.8): F within 2 % of (2/π)E*δ²/tanθ, radius within 2 %."""
    kappa, slope = 10.0, 10.0
    theta = np.arctan(slope)
    shape = Cone(slope, 12.0)
    grid = shape.grid(0.1)
    Ds = (45.0, 60.0)
    eqs = _solve(shape.gap(grid), FreeKernel(grid, kappa), Ds)
    c = grid.nx // 2
    for D, eq in zip(Ds, eqs):
        delta = D - eq.H[c, c]
        F = eq.P.sum() * grid.area
        assert F == pytest.approx(ref.sneddon_cone_force(delta, 1 / kappa, theta), rel=0.02)
        a = np.sqrt(3.0 * _r2_moment(eq.P, grid))
        assert a == pytest.approx(ref.sneddon_cone_contact_radius(delta, theta), rel=0.02)


# ---------------------------------------------------------------------------------------------
# Westergaard: λ = 20, Δ = 200, κ = πΔ/λ (p* = 1), periodic kernel, a strip of 4 pixels in Y
# ---------------------------------------------------------------------------------------------
WL, AMP = 20.0, 200.0
K_W = np.pi * AMP / WL


@lru_cache(maxsize=None)
def westergaard(n):
    grid = Grid(n, 4, WL / n, WL / n)
    U0 = Sinusoid1D(WL, AMP).gap(grid)
    Ds = (120.0, 150.0, 180.0)  # D from the mean plane (mean U0 = Δ = 200): partial contact
    eqs = _solve(U0, PeriodicKernel(grid, K_W), Ds)
    return grid, eqs


def _x2(prof, x):
    return float((prof * x * x).sum() / prof.sum())


@pytest.mark.parametrize("n", [200, 400])
def test_westergaard_mean_pressure_vs_half_width(n):
    """p̄ = mean P against the half-width a: moment-based a within 2 % of a(p̄) (Johnson 13.12), and the
    profile within 3 % (L1) and 6 % of the peak (L∞, at the edges, rounded by the ε-range wall)
    of Westergaard's p(x)."""
    grid, eqs = westergaard(n)
    x = grid.x
    xf = np.linspace(-WL / 2, WL / 2, 200001)
    for eq in eqs:
        pm = eq.P.mean()
        assert 0.05 < pm < 0.95  # partial contact, p̄/p* in range
        a_ref = ref.westergaard_contact_half_width(pm, WL, AMP, 1 / K_W)
        prof = eq.P[:, 0]
        pref_f = ref.westergaard_pressure(xf, pm, WL, AMP, 1 / K_W)
        a_meas = a_ref * np.sqrt(_x2(prof, x) / _x2(pref_f, xf))
        assert a_meas == pytest.approx(a_ref, rel=0.02)
        pref = ref.westergaard_pressure(x, pm, WL, AMP, 1 / K_W)
        assert np.abs(prof - pref).sum() < 0.03 * pref.sum()          # L1, relative
        assert np.max(np.abs(prof - pref)) < 0.06 * pref.max()        # L∞ (edge rounding), relative to peak
        # and the inverse relation: p̄(a) from the measured a
        assert pm == pytest.approx(ref.westergaard_mean_pressure(a_meas, WL, AMP, 1 / K_W), rel=0.04)
