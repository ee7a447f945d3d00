"""The constrained solver 'pk' (tengsim.solvers.pk): Polonsky–Keer's constrained CG for the hard wall and
its cohesive extension, against closed forms (Hertz, Westergaard, Maugis–Dugdale) and against the
L-BFGS solver with a stiffening penalty wall on a rough periodic cell.  Measured values:
docs/validation.md, "The constrained solver 'pk'"."""
from __future__ import annotations

from functools import lru_cache

import numpy as np
import pytest

from tengsim import references as ref
from tengsim.errors import TengsimError
from tengsim.grid import Grid
from tengsim.kernels import FreeKernel, PeriodicKernel
from tengsim.laws import LJ93, Exponential, MaugisDugdale, Repulsive
from conftest import rough_cell
from tengsim.shapes import Paraboloid, Sinusoid1D
from tengsim.solvers import FastSolver, Problem, State, make_solver
from tengsim.solvers.pk import PKSolver

import tengsim.plugins  # noqa: F401  (registers 'pk')


def test_registered_and_refuses_smooth_repulsion():
    """'pk' is a registered solver; LJ93 (no wall) is refused in one line naming the solvers that can."""
    s = make_solver("pk", tol=1e-6)
    assert isinstance(s, PKSolver)
    grid = Grid(8, 8, 0.5, 0.5)
    with pytest.raises(TengsimError, match="use solver 'fast'"):
        s.solve(Problem(np.full((8, 8), 2.0), LJ93(), FreeKernel(grid, 1.0)), State.zero((8, 8)))
    with pytest.raises(TengsimError, match="md_zone"):
        PKSolver(md_zone="soft")


# ---- Hertz: R = 0.1, κ = 10 (E* = 0.1), free kernel, dx = 0.1 ------------------------------------------
R_H, K_H = 0.1, 10.0


@pytest.mark.parametrize("D", [60.0, 90.0])
def test_hertz_sphere(D):
    """Force within 0.3 % of (4/3)E*R^½δ^{3/2} (measured 0.009 %, 0.006 %), contact radius from the
    contact area within 1.5 % of sqrt(Rδ) (measured 0.36 %, 0.46 %: the pixelated disc), no overlap."""
    shape = Paraboloid(R_H, 9.0)
    grid = shape.grid(0.1)
    U0 = shape.gap(grid)
    eq = PKSolver(1e-8).solve(Problem(U0 - D + 1.0, Repulsive(), FreeKernel(grid, K_H)), State.zero(U0.shape))
    assert eq.converged, eq.message
    delta = D  # the wall at g = 1: the apex touches at D = 0
    F = eq.P.sum() * grid.area
    assert F == pytest.approx(ref.hertz_force(delta, R_H, 1 / K_H), rel=3e-3)
    a = np.sqrt((eq.P > 0).sum() * grid.area / np.pi)
    assert a == pytest.approx(ref.hertz_contact_radius(delta, R_H), rel=0.015)
    assert eq.H.min() > -1e-7 and eq.P.min() >= 0.0


# ---- Westergaard: λ = 20, Δ = 200, κ = πΔ/λ (p* = 1), periodic strip ---------------------------------
WL, AMP = 20.0, 200.0
K_W = np.pi * AMP / WL


def _strip(n):
    grid = Grid(n, 4, WL / n, WL / n)
    return grid, Sinusoid1D(WL, AMP).gap(grid), PeriodicKernel(grid, K_W)


@pytest.mark.parametrize("D", [120.0, 150.0, 180.0])
def test_westergaard_partial_contact(D):
    """Displacement control, partial contact: the half-width within 1 % of a(p̄) (Johnson 13.12; measured
    0.05–0.2 % at 400 pixels) and the profile within 1.5 % of the peak of Westergaard's p(x)."""
    grid, U0, K = _strip(400)
    eq = PKSolver(1e-8).solve(Problem(U0 - D + 1.0, Repulsive(), K), State.zero(U0.shape))
    assert eq.converged, eq.message
    pm = eq.P.mean()
    assert 0.05 < pm < 0.95
    a = (eq.P[:, 0] > 0).sum() * grid.dx / 2
    assert a == pytest.approx(ref.westergaard_contact_half_width(pm, WL, AMP, 1 / K_W), rel=0.01)
    pref = ref.westergaard_pressure(grid.x, pm, WL, AMP, 1 / K_W)
    assert np.max(np.abs(eq.P[:, 0] - pref)) < 0.015 * pref.max()


