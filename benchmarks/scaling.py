"""Scaling study of tengsim's fast solver (issue 6): one equilibrium on a periodic random rough
surface at n² = 256² … 4096², time and peak memory, and the fitted growth.

    OPENBLAS_NUM_THREADS=1 python benchmarks/scaling.py --sizes 256 512 1024 2048 --out benchmarks/results

tengsim's FFT threading rule applies (1 thread below 512² points, all cores from 512² up);
TENGSIM_FFT_WORKERS forces a count and is recorded in ``scaling.md``.

The surface is statistically the same at every size: fixed pixel dx (in ε), so the cell grows
with n (L = n·dx); a self-affine power spectrum C(q) ∝ q^{-2(1+H)} between a roll-off wavelength
λr and a short cutoff λs (both fixed in ε), random phases from a fixed seed, rms height h_rms.
U0 = max(h) − h, periodic kernel (μ^{3/2} · 2/|q|), LJ 8-2 law, μ = 0.5.  D is set so that a fixed
fraction of the surface overlaps rigidly (U0 < D): the contact state is comparable across sizes.

Per size, in a fresh subprocess (so peak memory is that size's alone):
* a cold equilibrium at D0 from the undeformed state, then a warm one at D0 + ΔD (the
  per-step cost on a path);
* convolutions per equilibrium, time of one convolution, peak RSS (resource.getrusage).
The growth exponent is the least-squares slope of log(time) against log(n²) (n² log n gives a
slope just above 1).
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent


def rough_surface(n, dx, hurst=0.8, lam_r=16.0, lam_s=2.0, h_rms=1.0, seed=0):
    """Periodic self-affine surface on an n × n grid of pixel dx (NumPy only, fixed seed)."""
    rng = np.random.default_rng(seed)
    L = n * dx
    qx = 2 * np.pi * np.fft.fftfreq(n, d=dx)
    qy = 2 * np.pi * np.fft.rfftfreq(n, d=dx)
    q = np.hypot(qx[:, None], qy[None, :])
    qr, qs = 2 * np.pi / lam_r, 2 * np.pi / lam_s
    amp = np.where(q > 0, np.maximum(q, qr) ** (-(1 + hurst)), 0.0)
    amp[q > qs] = 0.0
    spec = amp * np.exp(2j * np.pi * rng.random(amp.shape))
    h = np.fft.irfft2(spec, s=(n, n))
    h *= h_rms / h.std()
    del spec, amp, q
    return h, L


def one_size(n, dx, mu, tol, overlap, dD, seed):
    from tengsim.grid import Grid
    from tengsim.interaction import LJ93
    from tengsim.kernels import make_kernel
    from tengsim.solvers import Problem, State, make_solver

    t_setup = time.perf_counter()
    h, L = rough_surface(n, dx, seed=seed)
    grid = Grid(n, n, dx, dx)
    slope = float(np.sqrt(np.mean(np.gradient(h, dx, axis=0) ** 2 + np.gradient(h, dx, axis=1) ** 2)))
    U0 = h.max() - h
    del h
    D0 = float(np.quantile(U0, overlap))
    kernel = make_kernel("periodic", grid, mu ** 1.5)
    law = LJ93()
    solver = make_solver("fast", tol=tol)
    t_setup = time.perf_counter() - t_setup
    # one convolution
    p = np.random.default_rng(1).standard_normal((n, n))
    kernel.apply(p)
    ts = []
    for _ in range(5 if n <= 1024 else 3):
        t0 = time.perf_counter()
        kernel.apply(p)
        ts.append(time.perf_counter() - t0)
    t_conv = float(np.median(ts))
    del p
    out = dict(n=n, N=n * n, dx=dx, L=L, mu=mu, tol=tol, rms_slope=slope, D0=D0, dD=dD, t_conv=t_conv,
               t_setup=t_setup)
    t0 = time.perf_counter()
    eq = solver.solve(Problem(U0 - D0 + 1.0, law, kernel), State.zero(grid.shape))
    out.update(cold_s=time.perf_counter() - t0, cold_conv=eq.n_conv, cold_ok=bool(eq.converged),
               cold_res=eq.residual, cold_area=float(np.mean(eq.P > 0)))
    state = eq.state
    del eq
    t0 = time.perf_counter()
    eq = solver.solve(Problem(U0 - (D0 + dD) + 1.0, law, kernel), state)
    out.update(warm_s=time.perf_counter() - t0, warm_conv=eq.n_conv, warm_ok=bool(eq.converged),
               warm_res=eq.residual, warm_area=float(np.mean(eq.P > 0)))
    out["peak_rss_MiB"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    out["array_MiB"] = n * n * 8 / 2 ** 20
    return out


def fit(ns, ts):
    """Slope of log t vs log N (N = n²) and the constant of t = c · N log N."""
    N = np.asarray(ns, float) ** 2
    t = np.asarray(ts, float)
    slope = float(np.polyfit(np.log(N), np.log(t), 1)[0])
    c = t / (N * np.log(N))
    return slope, c


def main(argv=None):
    ap = argparse.ArgumentParser(description="tengsim fast-solver scaling on a random rough surface")
    ap.add_argument("--sizes", type=int, nargs="+", default=[256, 512, 1024, 2048, 4096])
    ap.add_argument("--dx", type=float, default=0.25)
    ap.add_argument("--mu", type=float, default=0.5)
    ap.add_argument("--tol", type=float, default=1e-6)
    ap.add_argument("--overlap", type=float, default=0.05, help="fraction with U0 < D0")
    ap.add_argument("--dD", type=float, default=0.1)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--timeout", type=float, default=1500, help="seconds per size")
    ap.add_argument("--out", type=Path, default=HERE / "results")
    ap.add_argument("--one", type=int, help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.one:
        print(json.dumps(one_size(a.one, a.dx, a.mu, a.tol, a.overlap, a.dD, a.seed)))
        return
    rows = []
    for n in a.sizes:
        cmd = [sys.executable, __file__, "--one", str(n), "--dx", str(a.dx), "--mu", str(a.mu),
               "--tol", str(a.tol), "--overlap", str(a.overlap), "--dD", str(a.dD), "--seed", str(a.seed)]
        print(f"n = {n} ...", flush=True)
        try:
            p = subprocess.run(cmd, capture_output=True, text=True, timeout=a.timeout, env=os.environ)
        except subprocess.TimeoutExpired:
            print(f"  n = {n}: timed out after {a.timeout} s", flush=True)
            rows.append(dict(n=n, error=f"timeout {a.timeout} s"))
            continue
        if p.returncode != 0:
            err = (p.stderr.strip().splitlines() or ["?"])[-1]
            print(f"  n = {n}: failed ({err})", flush=True)
            rows.append(dict(n=n, error=err))
            continue
        r = json.loads(p.stdout.strip().splitlines()[-1])
        rows.append(r)
        print(f"  cold {r['cold_s']:.2f} s ({r['cold_conv']} conv), warm {r['warm_s']:.2f} s ({r['warm_conv']} conv), "
              f"t_conv {r['t_conv'] * 1e3:.1f} ms, peak RSS {r['peak_rss_MiB']:.0f} MiB, "
              f"repulsive area {r['warm_area']:.3f}", flush=True)
    ok = [r for r in rows if "error" not in r]
    lines = ["# Scaling of tengsim's fast solver (one equilibrium, periodic random rough surface)", "",
             f"Command: `python benchmarks/scaling.py {' '.join(sys.argv[1:])}`", "",
             f"Surface: self-affine, Hurst 0.8, λr = 16 ε, λs = 2 ε, h_rms = 1 ε, pixel dx = {a.dx} ε "
             f"(cell grows with n), seed {a.seed}; μ = {a.mu}, LJ 8-2, periodic kernel, tol = {a.tol:g}; "
             f"D0 such that {100 * a.overlap:g} % overlaps rigidly, warm step ΔD = {a.dD}.", "",
             f"Machine: {os.cpu_count()} cores; OPENBLAS_NUM_THREADS={os.environ.get('OPENBLAS_NUM_THREADS')}, "
             f"TENGSIM_FFT_WORKERS={os.environ.get('TENGSIM_FFT_WORKERS')} (unset: 1 thread below 512² "
             f"points, all cores above).", "",
             "| n | cold [s] | cold conv | warm [s] | warm conv | t_conv [ms] | warm/(conv·t_conv) | "
             "peak RSS [MiB] | RSS / array | repulsive area | rms slope |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        if "error" in r:
            lines.append(f"| {r['n']} | {r['error']} |" + " |" * 9)
            continue
        lines.append(
            f"| {r['n']} | {r['cold_s']:.2f} | {r['cold_conv']} | {r['warm_s']:.3f} | {r['warm_conv']} | "
            f"{r['t_conv'] * 1e3:.2f} | {r['warm_s'] / (r['warm_conv'] * r['t_conv']):.2f} | "
            f"{r['peak_rss_MiB']:.0f} | {r['peak_rss_MiB'] / r['array_MiB']:.0f} | {r['warm_area']:.3f} | "
            f"{r['rms_slope']:.2f} |")
    if len(ok) >= 2:
        ns = [r["n"] for r in ok]
        for key in ("cold_s", "warm_s", "t_conv"):
            s, _ = fit(ns, [r[key] for r in ok])
            lines.append("")
            lines.append(f"Fitted growth of {key}: time ∝ N^{s:.2f} (N = n²).")
        sm = float(np.polyfit(np.log(np.asarray(ns, float) ** 2), np.log([r["peak_rss_MiB"] for r in ok]), 1)[0])
        lines.append("")
        lines.append(f"Fitted growth of peak memory: ∝ N^{sm:.2f}.")
    lines.append("")
    a.out.mkdir(parents=True, exist_ok=True)
    (a.out / "scaling.md").write_text("\n".join(lines))
    (a.out / "scaling.json").write_text(json.dumps(rows, indent=1))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
