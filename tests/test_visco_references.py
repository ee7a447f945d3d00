"""The viscoelastic drive against closed forms (docs/viscoelastic.md, docs/validation.md "Viscoelastic contact").

A paraboloid on the free half-space, R = 0.025, κ_ref = 10 at E_ref = E∞ (E*_∞ = 0.1), the Repulsive wall,
a standard linear solid E(t) = E∞ + E1 e^{−t/τ} with E1 = E∞ (E0 = 2 E∞), τ = 1.  Indentations of hundreds of
ε (a ≈ 2–3) keep the soft wall's own compliance below 0.2 % of the force (the Hertz checks of
test_engine_elastic.py use δ = D − H(apex) for the same reason).  Default tests on dx = 0.2 (45² points);
the converged-grid versions (dx = 0.1) are slow.
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np
import pytest

from tengsim.run.plan import ContactPlan
from tengsim import PathSpec, simulate
from tengsim.laws import LJ93, Repulsive
from tengsim.references import hertz_force
from tengsim.references.viscoelastic import lee_radok_radius, ting_triangle_force
from tengsim.relaxation import Prony, sls, sls_creep
from tengsim.shapes import Paraboloid
from tengsim.visco import FixedTimeSteps, GeometricTimeSteps, History, ramp_hold, simulate_history, triangle

R, KAPPA, TAU = 0.025, 10.0, 1.0
MAT = sls(1.0, 1.0, TAU)                     # E0 = 2 E∞; moduli relative to E_ref = E∞
E_STAR = 1 / KAPPA                            # E*_∞ of the reference kernel
SHAPE = Paraboloid(R, 9.0)
TABOR = KAPPA ** (2 / 3)


def run(history, steps, dx=0.2, material=MAT, law=None, maps_at=(), solver="fast", **kw):
    return simulate_history(SHAPE, TABOR, dx, material, history, steps, law=law or Repulsive(), tol=1e-5,
                            maps_at=maps_at, solver=solver, **kw)


def apex_indentation(res, dx):
    """δ = D − H(apex) at each kept map's time (the rigid indentation, the wall's compression removed)."""
    c = SHAPE.grid(dx).nx // 2
    out = {}
    for tm, (t, P, H) in res.maps.items():
        i = int(np.argmin(np.abs(res.t - t)))
        out[tm] = (t, res["D"][i] - H[c, c])
    return out


# ---- relaxation under a held indentation: F(t) = (4/3) E(t) R^{1/2} δ^{3/2} --------------------------------
@lru_cache(maxsize=None)
def relaxation_run(dx):
    return run(ramp_hold(0.0, 300.0, 0.0, 5.0), GeometricTimeSteps(0.01, 1.3, 0.5), dx)


@pytest.mark.parametrize("dx", [0.2, pytest.param(0.1, marks=pytest.mark.slow)])
def test_relaxation_under_held_indentation(dx):
    res = relaxation_run(dx)
    assert res.ok
    hold = res.t > 0
    c = SHAPE.grid(dx).nx // 2
    F = res["F"][hold] * 3 * np.pi                # ∬ P dA (Eq. 10 has 1/3π)
    Et = MAT.relaxation(res.t[hold]) * E_STAR
    # the indentation at the first hold step stands for the whole hold (the wall's compression changes < 0.1 ε)
    ref = hertz_force(300.0, R, 1.0) * Et
    assert np.max(np.abs(F / ref - 1)) < 0.01
    assert F[-1] / F[0] == pytest.approx(Et[-1] / Et[0], rel=0.003)


# ---- Lee–Radok: a step load held, a(t)³ = (3RP0/4) J(t) -------------------------------------------------------
P_MEAN = 150.0 / 81.0                         # mean pressure over the 9×9 cell: ∬P dA = 150


@lru_cache(maxsize=None)
def creep_run(dx):
    return run(ramp_hold(0.0, P_MEAN, 0.0, 4.0, kind="pressure"), GeometricTimeSteps(0.01, 2.0, 1.0), dx,
               maps_at=(0.01, 1.0, 4.0), p_tol=1e-5, d_step=20.0)


@pytest.mark.parametrize("dx", [0.2, pytest.param(0.1, marks=pytest.mark.slow)])
def test_lee_radok_creep_under_held_load(dx):
    res = creep_run(dx)
    assert res.ok
    P0 = P_MEAN * 81.0
    assert np.all(np.abs(res["mean_pressure"][1:] / P_MEAN - 1) < 1e-5)  # the load is held
    for tm, (t, delta) in apex_indentation(res, dx).items():
        a = np.sqrt(R * delta)                # a² = R δ while the contact grows (Lee & Radok 1960)
        J = sls_creep(t, 1.0, 1.0, TAU) / E_STAR
        assert a == pytest.approx(float(lee_radok_radius(P0, R, J)), rel=0.01), t
    d = apex_indentation(res, dx)
    ratio = (d[4.0][1] / d[0.01][1]) ** 1.5   # a³(t)/a³(0+) = J(t)/J(0+): the grid's error cancels
    assert ratio == pytest.approx(sls_creep(d[4.0][0], 1, 1, TAU) / sls_creep(d[0.01][0], 1, 1, TAU), rel=0.003)


# ---- Ting: loading then unloading, the maximum-history rule ------------------------------------------------------
@lru_cache(maxsize=None)
def ting_run(dx):
    return run(triangle(0.0, 360.0, 1.0, 1.0), FixedTimeSteps(0.05), dx)


@pytest.mark.parametrize("dx", [0.2, pytest.param(0.1, marks=pytest.mark.slow)])
def test_ting_loading_then_unloading(dx):
    """D 0 → 360 ε in 1 τ, then back at the same rate to 0 (the contact shrinks, then is lost): during the
    unloading the force is Ting's, the contact radius the one of the loading time t1(t) (within 2 %)."""
    res = ting_run(dx)
    assert res.ok
    F = res["F"] * 3 * np.pi
    ref = ting_triangle_force(res.t, R, 360.0, 1.0, 360.0, E_STAR, E_STAR, TAU)
    up = (res.t > 0.2) & (res.t <= 1.0)
    down = (res.t > 1.0) & (ref > 0.1 * ref.max())    # while the contact carries ≥ 10 % of the peak force
    assert down.sum() >= 5
    assert np.max(np.abs(F[up] / ref[up] - 1)) < 0.02
    assert np.max(np.abs(F[down] / ref[down] - 1)) < 0.02
    # the rule matters: a force from the current indentation alone (the elastic answer at E∞ … E0) misses it
    naive = hertz_force(res["D"][down], R, E_STAR * 2)
    assert np.max(np.abs(F[down] / naive - 1)) > 0.1
    # Ting's contact is lost before D returns to 0: the force vanishes while D > 0
    lost = res.t[(res.t > 1.0) & (F < 1e-3 * F.max())]
    assert lost.size and res["D"][np.searchsorted(res.t, lost[0])] > 10