def test_westergaard_full_contact_under_load():
    """Load control above p* = πE*Δ/λ: full contact, p = p̄ + p* cos(2πx/λ) (Johnson 13.10) to 1e-6; under
    displacement control the same cell at a mean gap below the wall has no state and says so."""
    grid, U0, K = _strip(64)
    pm = 1.5
    eq, dD = PKSolver(1e-10).solve_load(Problem(U0 + 1.0, Repulsive(), K), pm)
    assert eq.converged, eq.message
    assert (eq.P > 0).all() and np.abs(eq.H).max() < 1e-8
    pref = ref.westergaard_pressure(grid.x, pm, WL, AMP, 1 / K_W)
    assert np.max(np.abs(eq.P[:, 0] - pref)) < 1e-6 * pm
    assert dD > 0
    bad = PKSolver().solve(Problem(U0 - 300.0 + 1.0, Repulsive(), K), State.zero(U0.shape))
    assert not bad.converged and "load control" in bad.message


# ---- Maugis–Dugdale sphere: R = 1, μ = 1 (λ = 1.157), free kernel --------------------------------------
@lru_cache(maxsize=None)
def _md_states(dx, zone="ramp", loop="inner"):
    shape = Paraboloid(1.0, 16.0)
    grid = shape.grid(dx)
    U0 = shape.gap(grid)
    K = FreeKernel(grid, 1.0)
    st, out = State.zero(U0.shape), []
    for D in (0.0, 0.5, 1.0):
        eq = PKSolver(1e-7, md_zone=zone, zone=loop).solve(Problem(U0 - D + 1.0, MaugisDugdale(), K), st)
        assert eq.converged, eq.message
        st = eq.state
        out.append((D, eq.P.sum() * grid.area))
    return out


def _md_reference(D):
    """Maugis' load at the rigid indentation D on the branch of the largest contact (MD units → ∬P)."""
    lam = ref.md_lambda(1.0, 1.0, 1.0, MaugisDugdale().tension)
    sc = ref.md_scales(1.0, 1.0, 1.0)
    cur = ref.maugis_dugdale_curve(lam, A_max=4.0, n=2000)
    d = D / sc.indentation
    i = np.flatnonzero(np.diff(np.sign(cur.D - d)))[-1]
    return float(np.interp(d, cur.D[i:i + 2], cur.P[i:i + 2])) * sc.force


@pytest.mark.parametrize("loop", ["inner", "outer"])
def test_maugis_dugdale_sphere_load_at_indentation(loop):
    """∬P at D = 0, 0.5, 1 ε on the approach within 3 % of Maugis' load at that indentation (dx = 0.1;
    measured docs/validation.md); the sharp zone (the ramp off) errs more on the same grid.  Both zone loops."""
    for (D, F), (_, Fs) in zip(_md_states(0.1, loop=loop), _md_states(0.1, "sharp", loop)):
        Fr = _md_reference(D)
        assert F == pytest.approx(Fr, rel=0.03)
        assert abs(F - Fr) < abs(Fs - Fr)


def test_exponential_sphere_matches_penalty_wall_solution():
    """Exponential law (its hard-wall limit) against the fast solver's answer with the law's stiff wall
    (k = 1000 W/ε²) on the same grid (dx = 0.2): ∬P within 1 % (measured 0.1 % at dx 0.1)."""
    shape = Paraboloid(1.0, 12.0)
    grid = shape.grid(0.2)
    U0 = shape.gap(grid)
    K = FreeKernel(grid, 1.0)
    prob = Problem(U0 - 0.5 + 1.0, Exponential(), K)
    eq = PKSolver(1e-7).solve(prob, State.zero(U0.shape))
    assert eq.converged, eq.message
    f = FastSolver(1e-6, max_iter=20000).solve(prob, eq.state)
    assert f.converged, f.message
    assert eq.P.sum() == pytest.approx(f.P.sum(), rel=0.01)


# ---- rough periodic cell: 'pk' against L-BFGS with a stiffening penalty wall ----------------------------
@lru_cache(maxsize=None)
def _rough():
    return rough_cell(64, 3)


