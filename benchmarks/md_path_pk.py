"""A Maugis–Dugdale path (approach and retraction with jumps) on the constrained solver 'pk' against the
range homotopy ('homotopy') and the plain L-BFGS solver ('fast') on the same grid, one run.  Not part of
the test suite.

Sphere R = 1 (units sqrt(Rε)), free kernel, Tabor μ = 1 (Maugis λ = 1.157), law ``md`` (defaults: σ0 = LJ93's
peak tension, wall k = 1000 W/ε², smoothing 0.2 ε; 'pk' solves its hard-wall limit), cell 16, D from
−2.5 to 0.5 ε in steps of 0.05 (fixed steps, bisected at jumps), tol 1e-6 ε.  Prints wall time, solves,
the pull-off ∬P / π against Maugis' P̄(λ) and the jumps of each solver, and the speed-up.

    OPENBLAS_NUM_THREADS=1 python benchmarks/md_path_pk.py --dx 0.2 --solvers pk homotopy
    OPENBLAS_NUM_THREADS=1 python benchmarks/md_path_pk.py --dx 0.2 --dx-of homotopy=0.1   # at equal pull-off error

Both solvers stop at the same residual in the same unit: 1e-6 ε (homotopy: of Eq. (9) with the penalty wall;
pk: the gap residual against the wall and the law).  'pk-jax' (the contact solve compiled with JAX)
may be added to --solvers; its first solve on a grid compiles (seconds, counted; its zone loop is the outer one).
``--pk-zone outer``: pk's zone by the outer fixed point (PKSolver(zone='outer')) instead of its contact's loop.
"""
from __future__ import annotations

import argparse
import sys
import time

import numpy as np

from tengsim import references as ref
from tengsim.continuation import PathSpec, run_path
from tengsim.kernels import FreeKernel
from tengsim.laws import MaugisDugdale
from tengsim.shapes import Paraboloid
from tengsim.solvers import make_solver

import tengsim.plugins  # noqa: F401  (registers every solver)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--dx", type=float, default=0.2)
    ap.add_argument("--mu", type=float, default=1.0)
    ap.add_argument("--cell", type=float, default=16.0)
    ap.add_argument("--solvers", nargs="+", default=["pk", "homotopy"])
    ap.add_argument("--pk-zone", choices=("inner", "outer"), default="inner",
                    help="pk's cohesive zone: in the contact's loop (default) or the outer fixed point")
    ap.add_argument("--tol", type=float, default=1e-6, help="every solver's tolerance (ε; default 1e-6)")
    ap.add_argument("--dx-of", nargs="*", default=[], metavar="SOLVER=DX",
                    help="another grid for a solver (compare at equal pull-off accuracy: e.g. homotopy=0.1)")
    args = ap.parse_args(argv)
    dx_of = {k: float(v) for k, v in (a.split("=") for a in args.dx_of)}
    law = MaugisDugdale()
    shape = Paraboloid(1.0, args.cell)
    lam = ref.md_lambda(1.0, args.mu ** -1.5, 1.0, law.tension)
    md = ref.maugis_dugdale_pulloff(lam)
    spec = PathSpec(-2.0 * args.mu - 0.5, 0.5, 0.05)
    rows = []
    for name in args.solvers:
        grid = shape.grid(dx_of.get(name, args.dx))
        kernel = FreeKernel(grid, args.mu ** 1.5)
        solver = make_solver(name, tol=args.tol, **({"zone": args.pk_zone} if name == "pk" else
                                                    {} if name.startswith("pk") else {"max_iter": 20000}))
        t = time.perf_counter()
        res = run_path(shape.gap(grid), law, kernel, solver, spec)
        dt = time.perf_counter() - t
        po = -3.0 * res.pull_off_force  # ∬P at pull-off / π (force = ∬P / 3π)
        rows.append((name, dt, res.all_converged, po, len(res.jumps), f"{grid.nx}² (dx {dx_of.get(name, args.dx)})"))
        print(f"{name}: {dt:.1f} s, converged {res.all_converged}, pull-off ∬P/π = {po:.4f} "
              f"(Maugis {md:.4f}, {100 * (po / md - 1):+.1f} %), {len(res.jumps)} jumps", flush=True)
    base = {r[0]: r[1] for r in rows}
    print(f"\n| solver | grid | time (s) | all converged | pull-off ∬P/π (Maugis {md:.4f}) | jumps | time / pk |")
    print("|---|---|---|---|---|---|---|")
    for name, dt, ok, po, nj, g in rows:
        ratio = dt / base["pk"] if "pk" in base else np.nan
        print(f"| {name} | {g} | {dt:.1f} | {ok} | {po:.4f} ({100 * (po / md - 1):+.1f} %) | {nj} | {ratio:.1f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
