"""The fast solver compiled with JAX (``--solver jax`` / ``gpu`` / ``auto`` on a GPU) against the NumPy fast solver.

Rows (each against the CPU NumPy solver's figure where that is affordable, else extrapolated and marked so):

* cold adhesive equilibria on the periodic random rough surface of benchmarks/scaling.py (Hurst 0.8,
  λr = 16 ε, λs = 2 ε, h_rms = 1 ε, dx = 0.25 ε, μ = 0.5, D0 with 5 % rigid overlap, LJ93, tol 1e-6),
  float64 and float32, at ``--sizes`` (default 1024 4096 8192);
* the same surface split over the devices JAX has (``JaxSolver(shards=N)``, a slab FFT with all-to-all) at
  ``--shard-sizes``, against the one-device solve (ΔF) where that fits; skipped with one device;
* a group C path (free cell, approach and retraction, the paper's μ = 0.5);
* a small design-like run: group A pyramid paths at three Tabor parameters through the ordinary contact API;
* whole designs (``tengsim design`` with the JAX solver): the README pyramid and a hemisphere (pitch 4 µm,
  R 1.5 µm, ε 50 nm), with the design's own expected time beside the measured one (its cost model).

Per row: iterations, total time, time per iteration, compile time (paid once per grid shape, not in the
total), device memory per point (GPU: ``peak_bytes_in_use`` of the device; every backend: XLA's own
count of the compiled loop's buffers, ``memory_analysis``), the process's peak RSS.  The NumPy reference
runs up to ``--cpu-max`` points a side; above it its time is extrapolated from the largest measured size
with the cold-solve growth N^1.52 of docs/benchmarks.md (the scaling table), and says so.

Each row is written as one JSON line to OUT/gpu.jsonl as soon as it finishes; ``--deadline`` (seconds from
the start) skips a row whose projected time (tengsim.resources.GPU_COST, or the row before it) would end past
it, and says so: device time is counted in minutes.

    python benchmarks/gpu.py --out benchmarks/results/gpu --deadline 540   # on a GPU: pip install -e '.[gpu]'
    python benchmarks/gpu.py --quick               # CPU, 65² and tiny paths and designs (tests/test_jax_solver.py)
    python benchmarks/gpu.py --quick --virtual-devices 4   # the sharded rows on 4 virtual CPU devices
"""
from __future__ import annotations

import argparse
import json
import math
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
    from tengsim.continuation import PathSpec
    from tengsim.run.plan import ContactPlan
    from tengsim.run.simulate import simulate
    from tengsim.shapes import Pyramid
    from tengsim.solvers.jax_fast import JaxSolver, compile_stats

    out = {}
    for name in ("fast", "jax"):
        c0 = compile_stats()["compile_seconds"]
        t0 = time.perf_counter()
        it, F = 0, []
        for N, cell, mu, dx, d_max, d_step in runs:
            solver = "fast" if name == "fast" else JaxSolver(device=device)
            res = simulate(ContactPlan(Pyramid(N, cell), mu, dx, PathSpec(-1.0, d_max, d_step), solver=solver, symmetry="off"))
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


def shard_row(n, shards, device, tol, max_iter, ref):
    """The rough surface at n² split over ``shards`` devices; ΔF against ``ref`` (the one-device F) if given."""
    from scaling import rough_surface

    from tengsim.grid import Grid
    from tengsim.kernels import make_kernel
    from tengsim.laws import LJ93
    from tengsim.solvers import Problem, State
    from tengsim.solvers.jax_fast import JaxSolver, compile_stats

    dx, mu = 0.25, 0.5
    h, _ = rough_surface(n, dx, seed=0)
    U0 = h.max() - h
    D0 = float(np.quantile(U0, 0.05))
    grid = Grid(n, n, dx, dx)
    pb = Problem(U0 - D0 + 1.0, LJ93(), make_kernel("periodic", grid, mu ** 1.5))
    c0 = compile_stats()["compile_seconds"]
    t0 = time.perf_counter()
    eq = JaxSolver(tol=tol, max_iter=max_iter, device=device, shards=shards).solve(pb, State.zero((n, n)))
    run = time.perf_counter() - t0 - (compile_stats()["compile_seconds"] - c0)
    F = float(eq.P.sum()) * grid.area
    xb = xla_bytes((n, n), "float64")
    return dict(case=f"rough {n}² on {shards} devices", n=n, dtype="float64", device=device, iterations=eq.iterations,
                converged=eq.converged, residual=eq.residual, total_s=run,
                per_iter_ms=1e3 * run / max(eq.iterations, 1),
                compile_s=compile_stats()["compile_seconds"] - c0, F=F, device_peak_B_per_pt=None,
                xla_B_per_pt=None if xb is None else xb / (n * n), rss_MiB=rss_mib(), cpu_s=None, cpu_iterations=None,
                cpu_note="one-device F", dF_rel=None if ref is None else abs(F - ref) / abs(ref), speedup=None)


