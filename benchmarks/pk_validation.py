"""The constrained solver 'pk' against closed forms: the numbers of docs/validation.md, "The constrained solver
'pk'" (the same problems as tests/test_pk_solver.py, more grids).  Not part of the test suite.

    OPENBLAS_NUM_THREADS=1 python benchmarks/pk_validation.py
"""
from __future__ import annotations

import sys

import numpy as np

from tengsim import references as ref
from tengsim.grid import Grid
from tengsim.kernels import FreeKernel, PeriodicKernel
from tengsim.laws import Exponential, MaugisDugdale, Repulsive
from tengsim.shapes import Paraboloid, Sinusoid1D
from tengsim.solvers import Problem, State
from tengsim.solvers.homotopy import HomotopySolver
from tengsim.solvers.pk import PKSolver


def hertz():
    R, K = 0.1, 10.0
    for dx in (0.2, 0.1):
        shape = Paraboloid(R, 9.0)
        grid = shape.grid(dx)
        U0 = shape.gap(grid)
        st = State.zero(U0.shape)
        for D in (60.0, 90.0):
            eq = PKSolver(1e-8).solve(Problem(U0 - D + 1.0, Repulsive(), FreeKernel(grid, K)), st)
            st = eq.state
            F = eq.P.sum() * grid.area
            a = np.sqrt((eq.P > 0).sum() * grid.area / np.pi)
            print(f"| Hertz, free, dx {dx}, δ = {D:g} ε | force {100 * (F / ref.hertz_force(D, R, 1 / K) - 1):+.3f} %, "
                  f"radius (area) {100 * (a / ref.hertz_contact_radius(D, R) - 1):+.2f} % | {eq.iterations} |")


def westergaard():
    WL, AMP = 20.0, 200.0
    kap = np.pi * AMP / WL
    for n in (200, 400):
        grid = Grid(n, 4, WL / n, WL / n)
        U0 = Sinusoid1D(WL, AMP).gap(grid)
        K = PeriodicKernel(grid, kap)
        for D in (120.0, 150.0, 180.0):
            eq = PKSolver(1e-8).solve(Problem(U0 - D + 1.0, Repulsive(), K), State.zero(U0.shape))
            pm = eq.P.mean()
            a = (eq.P[:, 0] > 0).sum() * grid.dx / 2
            pref = ref.westergaard_pressure(grid.x, pm, WL, AMP, 1 / kap)
            print(f"| Westergaard partial, {n} px, p̄/p* = {pm:.3f} | half-width "
                  f"{100 * (a / ref.westergaard_contact_half_width(pm, WL, AMP, 1 / kap) - 1):+.2f} %, profile L∞ "
                  f"{100 * np.abs(eq.P[:, 0] - pref).max() / pref.max():.2f} % of peak | {eq.iterations} |")
        eq, _ = PKSolver(1e-10).solve_load(Problem(U0 + 1.0, Repulsive(), K), 1.5)
        pref = ref.westergaard_pressure(grid.x, 1.5, WL, AMP, 1 / kap)
        print(f"| Westergaard full (load control), {n} px, p̄/p* = 1.5 | profile L∞ "
              f"{np.abs(eq.P[:, 0] - pref).max() / 1.5:.1e} of p̄ | {eq.iterations} |")


def md_reference(D):
    lam = ref.md_lambda(1.0, 1.0, 1.0, MaugisDugdale().tension)
    sc = ref.md_scales(1.0, 1.0, 1.0)
    cur = ref.maugis_dugdale_curve(lam, A_max=4.0, n=2000)
    d = D / sc.indentation
    i = np.flatnonzero(np.diff(np.sign(cur.D - d)))[-1]
    return float(np.interp(d, cur.D[i:i + 2], cur.P[i:i + 2])) * sc.force


def maugis():
    for dx in (0.2, 0.1, 0.05):
        shape = Paraboloid(1.0, 16.0)
        grid = shape.grid(dx)
        U0 = shape.gap(grid)
        K = FreeKernel(grid, 1.0)
        for zone in ("ramp", "sharp"):
            st, errs, its = State.zero(U0.shape), [], 0
            for D in (0.0, 0.5, 1.0):
                eq = PKSolver(1e-7, md_zone=zone).solve(Problem(U0 - D + 1.0, MaugisDugdale(), K), st)
                st, its = eq.state, its + eq.iterations
                errs.append(100 * (eq.P.sum() * grid.area / md_reference(D) - 1))
            print(f"| Maugis–Dugdale sphere μ = 1 (λ = 1.157), free, dx {dx}, zone {zone} | ∬P at D = 0, 0.5, 1 ε: "
                  + ", ".join(f"{e:+.1f} %" for e in errs) + f" | {its} |")


def exponential():
    shape = Paraboloid(1.0, 16.0)
    grid = shape.grid(0.1)
    U0 = shape.gap(grid)
    prob = Problem(U0 - 0.5 + 1.0, Exponential(), FreeKernel(grid, 1.0))
    eq = PKSolver(1e-7).solve(prob, State.zero(U0.shape))
    h = HomotopySolver(1e-6, max_iter=20000).solve(prob, State.zero(U0.shape))
    print(f"| exponential sphere μ = 1, free, dx 0.1, D = 0.5 ε | ∬P {100 * (eq.P.sum() / h.P.sum() - 1):+.2f} % from "
          f"the homotopy solver's (wall k = 1000 W/ε²) | {eq.iterations} |")


def main():
    print("| case | pk against the reference | iterations |\n|---|---|---|")
    hertz()
    westergaard()
    maugis()
    exponential()
    return 0


if __name__ == "__main__":
    sys.exit(main())
