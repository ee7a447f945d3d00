"""The hard-wall rough contact of benchmarks/peer_aspher.py's kind on 'pk' (NumPy) and 'pk-jax' (the contact solve
compiled with JAX, float64, JAX's default device), one run: wall time of a solve (pk-jax: after its compilation,
reported apart), iterations, and the agreement of the two (contact area, largest pressure difference).  Not part
of the test suite.

    OPENBLAS_NUM_THREADS=1 python benchmarks/pk_jax_rough.py --n 256 512
"""
from __future__ import annotations

import argparse
import sys
import time

import numpy as np

from tengsim.grid import Grid
from tengsim.kernels import PeriodicKernel
from tengsim.laws import Repulsive
from tengsim.solvers import Problem, State
from tengsim.solvers.pk import PKJaxSolver, PKSolver


def rough(n, seed=1):
    """Hurst 0.8 self-affine surface on n², 30 ε rms, the wall 70 ε below the highest summit."""
    rng = np.random.default_rng(seed)
    k = np.fft.fftfreq(n, 1.0 / n)
    kk = np.hypot(*np.meshgrid(k, k, indexing="ij"))
    c = np.where((kk >= 2) & (kk <= n / 4), np.maximum(kk, 1e-9) ** -1.8, 0.0)
    c = c * np.exp(2j * np.pi * rng.random((n, n)))
    h = np.real(np.fft.ifft2(c))
    h *= 30.0 / h.std()
    grid = Grid(n, n, 1.0, 1.0)
    return h.max() - h - 70.0 + 1.0, PeriodicKernel(grid, 3.0)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, nargs="+", default=[256])
    ap.add_argument("--tol", type=float, default=1e-6)
    args = ap.parse_args(argv)
    print("| grid | pk (s) | pk-jax compile + first (s) | pk-jax (s) | pk / pk-jax | iterations pk / pk-jax | "
          "area | max |ΔP| / max P |")
    print("|---|---|---|---|---|---|---|---|")
    for n in args.n:
        g0, K = rough(n)
        pr, z = Problem(g0, Repulsive(), K), State.zero(g0.shape)
        t = time.perf_counter()
        a = PKSolver(args.tol).solve(pr, z)
        t_np = time.perf_counter() - t
        js = PKJaxSolver(args.tol)
        t = time.perf_counter()
        js.solve(pr, z)
        t_first = time.perf_counter() - t
        t = time.perf_counter()
        b = js.solve(pr, z)
        t_jax = time.perf_counter() - t
        dP = float(np.abs(a.P - b.P).max() / a.P.max())
        print(f"| {n}² | {t_np:.2f} | {t_first:.2f} | {t_jax:.2f} | {t_np / t_jax:.2f} | {a.iterations} / {b.iterations} "
              f"| {np.mean(b.P > 0):.4f} | {dP:.1e} |", flush=True)
        assert a.converged and b.converged, (a.message, b.message)
    return 0


if __name__ == "__main__":
    sys.exit(main())
