"""Peer benchmark: tengsim's constrained solver 'pk' against ASPHER 0.1.3 (PyPI ``aspher``; Polonsky–Keer
CG with a |q| preconditioner) on the same periodic self-affine rough surface, non-adhesive, same mean
pressure, side by side in one run.  Not part of tengsim or its test suite.

Install the peer (its source build fetches Eigen from the network; give it Debian's instead):

    apt-get install -y libeigen3-dev && pip install aspher==0.1.3

Problem (both codes, E* = 1, cell L = 1, periodic): heights h of a Gaussian self-affine surface (Hurst
0.8, wavevectors 4 ≤ |k| L/2π ≤ N/8, random phases, seed 1, rms slope 1, the same surface sampled on
every grid); a rigid flat pressed on it at mean pressure 0.05 E*.  ASPHER gets the gap max h − h;
tengsim the initial gap g0 = 1 + max h − h (wall at g = 1, hard: law ``repulsive``'s limit), its
periodic kernel 2κ/|q| with κ = 1/E* (the same compliance), and load control (``PKSolver.solve_load``).

Both solve to their own default kind of tolerance: ASPHER ``tol`` (its relative complementarity error),
tengsim ``tol`` = ``rel_tol`` × rms height (the gap residual, ε).  The table gives time (best of
``--repeat``), iterations, contact fraction of each and their difference, and the ratio tengsim/ASPHER.
Threads: each thread count runs in its own process (``TENGSIM_FFT_WORKERS`` and ``OMP_NUM_THREADS`` set
before the imports).

    OPENBLAS_NUM_THREADS=1 python benchmarks/peer_aspher.py --sizes 256 512 1024 --threads 1 2
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time

import numpy as np


def surface(n: int, seed: int = 1, hurst: float = 0.8) -> np.ndarray:
    """Heights on n×n (L = 1): spectrum ∝ |k|^{-2(1+H)} over 4 ≤ |k| ≤ n/8 (cycles per L), rms slope 1.
    The coefficients are drawn on the 2048² reference lattice and kept for |k| ≤ n/8, so every grid
    samples the same surface up to its own cutoff."""
    rng = np.random.default_rng(seed)
    m = 2048
    k = np.fft.fftfreq(m, 1.0 / m)
    KX, KY = np.meshgrid(k, k, indexing="ij")
    K = np.hypot(KX, KY)
    amp = np.where((K >= 4) & (K <= 256), np.maximum(K, 1e-9) ** (-(1 + hurst)), 0.0)
    c = amp * np.exp(2j * np.pi * rng.random((m, m)))
    band = (np.abs(KX) <= n // 8) & (np.abs(KY) <= n // 8) & (K <= n / 8)
    c = np.where(band, c, 0.0)
    sub = np.zeros((n, n), complex)
    idx = np.r_[0:n // 2, m - n // 2:m]
    sub[:, :] = c[np.ix_(idx, idx)]
    h = np.real(np.fft.ifft2(sub)) * n * n
    kk = np.fft.fftfreq(n, 1.0 / n) * 2 * np.pi
    gx = np.real(np.fft.ifft2(1j * kk[:, None] * np.fft.fft2(h)))
    gy = np.real(np.fft.ifft2(1j * kk[None, :] * np.fft.fft2(h)))
    return h / np.sqrt(np.mean(gx**2 + gy**2))


def run_tengsim(h, p_mean, rel_tol, repeat):
    from tengsim.grid import Grid
    from tengsim.kernels import PeriodicKernel
    from tengsim.laws import Repulsive
    from tengsim.solvers import Problem
    from tengsim.solvers.pk import PKSolver

    n = h.shape[0]
    grid = Grid(n, n, 1.0 / n, 1.0 / n)
    prob = Problem(1.0 + h.max() - h, Repulsive(), PeriodicKernel(grid, 1.0))
    solver = PKSolver(tol=rel_tol * float(h.std()), max_iter=5000)
    best = cpu = None
    for _ in range(repeat):
        t, c = time.perf_counter(), time.process_time()
        eq, _dD = solver.solve_load(prob, p_mean)
        dt, dc = time.perf_counter() - t, time.process_time() - c
        best = dt if best is None else min(best, dt)
        cpu = dc if cpu is None else min(cpu, dc)
    return {"seconds": best, "cpu": cpu, "iterations": eq.iterations, "n_conv": eq.n_conv, "converged": eq.converged,
            "area": float(np.mean(eq.P > 0)), "mean_p": float(eq.P.mean()), "P": eq.P}


def run_tengsim_nested(h, p_mean, rel_tol, repeat, coarsest=64):
    """pk from the coarser grids' solutions (tengsim.solvers.multilevel.nested_solve, block prolongation, load control),
    coarsest grid ``coarsest``² as ASPHER's nested solve; every level to the fine tolerance."""
    from tengsim.grid import Grid
    from tengsim.kernels import PeriodicKernel
    from tengsim.laws import Repulsive
    from tengsim.solvers.multilevel import nested_solve
    from tengsim.solvers.pk import PKSolver

    n = h.shape[0]
    kernel = PeriodicKernel(Grid(n, n, 1.0 / n, 1.0 / n), 1.0)
    solver = PKSolver(tol=rel_tol * float(h.std()), max_iter=5000)
    best = cpu = None
    for _ in range(repeat):
        t, c = time.perf_counter(), time.process_time()
        ns = nested_solve(solver, 1.0 + h.max() - h, Repulsive(), kernel, min_size=coarsest, max_dx=1.0,
                          coarse_tol=None, coarse_max_iter=None, load=p_mean, prolong="block")
        dt, dc = time.perf_counter() - t, time.process_time() - c
        best = dt if best is None else min(best, dt)
        cpu = dc if cpu is None else min(cpu, dc)
    eq = ns.equilibrium
    return {"seconds": best, "cpu": cpu, "iterations": eq.iterations, "levels": [s.iterations for s in ns.levels],
            "n_conv_fine_equivalent": ns.fine_equivalent_conv, "converged": eq.converged,
            "area": float(np.mean(eq.P > 0)), "mean_p": float(eq.P.mean()), "P": eq.P}