def test_rough_cell_against_penalty_wall():
    """Hurst 0.8, 64², 30 ε rms: the fast solver with P = c g^-k, k = 9, 18, 36 against the hard wall.  At
    the same approach the mean pressure differs by the penalty wall's compression (measured 0.97, 0.43,
    0.19 %); at the fast solver's load the hard wall's mean gap lies lower by ~ln(c/p)/k (measured 0.15,
    0.066, 0.029 ε); the contact areas above a tenth of the mean contact pressure agree to a few pixels.
    The differences shrink as k doubles."""
    grid, g0, K = _rough()
    hard = PKSolver(1e-8).solve(Problem(g0, Repulsive(), K), State.zero(g0.shape))
    assert hard.converged, hard.message
    area = np.mean(hard.P > 0)
    assert 0.01 < area < 0.3
    p_t = 0.1 * hard.P[hard.P > 0].mean()
    dp, dg, da = [], [], []
    for k in (9.0, 18.0, 36.0):
        f = FastSolver(1e-6, max_iter=20000).solve(Problem(g0, Repulsive(exponent=k), K), State.zero(g0.shape))
        assert f.converged, f.message
        dp.append(abs(f.P.mean() / hard.P.mean() - 1))
        da.append(abs(np.mean(f.P > p_t) - np.mean(hard.P > p_t)))
        _, dD = PKSolver(1e-8).solve_load(Problem(g0, Repulsive(), K), float(f.P.mean()))
        dg.append(abs(dD))
    assert dp[0] < 0.02 and dg[0] < 0.3 and da[0] < 0.2 * area
    assert dp[2] < 0.6 * dp[1] < 0.36 * dp[0]
    assert dg[2] < 0.6 * dg[1] < 0.36 * dg[0]
    assert da[2] <= da[0]


# ---- design: a cohesive law with a wall runs on 'pk' and says so ------------------------------------------
class _Said:
    def __init__(self):
        self.lines = []

    def say(self, text):
        self.lines.append(text)


@pytest.mark.parametrize("law, solver, expect", [("md", None, "pk"), ("exp", None, "pk"), ("lj93", None, "fast"),
                                                 ("md", "homotopy", "homotopy")])
def test_design_chooses_pk_for_cohesive_laws(law, solver, expect):
    """`tengsim design ... --law md` (or exp) runs on 'pk' and says so in one line; LJ93 keeps the fast
    solver, and a design that names its solver keeps it."""
    from tengsim.design.plan import plan_design
    from tengsim.design.run import choose_solver

    table = {"shape": "pyramid", "pitch": "10um", "base": "5um", "height": "3.5um", "E_star": "1MPa",
             "W": "50mJ/m2", "eps": "200nm", "p_max": "100kPa", "p_step": "5kPa", "law": law}
    if solver:
        table["solver"] = solver
    plan = plan_design(table)
    said = _Said()
    from tengsim.run.plan import chosen_solver

    cplan = choose_solver(plan, plan.contact_plan, said)
    assert chosen_solver(cplan)[0] == expect  # 'auto' (LJ93) chosen on the grid solved: fast on this machine
    assert any("solver: pk" in line for line in said.lines) == (expect == "pk")


@pytest.mark.parametrize("kind", [PeriodicKernel, FreeKernel])
def test_film_kernels_against_penalty_wall(kind):
    """A film (thickness 10, ν = 0.3, bonded) under the rough cell, periodic and free: the hard wall's mean
    pressure within 0.5 % of the fast solver's with the k = 36 penalty wall (measured 0.17 %, 0.16 %: the
    half-space's 0.19 %, the penalty's compression)."""
    grid, g0, _ = _rough()
    K = kind(grid, 3.0, thickness=10.0, poisson=0.3)
    hard = PKSolver(1e-8).solve(Problem(g0, Repulsive(), K), State.zero(g0.shape))
    assert hard.converged, hard.message
    f = FastSolver(1e-6, max_iter=20000).solve(Problem(g0, Repulsive(exponent=36.0), K), State.zero(g0.shape))
    assert f.converged, f.message
    assert f.P.mean() == pytest.approx(hard.P.mean(), rel=5e-3)


