"""The slab-distributed periodic kernel and solve (issue 23, item 3): 1 against N MPI processes.

    mpiexec -n 1 python benchmarks/mpi_scaling.py --sizes 1024 2048      # the serial reference
    mpiexec -n 2 python benchmarks/mpi_scaling.py --sizes 1024 2048      # split in 2 slabs

Per size: the time of one convolution (best of --repeat, after a warm-up), the bytes each rank sends per
convolution (the all-to-all transposes), the memory of the kernel and of the solver's arrays per rank, and
with --solve one cold equilibrium of a periodic self-affine rough surface (H 0.8, rms slope 0.1, μ 2,
D = 0.5): iterations, convolutions, seconds.  Rank 0 prints one JSON line per size.  Ratios between runs
are only meaningful on an idle machine (TENGSIM_THREADS=1 TENGSIM_FFT_WORKERS=1 OPENBLAS_NUM_THREADS=1).
"""
from __future__ import annotations

import argparse
import json
import os
import time

for k in ("OPENBLAS_NUM_THREADS", "TENGSIM_THREADS", "TENGSIM_FFT_WORKERS"):
    os.environ.setdefault(k, "1")

import numpy as np  # noqa: E402
from mpi4py import MPI  # noqa: E402

from tengsim.grid import Grid  # noqa: E402
from tengsim.kernels import PeriodicKernel  # noqa: E402
from tengsim.kernels.distributed import SlabPeriodicKernel  # noqa: E402
from tengsim.laws import LJ93  # noqa: E402
from tengsim.shapes import Rough  # noqa: E402
from tengsim.solvers import FastSolver, Problem, State  # noqa: E402
from tengsim.solvers.distributed import SlabSolver  # noqa: E402


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[1024])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--solve", action="store_true", help="also one cold equilibrium per size")
    ap.add_argument("--dx", type=float, default=0.25)
    a = ap.parse_args(argv)
    comm = MPI.COMM_WORLD
    for n in a.sizes:
        g = Grid(n, n, a.dx, a.dx)
        kappa = 2.0**1.5
        if comm.size == 1:
            K = PeriodicKernel(g, kappa)
            rows = (0, n)
        else:
            K = SlabPeriodicKernel(g, kappa, comm)
            rows = K.rows
        p = np.random.default_rng(0).standard_normal((rows[1] - rows[0], n))
        K.apply(p)
        best = np.inf
        for _ in range(a.repeat):
            comm.Barrier()
            t0 = time.perf_counter()
            K.apply(p)
            dt = comm.allreduce(time.perf_counter() - t0, op=MPI.MAX)
            best = min(best, dt)
        spec_bytes = (K._mult.nbytes if comm.size > 1 else K._spectrum.nbytes)
        row = {"n": n, "processes": comm.size, "conv_ms": 1e3 * best,
               "bytes_sent_per_conv_per_rank": getattr(K, "bytes_per_apply", 0),
               "kernel_MiB_per_rank": spec_bytes / 2**20,
               "field_MiB_per_rank": (rows[1] - rows[0]) * n * 8 / 2**20}
        if a.solve:
            shape = Rough(cell=n * a.dx, hurst=0.8, rms_slope=0.1, short_cutoff=4 * a.dx, seed=1)
            U0 = shape.gap(g)
            solver = FastSolver(tol=1e-6, max_iter=3000)
            if comm.size > 1:
                solver = SlabSolver(solver)
            comm.Barrier()
            t0 = time.perf_counter()
            eq = solver.solve(Problem(U0 - 0.5 + 1.0, LJ93(), K), State.zero(g.shape))
            row.update(solve_s=comm.allreduce(time.perf_counter() - t0, op=MPI.MAX), iterations=eq.iterations,
                       convolutions=eq.n_conv, converged=bool(eq.converged), residual=float(eq.residual),
                       F=float(eq.P.sum() * g.area))
        if comm.rank == 0:
            print(json.dumps(row), flush=True)


if __name__ == "__main__":
    main()
