"""Benchmark (issue 15, "Speed"): the whole A/S(P) approach curve of a 16 × 16 array of group-A cells.

The array: ``tengsim.shapes.arrays.Array`` of the paper's group-A pyramid (N = 0.946, L̄ = 3.78, μ = 0.5),
K × K cells (default 16), rms height scatter ``--scatter`` (default 2 %, normal, ``--seed``), on the
paper's 400 µm bonded film (ν = 0.49, thickness 400 µm / ℓ in X units; periodic film kernel, so the
flat array has the film's finite mean stiffness and every state stays in the LJ law's range); ``--px``
pixels per cell (default 40: dx = L̄/40 = 0.095, at least as fine as the paper's converged dx = 0.1,
and a 640² grid = 2^7·5, FFT-friendly, where dx = 0.1 itself gives 39 px/cell and 624² = 2^4·3·13).

The path: D-controlled approach only (no retraction) with the package's path machinery
(``tengsim.continuation.run_path``: warm starts, secant predictor, jump bisection), LJ93, fast solver
(tol 1e-6), from D = −1 to ``--d-max`` (default 23.5 ε, where the nominal pressure has passed 150 kPa),
fixed step ``--d-step`` (default 0.1 ε ≈ 0.7 kPa on the film) or, with ``--adaptive``, the adaptive
continuation (``PathSpec(adaptive=True)``, step ``--d-step`` with ``--refine`` halvings).

Reported: wall time, CPU time (``time.process_time``: the process and all its threads), the load
average before and after (the machine is shared), equilibria (every solver call, counted by a wrapper),
total and per-equilibrium convolutions (``Equilibrium.n_conv``, FFT pairs), and the A/S(P) curve
(observer ``array_area``: Greenwood Σ Λc,k²/(K L̄)², Eq. 12 cell by cell) at 10, 20, … 150 kPa.

Usage: python benchmarks/array_curve.py [--K 16] [--px 40] [--adaptive --d-step 0.8 --refine 3]
       [--out benchmarks/results/array_curve] (writes <out>.fixed.json or <out>.adaptive.json, and <out>.md from those present)
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

import numpy as np

import tengsim
from tengsim.cases.paper.units import paper_scaling
from tengsim.shapes.arrays import Array, ArrayGrid

T_FILM, NU = 400e-6, 0.49
TARGETS_KPA = np.arange(10, 151, 10)


class CountingSolver:
    """Wraps a solver: counts every ``solve`` call and its convolutions."""

    def __init__(self, inner, progress_every=0):
        self.inner, self.calls, self.n_conv, self.every, self.t0 = inner, 0, 0, progress_every, time.perf_counter()

    def solve(self, problem, state):
        eq = self.inner.solve(problem, state)
        self.calls += 1
        self.n_conv += eq.n_conv
        if self.every and self.calls % self.every == 0:
            print(f"  {self.calls} equilibria, {self.n_conv} conv, {time.perf_counter() - self.t0:.0f} s, "
                  f"load {os.getloadavg()[0]:.1f}", file=sys.stderr, flush=True)
        return eq

    def __getattr__(self, name):
        return getattr(self.inner, name)


def run(K=16, px=40, scatter=0.02, seed=0, d_step=0.1, d_max=23.5, adaptive=False, refine=3, film=True):
    from tengsim.kernels import make_kernel
    from tengsim.observers import ArrayArea
    from tengsim.continuation import PathSpec, run_path
    from tengsim.solvers import make_solver

    sc = paper_scaling("A")
    arr = Array("pyramid", K=K, scatter_height=scatter, seed=seed, N=sc.N, cell=sc.cell)
    dx = sc.cell / px
    grid = ArrayGrid(K * px, K * px, dx, dx, cells=K)
    U0 = arr.gap(grid)
    kp = {"thickness": T_FILM / sc.lateral, "substrate": "bonded", "poisson": NU} if film else {}
    kern = make_kernel("periodic", grid, sc.mu**1.5, **kp)
    solver = CountingSolver(make_solver("fast", tol=1e-6), progress_every=20)
    spec = PathSpec(-1.0, d_max, d_step, retract=False, adaptive=adaptive,
                    **({"refine_levels": refine} if adaptive else {}))
    load0 = os.getloadavg()
    w0, c0 = time.perf_counter(), time.process_time()
    res = run_path(U0, tengsim.LJ93(), kern, solver, spec, observers=[ArrayArea()])
    wall, cpu = time.perf_counter() - w0, time.process_time() - c0
    load1 = os.getloadavg()
    t = res.table
    D = np.asarray(t["D"], float)
    F = np.asarray(t["F"], float)
    P = sc.pressure(F / K**2) / 1e3
    A = np.asarray(t["area_fraction_greenwood"], float)
    order = np.argsort(D, kind="stable")
    D, P, A = D[order], P[order], A[order]
    curve = []
    for p in TARGETS_KPA:
        idx = np.nonzero(P >= p)[0]
        curve.append(None if len(idx) == 0 else
                     dict(P_target_kPa=float(p), P_kPa=float(P[idx[0]]), D=float(D[idx[0]]), A_S=float(A[idx[0]])))
    gsafe = tengsim.LJ93().g_safe
    mg = np.asarray(t["min_gap"], float) + 1 if "min_gap" in t else None
    return dict(K=K, px=px, grid=list(grid.shape), dx=dx, scatter=scatter, seed=seed,
                realised_rms=float(arr.heights.std()), film=film, d_step=d_step, d_max=d_max, adaptive=adaptive,
                refine_levels=spec.refine_levels, rows=int(len(D)), equilibria=solver.calls, n_conv=solver.n_conv,
                conv_per_eq=solver.n_conv / max(solver.calls, 1), wall_s=wall, cpu_s=cpu, load_before=load0,
                load_after=load1, P_max_kPa=float(P.max()),
                unconverged=int(np.count_nonzero(~np.asarray(t["converged"], bool))),
                out_of_law_range=(int(np.count_nonzero(mg < gsafe)) if mg is not None else None),
                curve=curve, D_all=D.tolist(), P_all=P.tolist(), A_all=A.tolist())


def md_section(r):
    mode = (f"adaptive (PathSpec(adaptive=True), d_step {r['d_step']}, {r['refine_levels']} halvings)"
            if r["adaptive"] else f"fixed D step {r['d_step']} ε")
    L = [f"## {r['K']} × {r['K']} group-A array, {r['grid'][0]}² grid, {mode}", "",
         f"- cells {r['K']} × {r['K']}, {r['px']} px per cell (dx = {r['dx']:.4f}), grid {r['grid'][0]}², "
         f"height scatter {r['scatter']:.0%} (seed {r['seed']}, realised rms {r['realised_rms']:.4f}), "
         + ("400 µm bonded film, ν = 0.49" if r["film"] else "half-space") + ", periodic kernel, LJ93, fast solver tol 1e-6",
         f"- D-controlled approach −1 → {r['d_max']} ε, {mode}; P_max = {r['P_max_kPa']:.1f} kPa",
         f"- **wall {r['wall_s']:.0f} s ({r['wall_s'] / 60:.1f} min), CPU {r['cpu_s']:.0f} s** "
         f"(process_time, all threads); load average (1/5/15 min) before "
         + "/".join(f"{x:.1f}" for x in r["load_before"]) + ", after " + "/".join(f"{x:.1f}" for x in r["load_after"]),
         f"- equilibria (solver calls) {r['equilibria']}, table rows {r['rows']}; convolutions {r['n_conv']} "
         f"in all, {r['conv_per_eq']:.1f} per equilibrium; wall per convolution (all solver work) {1e3 * r['wall_s'] / r['n_conv']:.1f} ms",
         f"- unconverged rows {r['unconverged']}, rows out of the law's range {r['out_of_law_range']}", "",
         "| P (kPa) | " + " | ".join(f"{int(c['P_target_kPa'])}" for c in r["curve"] if c) + " |",
         "|---|" + "---|" * sum(1 for c in r["curve"] if c),
         "| A/S | " + " | ".join(f"{c['A_S']:.4f}" for c in r["curve"] if c) + " |",
         "| D (ε) | " + " | ".join(f"{c['D']:.2f}" for c in r["curve"] if c) + " |", ""]
    return "\n".join(L)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--K", type=int, default=16)
    ap.add_argument("--px", type=int, default=40)
    ap.add_argument("--scatter", type=float, default=0.02)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--d-step", type=float, default=0.1)
    ap.add_argument("--d-max", type=float, default=23.5)
    ap.add_argument("--adaptive", action="store_true")
    ap.add_argument("--refine", type=int, default=3)
    ap.add_argument("--halfspace", action="store_true", help="half-space kernel instead of the 400 µm film")
    ap.add_argument("--out", default="benchmarks/results/array_curve")
    args = ap.parse_args(argv)
    r = run(args.K, args.px, args.scatter, args.seed, args.d_step, args.d_max, args.adaptive, args.refine,
            not args.halfspace)
    tag = "adaptive" if args.adaptive else "fixed"
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    Path(f"{out}.{tag}.json").write_text(json.dumps(r, indent=1))
    print(md_section(r))
    write_md(out)


def _interp_diff(f, a, p_lo=5.0):
    """Max |A/S_fixed − A/S_adaptive| at the 10 … 150 kPa targets, each curve interpolated linearly in P
    over its states with P >= ``p_lo`` (where P rises with D); nan where P is not monotone there."""
    vals = []
    for r in (f, a):
        P, A = np.asarray(r["P_all"]), np.asarray(r["A_all"])
        m = P >= p_lo
        if not np.all(np.diff(P[m]) > 0):
            return float("nan")
        vals.append(np.interp(TARGETS_KPA, P[m], A[m]))
    return float(np.max(np.abs(vals[0] - vals[1])))


def write_md(out):
    """<out>.md from the runs present (<out>.fixed.json, <out>.adaptive.json), with their comparison."""
    runs = {tag: json.loads(Path(f"{out}.{tag}.json").read_text())
            for tag in ("fixed", "adaptive") if Path(f"{out}.{tag}.json").exists()}
    L = ["# A/S(P) of a 16 × 16 group-A array at the converged resolution (benchmarks/array_curve.py)", "",
         "Issue 15, Speed: a whole A/S(P) curve of a 16 × 16 array of group-A cells at the paper's converged",
         "resolution on 2 cores in under 15 minutes. The machine is shared (2 cores, other jobs running): the",
         "load average is given beside each timing, with the CPU time of the process.", ""]
    L += [md_section(r) for r in runs.values()]
    if len(runs) == 2:
        f, a = runs["fixed"], runs["adaptive"]
        dA = [abs(x["A_S"] - y["A_S"]) for x, y in zip(f["curve"], a["curve"]) if x and y]
        L += ["## Adaptive against fixed", "",
              f"- equilibria {a['equilibria']} vs {f['equilibria']} ({a['equilibria'] / f['equilibria']:.2f}×), "
              f"convolutions {a['n_conv']} vs {f['n_conv']} ({a['n_conv'] / f['n_conv']:.2f}×), wall "
              f"{a['wall_s']:.0f} vs {f['wall_s']:.0f} s, CPU {a['cpu_s']:.0f} vs {f['cpu_s']:.0f} s",
              f"- A/S at 10 … 150 kPa, first state reaching P (adaptive states overshoot P by up to "
              f"{max(y['P_kPa'] - y['P_target_kPa'] for y in a['curve'] if y):.1f} kPa, fixed by up to "
              f"{max(x['P_kPa'] - x['P_target_kPa'] for x in f['curve'] if x):.1f} kPa): max |difference| {max(dA):.2e}",
              f"- A/S interpolated linearly in P at 10 … 150 kPa: max |difference| {_interp_diff(f, a):.2e}", ""]
    Path(f"{out}.md").write_text("\n".join(L))

if __name__ == "__main__":
    main()