def test_design_refuses_pk_for_a_smooth_law_before_anything_runs(tmp_path, capsys, monkeypatch):
    """`design ... --solver pk` with LJ 9-3: the solver's own one line, exit 2, from the preflight (no solve, no
    progress line, nothing written)."""
    from tengsim.cli.main import main

    monkeypatch.chdir(tmp_path)
    rc = main(["design", "pyramid", "--pitch", "1um", "--base", "0.5um", "--height", "0.2um", "--E-star", "5MPa",
               "--W", "20mJ/m2", "--eps", "50nm", "--p-max", "20kPa", "--solver", "pk", "--out", "o"])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(err) == 1 and "smooth repulsion" in err[0] and "'fast'" in err[0]
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("law", [Repulsive(), MaugisDugdale()])
def test_gap_is_the_wall_on_the_contact(law):
    """Where the wall presses the gap is the wall's, g = 1 exactly (the solve leaves it within tol, of either
    sign): the charged area of a law whose peak tension starts at the wall (g <= 1) is then the contact's and
    not the solver's noise.  Sphere, dx 0.2, D = 3 ε: the charged area at tol 1e-4 and 1e-6 ε within 1 % of each
    other (measured: equal to 1e-5; before, 3.27 / 3.97 against a pressed area of 9.64 for the hard wall) and not
    below 97 % of the pressed pixels' area."""
    from tengsim.analysis import charged_area

    shape = Paraboloid(1.0, 9.0)
    grid = shape.grid(0.2)
    U0 = shape.gap(grid)
    A = []
    for tol in (1e-4, 1e-6):
        eq = PKSolver(tol).solve(Problem(U0 - 3.0 + 1.0, law, FreeKernel(grid, 1.0)), State.zero(U0.shape))
        assert eq.converged, eq.message
        pressed = int((eq.H == 0.0).sum())
        assert pressed > 20
        if isinstance(law, Repulsive):
            assert np.array_equal(eq.H == 0.0, eq.P > 0)
        A.append(charged_area(eq.H, grid, law.peak_separation, law.edge_opening))
        assert A[-1] >= 0.97 * pressed * grid.area      # (the edge placed inside its pixel pair: measured −2 %)
    assert A[0] == pytest.approx(A[1], rel=0.01)


# ---- the Maugis–Dugdale zone in the contact's loop (zone='inner', the default) against the outer fixed point ----
def test_zone_inner_matches_outer_fixed_point():
    """R = 1, μ = 1, dx 0.2, cell 9: the approach from D = −1.5 ε (no contact, the jump in) to 0.5 ε and the
    retraction to −2.5 ε (past pull-off: the jump out) in steps of 0.1 ε, each solver warm-started from its own last
    state, tol 1e-7 ε.  Where the outer loop's ramp settles (its message does not say it kept the sharp zone's state)
    the two give the same equilibrium: ∬P within 1e-5 of the largest |∬P| (measured 2e-7) and the same contact to 2
    pixels (measured 0); every solve converged, the inner one in its own loop; both jump in and out."""
    shape = Paraboloid(1.0, 9.0)
    grid = shape.grid(0.2)
    U0 = shape.gap(grid)
    K = FreeKernel(grid, 1.0)
    Ds = np.r_[np.arange(-1.5, 0.51, 0.1), np.arange(0.4, -2.51, -0.1)]
    F, touch, kept_sharp = {}, {}, []
    for zone in ("outer", "inner"):
        st, F[zone], touch[zone] = State.zero(U0.shape), [], []
        for D in Ds:
            eq = PKSolver(1e-7, zone=zone).solve(Problem(U0 - D + 1.0, MaugisDugdale(), K), st)
            assert eq.converged, eq.message
            assert zone == "outer" or "zone in the contact's loop" in eq.message, eq.message
            if zone == "outer":
                kept_sharp.append("sharp Dugdale zone" in eq.message)
            st = eq.state
            F[zone].append(eq.P.sum() * grid.area)
            touch[zone].append(eq.H == 0.0)
    same = ~np.array(kept_sharp)
    assert same.sum() > 0.8 * len(Ds)
    Fo, Fi = np.array(F["outer"]), np.array(F["inner"])
    assert np.abs(Fo - Fi)[same].max() <= 1e-5 * np.abs(Fo).max()
    assert all(int((a != b).sum()) <= 2 for a, b, s in zip(touch["outer"], touch["inner"], same) if s)
    for f in (Fo, Fi):
        jumps = np.abs(np.diff(f)) > 0.5 * np.abs(f).max()
        assert jumps[:20].sum() >= 1 and jumps[20:].sum() >= 1     # the jump in on the approach, out on retraction
    # the sharp zone (its pixels trap the contact's edge: other metastable states in the inner loop) stays outer
    eq = PKSolver(1e-7, md_zone="sharp").solve(Problem(U0 + 1.0, MaugisDugdale(), K), State.zero(U0.shape))
    assert eq.converged and "cohesive-zone updates" in eq.message


