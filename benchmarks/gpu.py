"""Issue 31: the fast solver compiled with JAX (``--solver jax`` / ``gpu``) against the NumPy fast solver.

Rows (each against the CPU NumPy solver's figure where that is affordable, else extrapolated and marked so):

* cold adhesive equilibria on the periodic random rough surface of benchmarks/scaling.py (Hurst 0.8,
  λr = 16 ε, λs = 2 ε, h_rms = 1 ε, dx = 0.25 ε, μ = 0.5, D0 with 5 % rigid overlap, LJ93, tol 1e-6),
  float64 and float32, at ``--sizes`` (default 1024 4096 8192);
* a group C path (free cell, approach and retraction, the paper's μ = 0.5);
* a small design-like run: group A pyramid paths at three Tabor parameters through the ordinary contact
  API (one grid: one compile serves the three).

Per row: iterations, total time, time per iteration, compile time (paid once per grid shape, not in the
total), device memory per point (GPU: ``peak_bytes_in_use`` of the device; every backend: XLA's own
count of the compiled loop's buffers, ``memory_analysis``), the process's peak RSS.  The NumPy reference
runs up to ``--cpu-max`` points a side; above it its time is extrapolated from the largest measured size
with the cold-solve growth N^1.52 of docs/benchmarks.md (the scaling table), and says so.

    python benchmarks/gpu.py                       # on a GPU machine: pip install -e '.[gpu]' first
    python benchmarks/gpu.py --quick               # CPU, 65² and tiny paths, ~20 s (tests/test_jax_solver.py)
    python benchmarks/gpu.py --sizes 128 256 512 --cpu-max 512 --out benchmarks/results/gpu_cpu
"""
from __future__ import annotations

import argparse
import json
import resource
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
COLD_GROWTH = 1.52  # cold rough solve time ∝ N^1.52 on the CPU (docs/benchmarks.md, scaling, 256² → 2048²)


def rss_mib() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def device_peak(dev):
    stats = getattr(dev, "memory_stats", lambda: None)()
    return None if not stats else stats.get("peak_bytes_in_use")


def xla_bytes(key_shape, dtype):
    """XLA's count (temp + arguments + outputs) of the newest compiled loop for this grid and dtype."""
    from tengsim.solvers import jax_fast

    for key, fn in reversed(list(jax_fast._CACHE.items())):
        if key[0] == key_shape and key[6] == dtype:
            ma = fn.memory_analysis()
            if ma is not None:
                return ma.temp_size_in_bytes + ma.argument_size_in_bytes + ma.output_size_in_bytes
    return None


def rough_row(n, dtype, device, cpu_max, tol, max_iter, ref_cache):
    from scaling import rough_surface

    from tengsim.grid import Grid
    from tengsim.kernels import make_kernel
    from tengsim.laws import LJ93
    from tengsim.solvers import FastSolver, Problem, State
    from tengsim.solvers.jax_fast import JaxSolver, compile_stats, find_device

    dx, mu = 0.25, 0.5
    h, _ = rough_surface(n, dx, seed=0)
    U0 = h.max() - h
    del h
    D0 = float(np.quantile(U0, 0.05))
    grid = Grid(n, n, dx, dx)
    pb = Problem(U0 - D0 + 1.0, LJ93(), make_kernel("periodic", grid, mu ** 1.5))
    st = State.zero((n, n))
    solver = JaxSolver(tol=tol, max_iter=max_iter, device=device, dtype=dtype)
    c0 = compile_stats()["compile_seconds"]
    t0 = time.perf_counter()
    eq = solver.solve(pb, st)
    wall = time.perf_counter() - t0
    compile_s = compile_stats()["compile_seconds"] - c0
    run = wall - compile_s
    F = float(eq.P.sum()) * grid.area
    dev = find_device(device)
    row = dict(case=f"rough {n}²", n=n, dtype=dtype, device=str(dev), iterations=eq.iterations,
               converged=eq.converged, residual=eq.residual, total_s=run, per_iter_ms=1e3 * run / max(eq.iterations, 1),
               compile_s=compile_s, F=F, device_peak_B_per_pt=None, xla_B_per_pt=None, rss_MiB=rss_mib())
    peak = device_peak(dev)
    if peak is not None and dev.platform != "cpu":
        row["device_peak_B_per_pt"] = peak / (n * n)
    xb = xla_bytes((n, n), dtype)
    if xb is not None:
        row["xla_B_per_pt"] = xb / (n * n)
    if n <= cpu_max:
        if n not in ref_cache:
            t0 = time.perf_counter()
            ref = FastSolver(tol=tol, max_iter=max_iter).solve(pb, st)
            ref_cache[n] = dict(t=time.perf_counter() - t0, it=ref.iterations, F=float(ref.P.sum()) * grid.area)
        r = ref_cache[n]
        row.update(cpu_s=r["t"], cpu_iterations=r["it"], cpu_note="measured", dF_rel=abs(F - r["F"]) / abs(r["F"]))
    elif ref_cache:
        m = max(ref_cache)
        row.update(cpu_s=ref_cache[m]["t"] * (n * n / (m * m)) ** COLD_GROWTH, cpu_iterations=None,
                   cpu_note=f"extrapolated from {m}² with N^{COLD_GROWTH}", dF_rel=None)
    row["speedup"] = row.get("cpu_s", np.nan) / run if run > 0 and row.get("cpu_s") else None
    return row


