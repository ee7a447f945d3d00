"""Peer benchmark: tengsim's adhesive constrained solver 'ram' (and 'pk') against Tamaas 2.9 (PyPI ``tamaas``;
``PolonskyKeerRey`` on the gap with its ``ExponentialAdhesionFunctional``: Rey, Anciaux & Molinari 2017) on the
same adhesive rough path, side by side in one run.  Not part of tengsim or its test suite.

Install the peer in its own environment (it runs in a subprocess; the two exchange .npz files):

    python3 -m venv /work/venvs/tamaas && /work/venvs/tamaas/bin/pip install tamaas numpy scipy

Problem (both codes): benchmarks/peer_aspher.py's periodic self-affine surface (Hurst 0.8, seed 1) on an
n×n grid, heights ×200 (rms 3.67 ε at 256²), cell L = 256 (lateral units; dx = 1 at 256², 0.5 at 512²), E* = 2
(tengsim κ = 0.5), hard wall + exponential adhesion W = 1, ρ = 1 ε (tengsim: ``Exponential(range=1)``'s
hard-wall limit; Tamaas: surface_energy 1, rho 1), under mean-gap control along 11.5 → 7.5 → 3.5 → 7.5 →
11.5 ε, each step from the last one's state (Tamaas keeps its model's state; tengsim a warm start).

Tolerances: tengsim's gap residual ``--tol`` (ε; its KKT criterion, tengsim.solvers._ram_core), Tamaas'
``--tamaas-tol`` (its relative error).  Reported per solver: CPU (time.process_time, the process's) and wall
time over the path, iterations, and per step the mean pressure and the contact area (fraction of pixels at
the wall: gap <= 1e-9·rms), with their largest differences from Tamaas' over the path.  One thread each
(OMP_NUM_THREADS=1, TENGSIM_FFT_WORKERS=1).

    OPENBLAS_NUM_THREADS=1 python benchmarks/peer_tamaas.py --sizes 256 512 --tamaas-python /work/venvs/tamaas/bin/python
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

PATH = (11.5, 7.5, 3.5, 7.5, 11.5)
L, KAPPA, SCALE = 256.0, 0.5, 200.0


def heights(n: int) -> np.ndarray:
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    from peer_aspher import surface

    return SCALE * surface(n)


def area_of(gap, h):
    return float(np.mean(gap <= 1e-9 * float(np.std(h))))


def run_tengsim(h, solver_name, tol, path=PATH):
    from tengsim.grid import Grid
    from tengsim.kernels import PeriodicKernel
    from tengsim.laws import Exponential
    from tengsim.solvers import Problem, State, make_solver

    import tengsim.plugins  # noqa: F401

    n = h.shape[0]
    grid = Grid(n, n, L / n, L / n)
    K = PeriodicKernel(grid, KAPPA)
    law = Exponential(range=1.0)
    name, _, start = solver_name.partition(":")
    kw = {"max_iter": 20000, "start": start or "scaled"} if name == "ram" else {}   # 'ram': the run's 'scaled' 
    solver = make_solver(name, tol=tol, **kw)
    st = State.zero(h.shape)
    steps = []
    c0, w0 = time.process_time(), time.perf_counter()
    for gbar in path:
        g0 = 1.0 + gbar - (h - h.mean())
        c, w = time.process_time(), time.perf_counter()
        eq = solver.solve(Problem(g0, law, K), st)
        st = eq.state
        steps.append({"gap": gbar, "cpu": time.process_time() - c, "wall": time.perf_counter() - w,
                      "iterations": eq.iterations, "converged": bool(eq.converged), "mean_p": float(eq.P.mean()),
                      "area": area_of(eq.H, h), "message": eq.message})
    return {"cpu": time.process_time() - c0, "wall": time.perf_counter() - w0, "steps": steps}


def tamaas_child(npz, out, tol):
    import tamaas as tm

    d = np.load(npz)
    h = d["h"]
    n = h.shape[0]
    model = tm.ModelFactory.createModel(tm.model_type.basic_2d, [L, L], [n, n])
    model.E, model.nu = 1.0 / KAPPA, 0.0
    surf = np.ascontiguousarray(h - h.mean())
    solver = tm.PolonskyKeerRey(model, surf, tol, tm.PolonskyKeerRey.gap, tm.PolonskyKeerRey.gap)
    adh = tm.ExponentialAdhesionFunctional(surf)
    adh.parameters = {"rho": 1.0, "surface_energy": 1.0}
    solver.addFunctionalTerm(adh)
    solver.setMaxIterations(20000)
    steps = []
    c0, w0 = time.process_time(), time.perf_counter()
    for gbar in PATH:
        c, w = time.process_time(), time.perf_counter()
        err = solver.solve(gbar)
        cpu, wall = time.process_time() - c, time.perf_counter() - w
        gap = np.asarray(model.displacement) - surf
        p = np.asarray(model.traction)
        steps.append({"gap": gbar, "cpu": cpu, "wall": wall, "error": float(err), "mean_p": float(p.mean()),
                      "area": area_of(gap, h), "mean_gap": float(gap.mean())})
    res = {"cpu": time.process_time() - c0, "wall": time.perf_counter() - w0, "steps": steps}
    with open(out, "w") as f:
        json.dump(res, f)


def run_tamaas(h, python, tol):
    with tempfile.TemporaryDirectory() as tmp:
        npz, out = os.path.join(tmp, "h.npz"), os.path.join(tmp, "out.json")
        np.savez(npz, h=h)
        env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
        got = subprocess.run([python, os.path.abspath(__file__), "--tamaas-child", npz, out, str(tol)], env=env,
                             capture_output=True, text=True)
        if got.returncode:
            return {"error": got.stderr.strip().splitlines()[-1] if got.stderr.strip() else "failed"}
        with open(out) as f:
            res = json.load(f)
        # Tamaas logs "iteration energy error" lines, the iteration counting from 0 in each solve: the last of a
        # run is that solve's iteration count
        runs, last = [], None
        for line in (got.stdout + "\n" + got.stderr).splitlines():
            f = line.split()
            if len(f) == 3 and f[0].isdigit():
                i = int(f[0])
                if last is None or i < last:
                    runs.append(i)
                runs[-1], last = i, i
        if len(runs) == len(res["steps"]):
            for s, i in zip(res["steps"], runs):
                s["iterations"] = i
        return res


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[256, 512])
    ap.add_argument("--tol", type=float, default=1e-6, help="tengsim's gap residual (ε)")
    ap.add_argument("--tamaas-tol", type=float, default=1e-10, help="Tamaas' PolonskyKeerRey tolerance")
    ap.add_argument("--tamaas-python", default="/work/venvs/tamaas/bin/python")
    ap.add_argument("--solvers", nargs="+", default=["ram"], help="tengsim solvers to run (ram = ram:scaled here, ram:shifted: the default start, pk)")
    ap.add_argument("--out", default=None, help="a JSON file for the rows")
    ap.add_argument("--tamaas-child", nargs=3, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.tamaas_child:
        tamaas_child(args.tamaas_child[0], args.tamaas_child[1], float(args.tamaas_child[2]))
        return 0
    rows = []
    load = os.getloadavg()
    for n in args.sizes:
        h = heights(n)
        row = {"n": n, "rms": float(h.std()), "load": load, "tamaas": run_tamaas(h, args.tamaas_python, args.tamaas_tol)}
        for s in args.solvers:
            row[s] = run_tengsim(h, s, args.tol)
        rows.append(row)
        print(json.dumps(row), flush=True)
    if args.out:
        with open(args.out, "w") as f:
            json.dump(rows, f, indent=1)
    print(f"\nload average at the start {load[0]:.1f} / {load[1]:.1f} / {load[2]:.1f}")
    print("| grid | solver | CPU s (wall s) over the path | iterations per step | converged | CPU / Tamaas' | "
          "max rel. diff. mean pressure | max abs. diff. area |")
    print("|---|---|---|---|---|---|---|---|")
    for r in rows:
        t = r["tamaas"]
        if "error" in t:
            print(f"| {r['n']}² | Tamaas | {t['error']} | | | | | |")
            continue
        its = "/".join(str(s.get("iterations", "?")) for s in t["steps"])
        print(f"| {r['n']}² | Tamaas | {t['cpu']:.3g} ({t['wall']:.3g}) | {its} | — | 1 | — | — |")
        for s in args.solvers:
            m = r[s]
            dp = max(abs(a["mean_p"] - b["mean_p"]) / max(abs(b["mean_p"]), 1e-300) for a, b in zip(m["steps"], t["steps"]))
            da = max(abs(a["area"] - b["area"]) for a, b in zip(m["steps"], t["steps"]))
            ok = sum(x["converged"] for x in m["steps"])
            print(f"| {r['n']}² | {s} | {m['cpu']:.3g} ({m['wall']:.3g}) | {'/'.join(str(x['iterations']) for x in m['steps'])} "
                  f"| {ok} of {len(m['steps'])} | {m['cpu'] / t['cpu']:.2f} | {dp:.1e} | {da:.1e} |")
        print("| | per step (gap: mean p Tamaas / " + " / ".join(args.solvers) + "; area) | "
              + "; ".join(f"{b['gap']}: {b['mean_p']:.6g} / " + " / ".join(f"{r[s]['steps'][i]['mean_p']:.6g}"
                                                                     for s in args.solvers)
                          + f", {b['area']:.5f}" for i, b in enumerate(t["steps"])) + " | | | | | |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