def run_aspher(h, p_mean, tol, repeat):
    import aspher

    n = h.shape[0]
    gap = (h.max() - h).astype(float)
    s = aspher.ContactSolver(n, 1.0, 1.0, backend="periodic")
    best = cpu = res = None
    for _ in range(repeat):
        t, c = time.perf_counter(), time.process_time()
        res = s.solve(gap, p_mean, tol=tol, max_iter=5000, precond="fourier")
        dt, dc = time.perf_counter() - t, time.process_time() - c
        best = dt if best is None else min(best, dt)
        cpu = dc if cpu is None else min(cpu, dc)
    P = np.asarray(res.pressure).reshape(n, n)
    return {"seconds": best, "cpu": cpu, "iterations": int(res.iterations), "converged": bool(res.converged),
            "area": float(np.mean(P > 0)), "mean_p": float(P.mean()), "P": P}


def run_aspher_nested(h, p_mean, tol, repeat):
    import aspher

    n = h.shape[0]
    gap = (h.max() - h).astype(float)
    best = cpu = res = None
    for _ in range(repeat):
        t, c = time.perf_counter(), time.process_time()
        res = aspher.solve_nested(n, gap, p_mean, domain_size=1.0, E_star=1.0, coarsest=64, backend="periodic",
                                  tol=tol)
        dt, dc = time.perf_counter() - t, time.process_time() - c
        best = dt if best is None else min(best, dt)
        cpu = dc if cpu is None else min(cpu, dc)
    P = np.asarray(res.pressure).reshape(n, n)
    return {"seconds": best, "cpu": cpu, "iterations": int(res.iterations), "converged": bool(res.converged),
            "area": float(np.mean(P > 0)), "mean_p": float(P.mean())}


