"""Timing of the solvers' shared algebra (tengsim.solvers._algebra): the NumPy fast solver and the JAX solver on
the CPU, on two of benchmarks/same_iterates.py's problems (the Maugis–Dugdale sphere walked into contact and
back, a 256² rough periodic surface solved cold), CPU time, best of ``--repeat``.

    OPENBLAS_NUM_THREADS=1 python benchmarks/algebra_timing.py [--repeat 3] [--solvers fast,jax]

The JAX solver is run once before timing, so that its compilation is not counted.  Prints one line per
(problem, solver): the best CPU seconds and the iterations (the same on every repeat).

``--pk-set``: instead, the pk solver's set update after a CG step on a 512² field (the step, the projection
p >= 0, the overlapping pixels entering), as the NumPy loop writes it (in place, tengsim.solvers._pk_core) and
as an xp-generic function would (the JAX loop's selects, tengsim.solvers._pk_jax): why pk's is not shared
(docs/extending.md, "One source for each algorithm").
"""
from __future__ import annotations

import argparse
import time


def md_sphere(solver):
    from tengsim.continuation import walk_states
    from tengsim.kernels import FreeKernel
    from tengsim.laws import MaugisDugdale
    from tengsim.shapes import Paraboloid
    shape = Paraboloid(1.0, 4.0)
    grid = shape.grid(0.08)
    Ds = [0.0, 0.2, 0.4, 0.2, 0.0, -0.2, -0.4, -0.5]
    eqs = walk_states(shape.gap(grid), MaugisDugdale(smoothing=0.2), FreeKernel(grid, 1.0), solver, Ds)
    return sum(eq.iterations for _, eq in eqs)


def rough_cold(solver):
    from tengsim.grid import Grid
    from tengsim.kernels import PeriodicKernel
    from tengsim.laws import LJ93
    from tengsim.shapes import Rough
    from tengsim.solvers import Problem, State
    shape = Rough(cell=32.0, hurst=0.8, rms_height=1.0, short_cutoff=2.0, seed=3)
    grid = Grid(256, 256, 32.0 / 256, 32.0 / 256)
    U0 = shape.gap(grid)
    kernel = PeriodicKernel(grid, 0.5 ** 1.5)
    return sum(solver.solve(Problem(U0 - D + 1.0, LJ93(), kernel), State.zero(grid.shape)).iterations
               for D in (0.5, 1.5))


def solvers(names):
    from tengsim.solvers import FastSolver
    out = {}
    for name in names:
        if name == "fast":
            out[name] = (lambda tol, it: FastSolver(tol, max_iter=it))
        elif name == "jax":
            from tengsim.solvers.jax_fast import JaxSolver
            out[name] = (lambda tol, it: JaxSolver(tol, max_iter=it, device="cpu"))
        else:
            raise SystemExit(f"unknown solver {name!r} (fast, jax)")
    return out


def pk_set_update(repeat):
    import numpy as np
    n = 512 * 512
    rng = np.random.default_rng(0)
    p0, u, t = np.maximum(rng.standard_normal(n), 0.0), rng.standard_normal(n), rng.standard_normal(n)
    tau, work, S = 0.01, np.empty(n), np.empty(n, bool)

    def in_place(p):  # _pk_core.constrained_cg
        p -= tau * t
        np.maximum(p, 0.0, out=p)
        np.less(u, 0.0, out=S)
        np.logical_and(S, p == 0, out=S)
        if S.any():
            np.multiply(u, S, out=work)
            p -= tau * work

    def generic(p, xp=np):  # _pk_jax's step, with xp = numpy
        p = xp.maximum(p - tau * t, 0.0)
        enter = (u < 0) & (p == 0)
        return xp.where(enter, p - tau * u, p)

    for name, f in (("in place", in_place), ("xp-generic", generic)):
        best = float("inf")
        for _ in range(max(repeat, 5)):
            ps = [p0.copy() for _ in range(50)]
            c = time.process_time()
            for p in ps:
                f(p)
            best = min(best, (time.process_time() - c) / 50)
        print(f"pk set update 512² {name:10s} {best * 1e3:7.3f} ms CPU", flush=True)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--solvers", default="fast,jax")
    ap.add_argument("--pk-set", action="store_true", help="time pk's set update instead (NumPy only)")
    a = ap.parse_args(argv)
    if a.pk_set:
        return pk_set_update(a.repeat)
    cases = {"md_sphere": (md_sphere, 1e-7, 20000), "rough_cold": (rough_cold, 1e-6, 5000)}
    for sname, make in solvers(a.solvers.split(",")).items():
        for cname, (fn, tol, it) in cases.items():
            solver = make(tol, it)
            if sname == "jax":
                fn(solver)  # compile once, outside the timing
            best, iters = float("inf"), None
            for _ in range(a.repeat):
                t = time.process_time()
                iters = fn(solver)
                best = min(best, time.process_time() - t)
            print(f"{cname:11s} {sname:5s} {best:8.3f} s CPU  ({iters} iterations)", flush=True)


if __name__ == "__main__":
    main()
