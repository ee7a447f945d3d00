"""Laws stiff at the pixel scale (issue 23, item 2): iterations, convolutions and seconds per equilibrium,
the fast solver alone (capped at max_iter, the old behaviour) against the fast solver with the automatic
continuation past the cap (tengsim.continuation.persist, the new behaviour).

    OPENBLAS_NUM_THREADS=1 python benchmarks/stiff.py bump --n 64            # the README command, ε = 1 nm
    OPENBLAS_NUM_THREADS=1 python benchmarks/stiff.py rough --sizes 256 512 1024 --tabor 3 --dx 0.5
    OPENBLAS_NUM_THREADS=1 python benchmarks/stiff.py homotopy --sizes 128 256 512 1024 [--plain 128 256]

``bump``: the README's topography command (30 nm Gaussian bump, 2 µm periodic cell, E* = 1 MPa,
W = 50 mJ/m², ε = 1 nm; the height map is the one tests/test_topography.py writes, on an n² grid), the
whole approach–retraction path, once with the continuation off and once on; prints the equilibria that
stopped at the cap and the totals.  ``rough``: one cold equilibrium per size of a self-affine surface
(the ``rough`` shape: H = 0.8, rms slope 0.2, short cut-off 4 dx, seed 0, cell n dx), LJ93 law, periodic
kernel, D = ``--d`` from the highest point; prints the pixel snap number (max Φ'' × pixel compliance)
and, per method, converged, iterations, convolutions, seconds.  Each size runs in this process, one
after another: on a shared machine compare the columns of one run, not runs.  ``homotopy``: the same cold
equilibria with the 'homotopy' solver (tengsim.solvers.homotopy: laws of range 2^ℓ on grids 2^ℓ times
coarser, then the true law on the given grid); prints every stage (grid, range factor, iterations,
convolutions on its grid, seconds), the totals (iterations, convolutions, their fine-grid worth, wall),
the energy and contact area (g < g_peak) of the result and its Eq. (9) residual recomputed with the true
law; ``--plain`` sizes also get the cold fast solve (uncapped, up to ``--plain-max-iter``) for comparison.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

from tengsim.continuation import walker as continuation
from tengsim.run.plan import plan_contact
from tengsim.run.simulate import simulate as run_contact
from tengsim.kernels import make_kernel
from tengsim.laws import LJ93
from tengsim.shapes.rough import Rough
from tengsim.solvers import FastSolver, Problem, State
from tengsim.solvers.homotopy import homotopy_solve
from tengsim.status import pixel_snap_number


def write_bump(path: Path, n: int) -> None:
    x = np.linspace(-1e-6, 1e-6, n)
    X, Y = np.meshgrid(x, x, indexing="ij")
    np.savetxt(path, 30e-9 * np.exp(-(X**2 + Y**2) / (0.4e-6) ** 2))


def bump(args) -> None:
    path = Path(args.tmp) / f"bump{args.n}.txt"
    write_bump(path, args.n)
    cfg = dict(shape="topography", file=str(path), physical_size="2um,2um", E_star="1MPa", W="50mJ/m2",
               eps=args.eps, boundary="periodic")
    plan = plan_contact(cfg)
    grid = plan.shape.grid(plan.dx)
    snap = pixel_snap_number(plan.law, make_kernel("periodic", grid, plan.tabor**1.5))
    print(f"bump {args.n}², dx = {plan.dx:.3g} ε, ε = {args.eps}, pixel snap number {snap:.3g}")
    print("| method | equilibria | not converged | iterations (sum) | max per equilibrium | convolutions | seconds |")
    print("|---|---|---|---|---|---|---|")
    for label, factor in (("fast, capped (old)", 0), ("fast + continuation (new)", continuation.PERSIST_FACTOR)):
        saved = continuation.PERSIST_FACTOR
        continuation.PERSIST_FACTOR = factor
        try:
            t0 = time.perf_counter()
            res = run_contact(dict(cfg))
            sec = time.perf_counter() - t0
        finally:
            continuation.PERSIST_FACTOR = saved
        t = res.table
        its, D = np.asarray(t["iterations"], dtype=int), np.asarray(t["D"], dtype=float)
        bad = D[~np.asarray(t["converged"], dtype=bool)]
        print(f"| {label} | {len(D)} | {len(bad)} | {int(its.sum())} | {int(its.max())} "
              f"| {int(np.sum(t['n_conv']))} | {sec:.1f} |")
        if len(bad):
            print("   not converged at D =", ", ".join(f"{d:.4g}" for d in bad[:12]), "…" if len(bad) > 12 else "")
        big = its > 3000
        if big.any() and factor:
            print("   continued past the cap:", ", ".join(f"D {d:.4g}: {i}" for d, i in zip(D[big], its[big])))
        sys.stdout.flush()


def rough(args) -> None:
    law = LJ93()
    print(f"rough surfaces: H 0.8, rms slope 0.2, dx {args.dx} ε, tabor {args.tabor}, D = {args.d}, cold, "
          f"tol {args.tol}")
    print("| n | pixel snap number | fast capped: converged, iterations, conv, s | "
          "fast + continuation: converged, iterations, conv, s |")
    print("|---|---|---|---|")
    for n in args.sizes:
        shape = Rough(cell=n * args.dx, hurst=0.8, rms_slope=0.2, short_cutoff=4 * args.dx, seed=args.seed)
        grid = shape.grid(args.dx)
        kernel = make_kernel("periodic", grid, args.tabor**1.5)
        U0 = shape.gap(grid)
        problem = Problem(U0 - args.d + 1.0, law, kernel)
        snap = pixel_snap_number(law, kernel)
        fast = FastSolver(tol=args.tol)
        eq = fast.solve(problem, State.zero(U0.shape))
        old = f"{int(eq.converged)}, {eq.iterations}, {eq.n_conv}, {eq.seconds:.1f}"
        if eq.converged:
            new = "the same (converged within the cap: untouched)"
        else:
            eq2 = continuation.persist(fast, problem, eq)
            new = f"{int(eq2.converged)}, {eq2.iterations}, {eq2.n_conv}, {eq2.seconds:.1f}"
        print(f"| {n} | {snap:.3g} | {old} | {new} |")
        sys.stdout.flush()


def _rough_problem(n, args):
    shape = Rough(cell=n * args.dx, hurst=0.8, rms_slope=0.2, short_cutoff=4 * args.dx, seed=args.seed)
    grid = shape.grid(args.dx)
    kernel = make_kernel("periodic", grid, args.tabor**1.5)
    return Problem(shape.gap(grid) - args.d + 1.0, LJ93(), kernel)


def _judge(problem, eq):
    """(max|r| of Eq. (9) afresh from H with the problem's law, contact area fraction g < g_peak)."""
    g = eq.H + 1.0
    _, P = problem.law.evaluate(g)
    r = float(np.max(np.abs(g - problem.g0 - problem.kernel.apply(P))))
    return r, float(np.mean(g < problem.law.g_peak))


def homotopy(args) -> None:
    print(f"rough surfaces: H 0.8, rms slope 0.2, dx {args.dx} ε, tabor {args.tabor}, D = {args.d}, cold, "
          f"tol {args.tol}; the 'homotopy' solver (stage_tol {args.stage_tol})")
    rows = []
    for n in args.sizes:
        problem = _rough_problem(n, args)
        N = problem.g0.size
        snap = pixel_snap_number(problem.law, problem.kernel)
        print(f"{problem.g0.shape[0]}² (n {n}), pixel snap number {snap:.3g}")

        def on_stage(st):
            print(f"   stage {st.shape[0]}² s={st.s:g}: {st.iterations} iterations, {st.n_conv} conv, "
                  f"{st.seconds:.1f} s, max|r| {st.residual:.2e}", flush=True)

        fast = FastSolver(tol=args.tol, max_iter=args.max_iter)
        eq, stages = homotopy_solve(fast, problem, stage_tol=args.stage_tol, on_stage=on_stage)
        fine_eq = sum(st.n_conv * np.prod(st.shape) for st in stages) / N
        r, area = _judge(problem, eq)
        rows.append((n, problem.g0.shape[0], snap, "homotopy", eq.converged, eq.iterations, eq.n_conv, fine_eq,
                     stages[-1].iterations, eq.seconds, eq.energy, area, r))
        if n in (args.plain or ()):
            p = FastSolver(tol=args.tol, max_iter=args.plain_max_iter).solve(problem, State.zero(problem.g0.shape))
            r2, area2 = _judge(problem, p)
            rows.append((n, problem.g0.shape[0], snap, "fast (cold)", p.converged, p.iterations, p.n_conv,
                         p.n_conv, p.iterations, p.seconds, p.energy, area2, r2))
        print("| grid | snap | method | converged | iterations (all stages) | convolutions | fine-grid worth | "
              "last stage's iterations | wall s | E (dimensionless) | area (g < g_peak) | Eq. (9) max|r| |")
        print("|---|---|---|---|---|---|---|---|---|---|---|---|")
        for (n_, m, sn, what, ok, it, nc, fe, last, sec, E, a, rr) in rows:
            print(f"| {m}² | {sn:.3g} | {what} | {'yes' if ok else 'no'} | {it} | {nc} | {fe:.0f} | {last} | "
                  f"{sec:.1f} | {E:.7g} | {a:.4f} | {rr:.1e} |")
        sys.stdout.flush()


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="what", required=True)
    b = sub.add_parser("bump")
    b.add_argument("--n", type=int, default=64)
    b.add_argument("--eps", default="1nm")
    b.add_argument("--tmp", default="/tmp")
    r = sub.add_parser("rough")
    r.add_argument("--sizes", type=int, nargs="+", default=[256, 512, 1024])
    r.add_argument("--dx", type=float, default=0.5)
    r.add_argument("--tabor", type=float, default=3.0)
    r.add_argument("--d", type=float, default=0.5)
    r.add_argument("--tol", type=float, default=1e-6)
    r.add_argument("--seed", type=int, default=0)
    h = sub.add_parser("homotopy")
    h.add_argument("--sizes", type=int, nargs="+", default=[128, 256, 512, 1024])
    h.add_argument("--plain", type=int, nargs="*", default=[], help="sizes that also get the cold fast solve")
    h.add_argument("--plain-max-iter", type=int, default=40000)
    h.add_argument("--max-iter", type=int, default=30000, help="per stage")
    h.add_argument("--stage-tol", type=float, default=1e-3)
    for a in (h,):
        a.add_argument("--dx", type=float, default=0.5)
        a.add_argument("--tabor", type=float, default=3.0)
        a.add_argument("--d", type=float, default=0.5)
        a.add_argument("--tol", type=float, default=1e-6)
        a.add_argument("--seed", type=int, default=0)
    args = ap.parse_args(argv)
    {"bump": bump, "rough": rough, "homotopy": homotopy}[args.what](args)


if __name__ == "__main__":
    main()