# ---- the rate limits: a fast history is elastic at E0, a slow one at E∞ -----------------------------------------
ADH = Paraboloid(1.0, 8.0)


def static_rows(E_rel, Ds, dx=0.25):
    """The static path (tengsim.simulate) of the adhesive sphere at the modulus E_rel × E_ref."""
    tabor = (0.5 ** 1.5 / E_rel) ** (2 / 3)
    res = simulate(ContactPlan(ADH, tabor, dx, PathSpec(-1.0, 3.0, 0.25)))
    tab = res.table
    app = np.asarray(tab["branch"]) == "approach"
    cols = [np.asarray(tab[k])[app] for k in ("D", "F", "charged_fraction")]
    return {float(d): (float(f), float(a)) for d, f, a in zip(*cols) if float(d) in Ds}


@pytest.mark.parametrize("tau, E_rel", [(1e6, 2.0), (1e-6, 1.0)], ids=["fast_is_E0", "slow_is_Einf"])
def test_rate_limits_equal_the_static_solution(tau, E_rel):
    """A history of 1 s on a material with τ = 10⁶ s is the elastic run at E0; with τ = 10⁻⁶ s at E∞ (A/S and F
    within 0.5 %): adhesive LJ93 sphere, approach D = −1 → 3 ε."""
    Ds = (0.0, 1.0, 2.0, 3.0)
    mat = sls(1.0, 1.0, tau)
    hist = History((0.0, 1.0), (-1.0, 3.0))
    res = simulate_history(ADH, 0.5, 0.25, mat, hist, FixedTimeSteps(1.0 / 16), law=LJ93(), tol=1e-7)
    assert res.ok
    ref = static_rows(E_rel, Ds)
    for D in Ds:
        i = int(np.argmin(np.abs(res["D"] - D)))
        assert res["D"][i] == pytest.approx(D, abs=1e-9)
        F, A = ref[D]
        assert res["F"][i] == pytest.approx(F, rel=0.005, abs=1e-4), D
        assert res["area_fraction"][i] == pytest.approx(A, rel=0.005), D


def test_no_branches_is_the_static_path():
    """An elastic material (no branch) gives the static run's rows to the solver's tolerance."""
    Ds = (0.0, 1.0, 2.0, 3.0)
    res = simulate_history(ADH, 0.5, 0.25, Prony(1.0), History((0.0, 1.0), (-1.0, 3.0)), FixedTimeSteps(1 / 16),
                           law=LJ93(), tol=1e-7)
    ref = static_rows(1.0, Ds)
    for D in Ds:
        i = int(np.argmin(np.abs(res["D"] - D)))
        assert res["F"][i] == pytest.approx(ref[D][0], rel=1e-4, abs=1e-6)
        assert res["area_fraction"][i] == pytest.approx(ref[D][1], rel=1e-4)


def test_lee_radok_on_the_constrained_solver():
    """The same creep on 'pk' (its own load control, the hard wall: δ = D): the indentation grows as J(t)^{2/3},
    and the absolute a(t) = sqrt(R δ) is Lee–Radok's within 1 %."""
    res = run(ramp_hold(0.0, P_MEAN, 0.0, 4.0, kind="pressure"), GeometricTimeSteps(0.01, 2.0, 1.0), 0.2,
              solver="pk")
    assert res.ok
    t, D = res.t[1:], res["D"][1:]
    J = sls_creep(t, 1.0, 1.0, TAU)
    assert np.allclose((D / D[0]) ** 1.5, J / J[0], rtol=0.003)
    a = np.sqrt(R * D)
    assert np.allclose(a, lee_radok_radius(P_MEAN * 81.0, R, J / E_STAR), rtol=0.01)