DESIGNS = {
    "README pyramid": dict(shape="pyramid", pitch="10um", base="5um", height="3.5um", E_star="1MPa", W="50mJ/m2",
                           eps="200nm", p_max="100kPa", p_step="5kPa"),
    "hemisphere": dict(shape="hemisphere", pitch="4um", radius="1.5um", E_star="2MPa", W="30mJ/m2", eps="50nm",
                       p_max="80kPa", budget=3600),
}
QUICK_DESIGN = dict(shape="pyramid", pitch="1um", base="0.5um", height="0.2um", E_star="5MPa", W="20mJ/m2",
                    eps="50nm", p_max="50kPa", p_step="5kPa")


def design_row(label, table, solver):
    """A whole design with ``solver``: its expected time (the design's cost model) and the measured one."""
    from tengsim.design import plan_design, run_design

    said = []

    class Say:
        def say(self, text):
            said.append(text)

    t0 = time.perf_counter()
    res = run_design(plan_design({**table, "solver": solver}), progress=Say())
    wall = time.perf_counter() - t0
    line = next((x for x in said if "expected time: " in x), "")
    expected = line.split("expected time: ")[1].split(" (")[0] if line else "n/a"
    backend = line.rsplit(" on ", 1)[-1].split(" (")[0] if line else "?"
    return dict(case=f"design: {label}, {res.summary.get('grids')}, status {res.status}; expected {expected} "
                     f"({backend} model)", n=None, dtype="float64", device=solver, iterations=None,
                converged=res.status == "ok", residual=None, total_s=wall, per_iter_ms=None, compile_s=None, F=None,
                device_peak_B_per_pt=None, xla_B_per_pt=None, rss_MiB=rss_mib(), cpu_s=None, cpu_iterations=None,
                cpu_note=expected, dF_rel=None, speedup=None, grids=res.summary.get("grids"), status=res.status)


def fmt(v, spec):
    return "n/a" if v is None or (isinstance(v, float) and not np.isfinite(v)) else format(v, spec)