def path_row(label, runs, device):
    """Whole paths through the contact API: ``runs`` = [(N, cell, mu, dx, d_max, d_step)], jax vs fast."""
    from tengsim.run.simulate import simulate_pyramid
    from tengsim.solvers.jax_fast import JaxSolver, compile_stats

    out = {}
    for name in ("fast", "jax"):
        c0 = compile_stats()["compile_seconds"]
        t0 = time.perf_counter()
        it, F = 0, []
        for N, cell, mu, dx, d_max, d_step in runs:
            solver = "fast" if name == "fast" else JaxSolver(device=device)
            res = simulate_pyramid(N, cell, mu, dx, d_min=-1.0, d_max=d_max, d_step=d_step, solver=solver,
                                   symmetry="off")
            it += int(np.sum(res.table["iterations"]))
            F.append(np.asarray(res.table["F"]))
        wall = time.perf_counter() - t0
        comp = compile_stats()["compile_seconds"] - c0 if name == "jax" else 0.0
        out[name] = dict(t=wall - comp, it=it, compile=comp, F=np.concatenate(F))
    j, f = out["jax"], out["fast"]
    return dict(case=label, n=None, dtype="float64", device=device, iterations=j["it"], converged=True,
                residual=None, total_s=j["t"], per_iter_ms=1e3 * j["t"] / max(j["it"], 1), compile_s=j["compile"],
                F=None, device_peak_B_per_pt=None, xla_B_per_pt=None, rss_MiB=rss_mib(), cpu_s=f["t"],
                cpu_iterations=f["it"], cpu_note="measured", dF_rel=float(np.max(np.abs(j["F"] - f["F"]))),
                speedup=f["t"] / j["t"] if j["t"] > 0 else None)


def fmt(v, spec):
    return "n/a" if v is None or (isinstance(v, float) and not np.isfinite(v)) else format(v, spec)


def table(rows) -> str:
    head = ("| case | dtype | iterations (CPU) | total [s] | per iteration [ms] | compile [s] | device B/pt "
            "(XLA count) | peak RSS [MiB] | CPU NumPy [s] | speed-up | ΔF (rough: relative; paths: max abs) |")
    lines = [head, "|" + "---|" * 11]
    for r in rows:
        cpu_it = "" if r.get("cpu_iterations") is None else f" ({r['cpu_iterations']})"
        note = "" if r.get("cpu_note") in (None, "measured") else " (extrap.)"
        dev = fmt(r["device_peak_B_per_pt"], ".0f") + " (" + fmt(r["xla_B_per_pt"], ".0f") + ")"
        lines.append(f"| {r['case']} | {r['dtype']} | {r['iterations']}{cpu_it} | {fmt(r['total_s'], '.2f')} | "
                     f"{fmt(r['per_iter_ms'], '.2f')} | {fmt(r['compile_s'], '.1f')} | {dev} | "
                     f"{fmt(r['rss_MiB'], '.0f')} | {fmt(r.get('cpu_s'), '.2f')}{note} | "
                     f"{fmt(r.get('speedup'), '.2f')} | {fmt(r.get('dF_rel'), '.1e')} |")
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[1024, 4096, 8192], help="rough grid sizes n (n²)")
    ap.add_argument("--dtypes", nargs="+", default=["float64", "float32"], choices=["float64", "float32"])
    ap.add_argument("--device", default="auto", choices=["auto", "cpu", "gpu"])
    ap.add_argument("--cpu-max", type=int, default=1024, help="largest n the NumPy reference runs at")
    ap.add_argument("--tol", type=float, default=1e-6)
    ap.add_argument("--max-iter", type=int, default=20000)
    ap.add_argument("--quick", action="store_true", help="CPU-sized: 65², a tiny group C path and design run")
    ap.add_argument("--out", type=Path, help="folder for gpu.json and gpu.md")
    a = ap.parse_args(argv)
    from tengsim.solvers.jax_fast import find_device

    dev = find_device(a.device)
    if a.quick:  # 65² and 49² pyramid cells: the grids tests/test_jax_solver.py compiles for anyway
        a.sizes, a.cpu_max = [65], max(a.cpu_max, 65)
        group_c = [(4.73, 18.9, 0.5, 0.4, 1.0, 0.25)]
        design = [(0.946, 3.78, mu, 0.08, 1.0, 0.25) for mu in (0.3, 0.5, 1.0)]
    else:
        group_c = [(4.73, 18.9, 0.5, 0.1, 14.0, 0.05)]
        design = [(0.946, 3.78, mu, 0.05, 3.0, 0.05) for mu in (0.3, 0.5, 1.0)]
    print(f"device: {dev} ({dev.platform}); sizes {a.sizes}; dtypes {a.dtypes}", flush=True)
    rows, refs = [], {}
    for n in a.sizes:
        for dt in a.dtypes:
            rows.append(rough_row(n, dt, a.device, a.cpu_max, a.tol, a.max_iter, refs))
            print(table(rows[-1:]).splitlines()[-1], flush=True)
    rows.append(path_row("group C path" + (" (dx 0.4)" if a.quick else " (dx 0.1)"), group_c, a.device))
    rows.append(path_row("design: group A at μ 0.3, 0.5, 1", design, a.device))
    md = table(rows)
    print(md)
    if a.out:
        a.out.mkdir(parents=True, exist_ok=True)
        (a.out / "gpu.json").write_text(json.dumps(rows, indent=1, default=float))
        (a.out / "gpu.md").write_text(md + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