def child(args):
    out = []
    for n in args.sizes:
        h = surface(n)
        row = {"n": n, "threads": args.threads[0]}
        t = run_tengsim(h, args.pressure, args.rel_tol, args.repeat)
        row["pk"] = {k: v for k, v in t.items() if k != "P"}
        tn = run_tengsim_nested(h, args.pressure, args.rel_tol, args.repeat)
        row["pk_nested"] = {k: v for k, v in tn.items() if k != "P"}
        row["pk_nested"]["p_l2_vs_pk"] = float(np.linalg.norm(tn["P"] - t["P"]) / np.linalg.norm(t["P"]))
        try:
            a = run_aspher(h, args.pressure, args.aspher_tol, args.repeat)
            row["aspher"] = {k: v for k, v in a.items() if k != "P"}
            row["p_l2"] = float(np.linalg.norm(t["P"] - a["P"]) / np.linalg.norm(a["P"]))
            row["nested"] = run_aspher_nested(h, args.pressure, args.aspher_tol, args.repeat)
        except ImportError as exc:
            row["aspher"] = {"error": f"not installed ({exc})"}
        out.append(row)
        print(json.dumps(row), flush=True)
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[256, 512, 1024])
    ap.add_argument("--threads", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--pressure", type=float, default=0.05, help="mean pressure, units of E*")
    ap.add_argument("--rel-tol", type=float, default=1e-6, help="tengsim's gap residual / rms height")
    ap.add_argument("--aspher-tol", type=float, default=1e-8, help="ASPHER's tol")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.child:
        child(args)
        return 0
    rows = []
    for th in args.threads:
        env = dict(os.environ, TENGSIM_FFT_WORKERS=str(th), TENGSIM_THREADS=str(th), OMP_NUM_THREADS=str(th),
                   OPENBLAS_NUM_THREADS="1")
        cmd = [sys.executable, __file__, "--child", "--threads", str(th), "--sizes", *map(str, args.sizes),
               "--pressure", str(args.pressure), "--rel-tol", str(args.rel_tol), "--aspher-tol",
               str(args.aspher_tol), "--repeat", str(args.repeat)]
        got = subprocess.run(cmd, env=env, capture_output=True, text=True)
        if got.returncode:
            print(got.stderr, file=sys.stderr)
            return got.returncode
        rows += [json.loads(line) for line in got.stdout.splitlines() if line.startswith("{")]
    print("CPU seconds (best of --repeat; wall in the JSON rows); iterations; nested: the finest level's")
    print("| grid | threads | ASPHER (its.) | ASPHER nested (finest its.) | pk (its., convolutions) | pk nested (its. "
          "per level) | pk / ASPHER | pk nested / ASPHER nested | contact fraction ASPHER / pk / pk nested | "
          "pressure L2 diff pk−ASPHER, nested−pk |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        pk, a, pn = r["pk"], r["aspher"], r["pk_nested"]
        if "error" in a:
            print(f"| {r['n']}² | {r['threads']} | {a['error']} | — | {pk['cpu']:.3g} ({pk['iterations']}, "
                  f"{pk['n_conv']}) | {pn['cpu']:.3g} ({'/'.join(map(str, pn['levels']))}) | — | — | "
                  f"— / {pk['area']:.4f} / {pn['area']:.4f} | —, {pn['p_l2_vs_pk']:.1e} |")
            continue
        ne = r["nested"]
        print(f"| {r['n']}² | {r['threads']} | {a['cpu']:.3g} ({a['iterations']}) | {ne['cpu']:.3g} "
              f"({ne['iterations']}) | {pk['cpu']:.3g} ({pk['iterations']}, {pk['n_conv']}) | {pn['cpu']:.3g} "
              f"({'/'.join(map(str, pn['levels']))}) | {pk['cpu'] / a['cpu']:.2f} | {pn['cpu'] / ne['cpu']:.2f} | "
              f"{a['area']:.4f} / {pk['area']:.4f} / {pn['area']:.4f} | {r['p_l2']:.1e}, {pn['p_l2_vs_pk']:.1e} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
