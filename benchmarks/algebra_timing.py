"""Timing of the solvers' shared algebra (tengsim.solvers._algebra): the NumPy fast solver and the JAX solver on
the CPU, on two of benchmarks/same_iterates.py's problems (the Maugis–Dugdale sphere walked into contact and
back, a 256² rough periodic surface solved cold), CPU time, best of ``--repeat``.

    OPENBLAS_NUM_THREADS=1 python benchmarks/algebra_timing.py [--repeat 3] [--solvers fast,jax]

The JAX solver is run once before timing, so that its compilation is not counted.  Prints one line per
(problem, solver): the best CPU seconds and the iterations (the same on every repeat).
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


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--solvers", default="fast,jax")
    a = ap.parse_args(argv)
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