def table(rows) -> str:
    head = ("| case | dtype | iterations (CPU) | total [s] | per iteration [ms] | compile [s] | device B/pt "
            "(XLA count) | peak RSS [MiB] | CPU NumPy [s] | speed-up | ΔF (rough: relative; paths: max abs) |")
    lines = [head, "|" + "---|" * 11]
    for r in rows:
        cpu_it = "" if r.get("cpu_iterations") is None else f" ({r['cpu_iterations']})"
        note = " (extrap.)" if str(r.get("cpu_note") or "").startswith("extrapolated") else ""
        dev = fmt(r["device_peak_B_per_pt"], ".0f") + " (" + fmt(r["xla_B_per_pt"], ".0f") + ")"
        its = "n/a" if r.get("iterations") is None else r["iterations"]
        lines.append(f"| {r['case']} | {r['dtype']} | {its}{cpu_it} | {fmt(r['total_s'], '.2f')} | "
                     f"{fmt(r['per_iter_ms'], '.2f')} | {fmt(r['compile_s'], '.1f')} | {dev} | "
                     f"{fmt(r['rss_MiB'], '.0f')} | {fmt(r.get('cpu_s'), '.2f')}{note} | "
                     f"{fmt(r.get('speedup'), '.2f')} | {fmt(r.get('dF_rel'), '.1e')} |")
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[1024, 4096, 8192], help="rough grid sizes n (n²)")
    ap.add_argument("--shard-sizes", type=int, nargs="*", default=[4096, 16384],
                    help="rough sizes split over all devices (skipped with one device)")
    ap.add_argument("--dtypes", nargs="+", default=["float64", "float32"], choices=["float64", "float32"])
    ap.add_argument("--device", default="auto", choices=["auto", "cpu", "gpu"])
    ap.add_argument("--cpu-max", type=int, default=1024, help="largest n the NumPy reference runs at")
    ap.add_argument("--tol", type=float, default=1e-6)
    ap.add_argument("--max-iter", type=int, default=20000)
    ap.add_argument("--quick", action="store_true", help="CPU-sized: 65², a tiny group C path and design run")
    ap.add_argument("--no-designs", action="store_true", help="leave out the whole-design rows")
    ap.add_argument("--virtual-devices", type=int, default=0, help="CPU: this many virtual devices (sharded rows)")
    ap.add_argument("--deadline", type=float, default=None, help="seconds from the start; rows projected past it "
                    "are skipped")
    ap.add_argument("--out", type=Path, help="folder for gpu.json, gpu.jsonl and gpu.md")
    a = ap.parse_args(argv)
    start = time.perf_counter()
    if a.virtual_devices:  # before JAX starts
        import os

        os.environ["XLA_FLAGS"] = (os.environ.get("XLA_FLAGS", "") +
                                   f" --xla_force_host_platform_device_count={a.virtual_devices}").strip()
    from tengsim.resources import GPU_COST
    from tengsim.solvers.jax_fast import find_device

    dev = find_device(a.device)
    import jax

    n_dev = len(jax.devices(dev.platform))
    if a.quick:  # 65² and 49² pyramid cells: the grids tests/test_jax_solver.py compiles for anyway
        a.sizes, a.cpu_max = [65], max(a.cpu_max, 65)
        a.shard_sizes = [64] if n_dev > 1 else []
        group_c = [(4.73, 18.9, 0.5, 0.4, 1.0, 0.25)]
        design = [(0.946, 3.78, mu, 0.08, 1.0, 0.25) for mu in (0.3, 0.5, 1.0)]
        designs = {"small pyramid (tests' CLI_SMALL)": QUICK_DESIGN}
    else:
        group_c = [(4.73, 18.9, 0.5, 0.1, 14.0, 0.05)]
        design = [(0.946, 3.78, mu, 0.05, 3.0, 0.05) for mu in (0.3, 0.5, 1.0)]
        designs = DESIGNS
    if a.no_designs:
        designs = {}
    print(f"device: {dev} ({dev.platform}), {n_dev} device(s); sizes {a.sizes}; dtypes {a.dtypes}", flush=True)
    rows, refs, f64 = [], {}, {}
    if a.out:
        a.out.mkdir(parents=True, exist_ok=True)
        (a.out / "gpu.jsonl").write_text("")

    def left():
        return math.inf if a.deadline is None else a.deadline - (time.perf_counter() - start)

    def emit(row):
        rows.append(row)
        print(table([row]).splitlines()[-1], flush=True)
        if a.out:
            with open(a.out / "gpu.jsonl", "a") as fh:
                fh.write(json.dumps(row, default=float) + "\n")

    def skip(case, projected):
        print(f"skipped {case}: projected {projected:.0f} s, {left():.0f} s left before the deadline", flush=True)

    for n in a.sizes:
        for dt in a.dtypes:
            its = 2.2 * n ** 0.75  # cold rough iterations, roughly (881 at 1024², 8401 at 8192² on the H200)
            proj = its * GPU_COST.iteration_seconds(n * n) * (1 if dt == "float64" else 0.7) + 30
            if proj > left():
                skip(f"rough {n}² {dt}", proj)
                continue
            row = rough_row(n, dt, a.device, a.cpu_max, a.tol, a.max_iter, refs)
            f64.setdefault(n, row["F"] if dt == "float64" else None)
            emit(row)
    for n in a.shard_sizes:
        if n_dev < 2:
            print(f"skipped rough {n}² sharded: JAX has one {dev.platform} device", flush=True)
            break
        shards = max(k for k in range(1, n_dev + 1) if n % k == 0)
        proj = 2.2 * n ** 0.75 * GPU_COST.iteration_seconds(n * n / shards) + 60
        if proj > left():
            skip(f"rough {n}² on {shards} devices", proj)
            continue
        emit(shard_row(n, shards, a.device, a.tol, a.max_iter, f64.get(n)))
    for label, runs in (("group C path" + (" (dx 0.4)" if a.quick else " (dx 0.1)"), group_c),
                        ("design: group A at μ 0.3, 0.5, 1", design)):
        if left() < 60:
            skip(label, 60)
            continue
        emit(path_row(label, runs, a.device))
    solver = "gpu" if dev.platform == "gpu" else "jax"
    for label, t in designs.items():
        if left() < (60 if a.quick else 120):
            skip(f"design {label}", 120)
            continue
        emit(design_row(label, t, solver))
    md = table(rows)
    print(md)
    if a.out:
        (a.out / "gpu.json").write_text(json.dumps(rows, indent=1, default=float))
        (a.out / "gpu.md").write_text(md + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
