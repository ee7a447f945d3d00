"""Scaling study of tengsim's fast solver (issue 6): one equilibrium on a periodic random rough
surface at n² = 256² … 4096², time and peak memory, and the fitted growth.

    OPENBLAS_NUM_THREADS=1 python benchmarks/scaling.py --sizes 256 512 1024 2048 --out benchmarks/results

A size too long for the per-size ``--timeout`` can be run alone and joined to the table:

    OPENBLAS_NUM_THREADS=1 python benchmarks/scaling.py --one 4096 --cold-max 0 > one4096.out
    OPENBLAS_NUM_THREADS=1 python benchmarks/scaling.py --sizes 256 512 1024 2048 --rows one4096.out ...

tengsim's FFT threading rule applies (1 thread below 512² points, all cores from 512² up);
TENGSIM_FFT_WORKERS forces a count and is recorded in ``scaling.md``.

``--surface pyramids`` solves a periodic array of the paper's group-C pyramids instead (``--px`` pixels
per pyramid cell, heights scattered by ``--jitter``, approach ``--D``; see :func:`pyramid_array`) and
writes ``scaling_pyramids.md`` / ``.json``.

The rough surface is statistically the same at every size: fixed pixel dx (in ε), so the cell grows
with n (L = n·dx); a self-affine power spectrum C(q) ∝ q^{-2(1+H)} between a roll-off wavelength
λr and a short cutoff λs (both fixed in ε), random phases from a fixed seed, rms height h_rms.
U0 = max(h) − h, periodic kernel (μ^{3/2} · 2/|q|), LJ 8-2 law, μ = 0.5.  D is set so that a fixed
fraction of the surface overlaps rigidly (U0 < D): the contact state is comparable across sizes.

Per size, in a fresh subprocess (so peak memory is that size's alone):
* a nested-grid solve (``tengsim.solvers.multilevel.nested_solve``: coarse grids over the same cell first,
  down to ``--min-size``), its convolutions on the finest grid and in fine-grid equivalents;
* for n <= ``--cold-max``: a cold equilibrium at D0 from the undeformed state and, for
  n <= ``--warm-max``, a warm one at D0 + ΔD from it (the per-step cost on a path);
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


def pyramid_array(n, px=128, group="C", jitter=0.02, seed=0):
    """Periodic square array of the paper's pyramids (group ``group``, Eq. 7 scaling), ``px`` pixels
    per pyramid cell, (n/px)² pyramids; each pyramid's height scaled by 1 + ``jitter``·ξ (ξ standard
    normal, fixed seed: fabrication scatter, so that no two cells are the same problem).
    Returns U0 (the undeformed gap, 0 at the highest tip), the pixel dx and μ."""
    from tengsim.grid import Grid
    from tengsim.cases.paper.units import paper_scaling

    if n % px:
        raise ValueError(f"n = {n} is not a multiple of the pixels per pyramid cell ({px})")
    sc = paper_scaling(group)
    dx = sc.cell / px
    m = n // px
    X, Y = Grid(px, px, dx, dx).mesh()                  # the package's cell-centred pixel coordinates
    # below the tip, one cell: Pyramid.gap without its clip at 2N (a scattered tip may stand higher)
    depth = 2 * np.maximum(np.abs(X), np.abs(Y))
    tips = 2 * sc.N * (1 + jitter * np.random.default_rng(seed).standard_normal((m, m)))
    # height above the base, cell by cell: max(tip − depth, 0), tiled over the m × m cells
    z = np.maximum(np.repeat(np.repeat(tips, px, 0), px, 1) - np.tile(depth, (m, m)), 0.0)
    return z.max() - z, dx, sc.mu


def one_size(n, dx, mu, tol, overlap, dD, seed, cold=True, nested=True, min_size=128, warm=True, max_dx=0.5,
             max_iter=3000, coarse_max_iter=1000, surface="rough", px=128, jitter=0.02, D=6.0):
    from tengsim.grid import Grid
    from tengsim.laws import LJ93
    from tengsim.kernels import make_kernel
    from tengsim.solvers import Problem, State, make_solver

    t_setup = time.perf_counter()
    if surface == "rough":
        h, L = rough_surface(n, dx, seed=seed)
        slope = float(np.sqrt(np.mean(np.gradient(h, dx, axis=0) ** 2 + np.gradient(h, dx, axis=1) ** 2)))
        U0 = h.max() - h
        del h
        D0 = float(np.quantile(U0, overlap))
    else:  # the paper's pyramids (group C), a periodic array of (n/px)² with scattered heights
        U0, dx, mu = pyramid_array(n, px=px, jitter=jitter, seed=seed)
        L, slope, D0 = n * dx, 2.0, float(D)   # |∇U0| = 2 on every face (Eq. 7 scaling)
    grid = Grid(n, n, dx, dx)
    kernel = make_kernel("periodic", grid, mu ** 1.5)
    law = LJ93()
    def monitor(it, rmax, E):  # progress of long solves, on stderr
        print(f"    it {it}: max|r| {rmax:.2e}, E {E:.10g}", file=sys.stderr, flush=True)

    solver = make_solver("fast", tol=tol, max_iter=max_iter, monitor=monitor if n >= 2048 else None)
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
               t_setup=t_setup, surface=surface)
    if nested:
        from tengsim.solvers.multilevel import nested_solve

        t0 = time.perf_counter()
        def progress(lv):  # one line per finished level, on stderr (kept if the size is cut)
            print(f"  level {lv.shape[0]}²: {lv.n_conv} conv, {lv.seconds:.1f} s, max|r| {lv.residual:.1e}",
                  file=sys.stderr, flush=True)

        ns = nested_solve(solver, U0 - D0 + 1.0, law, kernel, min_size=min_size, max_dx=max_dx,
                          coarse_max_iter=coarse_max_iter, on_level=progress)
        eq = ns.equilibrium
        out.update(nested_s=time.perf_counter() - t0, nested_conv=ns.n_conv,
                   nested_fine_conv=eq.n_conv, nested_fine_equiv=ns.fine_equivalent_conv,
                   nested_fine_s=ns.levels[-1].seconds, nested_ok=bool(eq.converged), nested_res=eq.residual,
                   nested_area=float(np.mean(eq.P > 0)), nested_energy=eq.energy,
                   nested_levels=[[lv.shape[0], lv.n_conv, lv.seconds, lv.residual] for lv in ns.levels])
        del ns, eq
        _emit(out)
    if cold:
        t0 = time.perf_counter()
        eq = solver.solve(Problem(U0 - D0 + 1.0, law, kernel), State.zero(grid.shape))
        out.update(cold_s=time.perf_counter() - t0, cold_conv=eq.n_conv, cold_ok=bool(eq.converged),
                   cold_res=eq.residual, cold_area=float(np.mean(eq.P > 0)), cold_energy=eq.energy)
        state = eq.state
        del eq
        _emit(out)
        if not warm:
            return out
        t0 = time.perf_counter()
        eq = solver.solve(Problem(U0 - (D0 + dD) + 1.0, law, kernel), state)
        out.update(warm_s=time.perf_counter() - t0, warm_conv=eq.n_conv, warm_ok=bool(eq.converged),
                   warm_res=eq.residual, warm_area=float(np.mean(eq.P > 0)))
    _emit(out)
    return out


def _emit(out):
    """One JSON line per finished phase, so a size cut by the timeout keeps what it finished."""
    out["peak_rss_MiB"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    out["array_MiB"] = out["N"] * 8 / 2 ** 20
    print(json.dumps(out), flush=True)


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
    ap.add_argument("--surface", choices=("rough", "pyramids"), default="rough",
                    help="random rough surface (default) or a periodic array of the paper's group-C pyramids")
    ap.add_argument("--px", type=int, default=128, help="pyramids: pixels per pyramid cell (n must be a multiple)")
    ap.add_argument("--jitter", type=float, default=0.02, help="pyramids: relative rms scatter of the heights")
    ap.add_argument("--D", type=float, default=6.0, help="pyramids: the rigid approach D [ε]")
    ap.add_argument("--timeout", type=float, default=1500, help="seconds per size")
    ap.add_argument("--cold-max", type=int, default=2048, help="largest n solved cold (and warm)")
    ap.add_argument("--warm-max", type=int, default=1024, help="largest n with the warm step")
    ap.add_argument("--no-nested", action="store_true", help="skip the nested-grid solve")
    ap.add_argument("--min-size", type=int, default=128, help="coarsest grid of the nested solve")
    ap.add_argument("--max-dx", type=float, default=0.5, help="coarsest pixel of the nested solve [ε]")
    ap.add_argument("--max-iter", type=int, default=3000, help="iteration cap of a solve (the finest level)")
    ap.add_argument("--coarse-max-iter", type=int, default=1000, help="iteration cap of the coarse levels")
    ap.add_argument("--rows", type=Path, nargs="*", default=[],
                    help="stdout files of earlier '--one N' runs whose rows join the table (a size run alone)")
    ap.add_argument("--out", type=Path, default=HERE / "results")
    ap.add_argument("--one", type=int, help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.one:
        one_size(a.one, a.dx, a.mu, a.tol, a.overlap, a.dD, a.seed, cold=a.one <= a.cold_max,
                 nested=not a.no_nested, min_size=a.min_size, warm=a.one <= a.warm_max,
                 max_dx=a.max_dx, max_iter=a.max_iter, coarse_max_iter=a.coarse_max_iter,
                 surface=a.surface, px=a.px, jitter=a.jitter, D=a.D)
        return
    if a.surface == "pyramids":
        bad = [n for n in a.sizes if n % a.px]
        if bad:
            ap.error(f"--sizes {bad} are not multiples of --px {a.px} (whole pyramid cells only)")
    rows = []
    for n in a.sizes:
        cmd = [sys.executable, __file__, "--one", str(n), "--dx", str(a.dx), "--mu", str(a.mu),
               "--tol", str(a.tol), "--overlap", str(a.overlap), "--dD", str(a.dD), "--seed", str(a.seed),
               "--cold-max", str(a.cold_max), "--warm-max", str(a.warm_max), "--min-size", str(a.min_size), "--max-dx", str(a.max_dx),
               "--max-iter", str(a.max_iter), "--coarse-max-iter", str(a.coarse_max_iter),
               "--surface", a.surface, "--px", str(a.px), "--jitter", str(a.jitter), "--D", str(a.D)] + (["--no-nested"] if a.no_nested else [])
        print(f"n = {n} ...", flush=True)
        t0 = time.perf_counter()
        try:
            p = subprocess.run(cmd, capture_output=True, text=True, timeout=a.timeout, env=os.environ)
            stdout, err = p.stdout, (None if p.returncode == 0 else
                                     (p.stderr.strip().splitlines() or ["?"])[-1])
        except subprocess.TimeoutExpired as e:
            so = e.stdout or ""
            stdout = so.decode() if isinstance(so, bytes) else so
            err = f"cut at the {a.timeout:g} s cap"
        lines = [ln for ln in stdout.splitlines() if ln.startswith("{")]
        r = json.loads(lines[-1]) if lines else dict(n=n)
        r["wall_total_s"] = time.perf_counter() - t0
        if err:
            r["error"] = err
        rows.append(r)
        print("  " + ", ".join(f"{k} {r[k]:.4g}" if isinstance(r[k], float) else f"{k} {r[k]}"
                               for k in ("nested_s", "nested_fine_conv", "cold_s", "cold_conv", "warm_s",
                                         "warm_conv", "peak_rss_MiB", "error") if k in r), flush=True)

    for f in a.rows:  # sizes run alone (``--one N > file``): their last JSON line
        got = [ln for ln in f.read_text().splitlines() if ln.startswith("{")]
        if got:
            r = json.loads(got[-1])
            r["note"] = f"run alone ({f.name})"
            rows.append(r)
    rows.sort(key=lambda r: r["n"])

    def cell(r, k, spec):
        return format(r[k], spec) if k in r else "–"

    if a.surface == "rough":
        title = "periodic random rough surface"
        what = (f"Surface: self-affine, Hurst 0.8, λr = 16 ε, λs = 2 ε, h_rms = 1 ε, pixel dx = {a.dx} ε "
                f"(cell grows with n), seed {a.seed}; μ = {a.mu}, LJ 8-2, periodic kernel, tol = {a.tol:g}; "
                f"D0 such that {100 * a.overlap:g} % overlaps rigidly")
    else:
        from tengsim.cases.paper.units import paper_scaling

        sc = paper_scaling("C")
        title = "periodic array of the paper's group-C pyramids"
        what = (f"Surface: the paper's group-C pyramids (Eq. 7: N = {sc.N:.2f}, cell {sc.cell:.2f} ε), {a.px} "
                f"pixels per pyramid cell (dx = {sc.cell / a.px:.4f} ε; the array grows with n: (n/{a.px})² "
                f"pyramids), heights scattered by {100 * a.jitter:g} % rms (seed {a.seed}); μ = {sc.mu:g}, "
                f"LJ 8-2, periodic kernel, tol = {a.tol:g}; D0 = {a.D:g}")
    lines = [f"# Scaling of tengsim's fast solver (one equilibrium, {title})", "",
             f"Command: `python benchmarks/scaling.py {' '.join(sys.argv[1:])}`", "",
             what + f", warm step ΔD = {a.dD}; nested: coarsest grid {a.min_size}², coarsest pixel {a.max_dx} ε.", "",
             f"Machine: {os.cpu_count()} cores; OPENBLAS_NUM_THREADS={os.environ.get('OPENBLAS_NUM_THREADS')}, "
             f"TENGSIM_FFT_WORKERS={os.environ.get('TENGSIM_FFT_WORKERS')} (unset: 1 thread below 512² "
             f"points, all cores above).", "",
             "| n | cold [s] | cold conv | warm [s] | warm conv | nested [s] | nested: fine-grid conv "
             "(fine-equivalent, all levels) | nested levels (n: conv, s) | nested = cold state? | t_conv [ms] | "
             "cold/(conv·t_conv) | warm/(conv·t_conv) | nested fine level/(conv·t_conv) | peak RSS [MiB] | "
             "repulsive area | note |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        if "t_conv" not in r:
            lines.append(f"| {r['n']} |" + " – |" * 14 + f" {r.get('error', '')} |")
            continue
        tc = r["t_conv"]
        same = "–"
        if "nested_energy" in r and "cold_energy" in r:
            de = abs(r["nested_energy"] - r["cold_energy"]) / abs(r["cold_energy"])
            same = f"yes (ΔE/E {de:.0e})" if de < 1e-8 else f"no (ΔE/E {de:.1e})"
        nested = (f"{r['nested_fine_conv']} ({r['nested_fine_equiv']:.0f})" if "nested_fine_conv" in r else "–")
        lv = ("; ".join(f"{x[0]}: {x[1]}, {x[2]:.1f}" for x in r["nested_levels"]) if "nested_levels" in r else "–")
        nfr = (f"{r['nested_fine_s'] / (r['nested_fine_conv'] * tc):.2f}" if "nested_fine_s" in r else "–")
        note = "; ".join(x for x in (r.get("note", ""), r.get("error", "")) if x)
        lines.append(
            f"| {r['n']} | {cell(r, 'cold_s', '.1f')} | {cell(r, 'cold_conv', 'd')} | {cell(r, 'warm_s', '.1f')} | "
            f"{cell(r, 'warm_conv', 'd')} | {cell(r, 'nested_s', '.1f')} | {nested} | {lv} | {same} | "
            f"{tc * 1e3:.1f} | "
            + (f"{r['cold_s'] / (r['cold_conv'] * tc):.2f}" if "cold_s" in r else "–") + " | "
            + (f"{r['warm_s'] / (r['warm_conv'] * tc):.2f}" if "warm_s" in r else "–") + f" | {nfr} | "
            f"{r['peak_rss_MiB']:.0f} | {r.get('cold_area', r.get('nested_area', float('nan'))):.3f} | "
            f"{note} |")
    for key in ("cold_s", "warm_s", "nested_s", "t_conv", "peak_rss_MiB"):
        ok = [r for r in rows if key in r]
        if len(ok) >= 2:
            sl, _ = fit([r["n"] for r in ok], [r[key] for r in ok])
            lines += ["", f"Fitted growth of {key} over n = {', '.join(str(r['n']) for r in ok)}: ∝ N^{sl:.2f} (N = n²)."]
    lines.append("")
    a.out.mkdir(parents=True, exist_ok=True)
    stem = "scaling" if a.surface == "rough" else "scaling_pyramids"
    (a.out / f"{stem}.md").write_text("\n".join(lines))
    (a.out / f"{stem}.json").write_text(json.dumps(rows, indent=1))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