def test_zone_inner_falls_back_and_says_so(monkeypatch):
    """Where the inner loop does not converge (here: held to 3 iterations, mixed and unmixed) the solve is the outer
    fixed point's from the same start, converged, its message says so, and its n_conv counts both."""
    import tengsim.solvers.pk as pkmod

    shape = Paraboloid(1.0, 9.0)
    grid = shape.grid(0.3)
    U0 = shape.gap(grid)
    pr = Problem(U0 - 0.3 + 1.0, MaugisDugdale(), FreeKernel(grid, 1.0))
    outer = PKSolver(1e-7, zone="outer").solve(pr, State.zero(U0.shape))
    real = pkmod.zone_inner
    monkeypatch.setattr(pkmod, "zone_inner",
                        lambda conv, h, m, p, c, tol, max_iter, *a: real(conv, h, m, p, c, tol, 3, *a))
    eq = PKSolver(1e-7).solve(pr, State.zero(U0.shape))
    assert eq.converged and "outer fixed point" in eq.message and "did not settle" in eq.message
    assert np.array_equal(eq.P, outer.P)
    assert eq.n_conv > outer.n_conv
    with pytest.raises(TengsimError, match="zone must be"):
        PKSolver(zone="cg")


def test_outer_ramp_not_converged_on_a_zone_off_the_law():
    """The outer loop's ramp is converged only where every gap is within tol of the law's graph: approaching from
    D = −1.5 ε in 0.1 ε steps (dx 0.2) the no-contact state at D = −1.2 ε, the apex inside the ramp, is not an
    equilibrium (before, two clipped Anderson iterates that agreed ended the loop with P = 0 marked converged).  Every
    state the outer loop returns has P < 0 where the apex gap is within the ramp, or says it kept the sharp zone's."""
    shape = Paraboloid(1.0, 9.0)
    grid = shape.grid(0.2)
    U0 = shape.gap(grid)
    K = FreeKernel(grid, 1.0)
    st = State.zero(U0.shape)
    for D in (-1.5, -1.4, -1.3, -1.2, -1.1):
        eq = PKSolver(1e-7, zone="outer").solve(Problem(U0 - D + 1.0, MaugisDugdale(), K), st)
        st = eq.state
        assert eq.converged, eq.message
        if D > -1.25:                                  # the apex gap −D within the ramp (its end: 1.31 ε at dx 0.2)
            assert eq.P.min() < 0 or "sharp Dugdale zone" in eq.message, (D, eq.message)


def test_md_path_jumps_out_at_maugis_displacement():
    """The retraction of a displacement-controlled Maugis–Dugdale path (R = 1, μ = 1, dx 0.2, cell 16, D −2 → 0.5
    → −2 ε in 0.05 ε, tol 1e-6 ε) on pk's default inner zone loop leaves the contact at Maugis' smallest
    indentation, D = −1.734 ε (the turning point of `references.maugis_dugdale_curve`): within 2 % (measured
    −1.744 ε, 0.6 %; the outer loop, holding the sharp zone's pinned states where its ramp does not settle, leaves
    at −1.96 ε)."""
    from tengsim.continuation import PathSpec, run_path

    shape = Paraboloid(1.0, 16.0)
    grid = shape.grid(0.2)
    res = run_path(shape.gap(grid), MaugisDugdale(), FreeKernel(grid, 1.0), PKSolver(1e-6), PathSpec(-2.0, 0.5, 0.05))
    assert res.all_converged
    lam = ref.md_lambda(1.0, 1.0, 1.0, MaugisDugdale().tension)
    cur = ref.maugis_dugdale_curve(lam, A_max=4.0, n=4000)
    D_out = cur.D.min() * ref.md_scales(1.0, 1.0, 1.0).indentation
    out = [j for j in res.jumps if j.branch == "retraction" and j.F_after == 0.0]
    assert len(out) == 1
    assert out[0].D_after == pytest.approx(D_out, rel=0.02)
