"""Adaptive continuation in D against today's fixed-step path (issue 14, "Speed").

    OPENBLAS_NUM_THREADS=1 python benchmarks/adaptive_path.py --groups A B C --out benchmarks/results

Problem: the paper's pyramid groups A, B, C (``paper_scaling``: N, cell, μ = 0.5), free kernel, LJ
9-3 law, FastSolver at max|r| <= 1e-6, approach from D = −1 then retraction.  Grid spacing dx = 0.2
(the paper's converged runs use 0.1; 0.2 keeps group C at seconds per curve, and the comparison is
between two paths on the same grid, so it does not depend on the grid being converged).

* fixed: ``PathSpec(d_min, d_max, 0.1)`` (refine_levels 4: smallest step 0.1/16 = 0.00625).
* adaptive: ``PathSpec(d_min, d_max, 0.8, refine_levels=7, adaptive=True, adapt_tol=…)``: largest
  step 0.8, smallest 0.8/2^7 = 0.00625, the same lattice as the fixed run's bisection.
D ranges: A −1 … 4.6, B −1 … 8.6, C −1 … 14.2 (past each group's full-contact transition; C is the
paper's −1 … 14 rounded up to a multiple of the largest step, so both runs visit the same end).

Counted: *solves* (every call of the solver, rejected adaptive steps and the fixed scheme's
predictor-confirm solves included), *rows* (equilibria in the result), convolutions (sum of n_conv
over every solve) and wall time.  F is compared by :func:`tengsim.continuation.compare_paths`: the adaptive
curve is cut at its jumps, interpolated on each continuous piece (PCHIP; linear reported too) at every D of the fixed
curve, fixed D inside an adaptive jump interval are skipped; the error is |ΔF| / max(|F|, |pull-off
F|).  Jump positions are the D_after of each recorded jump (branch, order).
"""
from __future__ import annotations

import argparse
import json
import math
import os
import platform
import sys
import time
from pathlib import Path

RANGES = {"A": (-1.0, 4.6), "B": (-1.0, 8.6), "C": (-1.0, 14.2)}


class Counting:
    """Solver proxy that counts solves and convolutions."""

    def __init__(self, inner):
        self.inner, self.name, self.tol = inner, inner.name, inner.tol
        self.solves, self.n_conv = 0, 0

    def solve(self, problem, start):
        eq = self.inner.solve(problem, start)
        self.solves += 1
        self.n_conv += eq.n_conv
        return eq


def run_group(group, dx, fixed_step, factor, tol, adapt_h, refine):
    import tengsim as ts
    from tengsim.kernels import FreeKernel
    from tengsim.continuation import PathSpec, compare_paths, run_path
    from tengsim.cases.paper.units import paper_scaling

    sc = paper_scaling(group)
    shape = ts.Pyramid(sc.N, sc.cell)
    grid = shape.grid(dx)
    kernel = FreeKernel(grid, sc.mu**1.5)
    U0 = shape.gap(grid)
    d_min, d_max = RANGES[group]
    extra = int(round(math.log2(factor)))
    specs = {
        "fixed": PathSpec(d_min, d_max, fixed_step, refine_levels=refine),
        "adaptive": PathSpec(d_min, d_max, fixed_step * factor, refine_levels=refine + extra,
                             adaptive=True, adapt_tol=tol, adapt_h=adapt_h),
    }
    out, res = {}, {}
    for name, spec in specs.items():
        solver = Counting(ts.FastSolver(1e-6))
        t0 = time.perf_counter()
        r = run_path(U0, ts.LJ93(), kernel, solver, spec)
        wall = time.perf_counter() - t0
        res[name] = r
        out[name] = dict(solves=solver.solves, rows=int(len(r.table["D"])), n_conv=solver.n_conv,
                         wall_s=round(wall, 2), converged=bool(r.all_converged),
                         pull_off_F=r.pull_off_force,
                         jumps=[(j.branch, round(j.D_before, 5), round(j.D_after, 5)) for j in r.jumps])
    cmp = compare_paths(res["fixed"], res["adaptive"])
    cmp_lin = compare_paths(res["fixed"], res["adaptive"], interp="linear")
    return dict(group=group, N=sc.N, cell=sc.cell, mu=sc.mu, grid=f"{grid.nx}x{grid.ny}", d_min=d_min,
                d_max=d_max, fixed=out["fixed"], adaptive=out["adaptive"],
                smallest_step=fixed_step / 2**refine,
                max_rel_dF=cmp["max_rel_dF"], where=cmp["where"], max_rel_dF_linear=cmp_lin["max_rel_dF"], n_compared=cmp["n_compared"],
                n_skipped=cmp["n_skipped"], max_rel_dF_same_D=cmp["max_rel_dF_same_D"],
                max_jump_dD=cmp["max_jump_dD"])


def table(rows, args) -> str:
    lines = [
        "# Adaptive continuation in D vs fixed steps (issue 14, Speed)",
        "",
        f"Command: `python benchmarks/adaptive_path.py {' '.join(sys.argv[1:])}`",
        "",
        f"Environment: {platform.processor() or platform.machine()}, {os.cpu_count()} cores, python "
        f"{platform.python_version()}, OPENBLAS_NUM_THREADS {os.environ.get('OPENBLAS_NUM_THREADS')}",
        "",
        f"Problem: pyramid groups (paper_scaling N, cell, μ = 0.5), free kernel, LJ 9-3, FastSolver "
        f"tol 1e-6, dx = {args.dx}. Fixed: d_step {args.fixed_step}, refine_levels {args.refine}. "
        f"Adaptive: d_step {args.fixed_step * args.factor:g} (largest), refine_levels "
        f"{args.refine + int(round(math.log2(args.factor)))}, adapt_tol {args.tol}, adapt_h {args.adapt_h} "
        f"(smallest step {args.fixed_step / 2**args.refine:g} in both).",
        "",
        "| group | grid | D range | solves fixed / adaptive (×) | rows fixed / adaptive | conv fixed / "
        "adaptive (×) | wall [s] fixed / adaptive | max rel ΔF (where) | linear | compared / skipped | "
        "jumps fixed (D_after) | jumps adaptive (D_after) | max jump ΔD |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        f, a = r["fixed"], r["adaptive"]

        def js(x):
            return ", ".join(f"{b[0][:3]} {d:g}" for b, d in ((j, j[2]) for j in x["jumps"])) or "none"
        lines.append(
            f"| {r['group']} | {r['grid']} | {r['d_min']:g} … {r['d_max']:g} | {f['solves']} / {a['solves']} "
            f"({f['solves'] / a['solves']:.2f}×) | {f['rows']} / {a['rows']} | {f['n_conv']} / {a['n_conv']} "
            f"({f['n_conv'] / a['n_conv']:.2f}×) | {f['wall_s']} / {a['wall_s']} | "
            f"{100 * r['max_rel_dF']:.3f} % ({r['where'][0][:3]} D={r['where'][1]:.3g}) | "
            f"{100 * r['max_rel_dF_linear']:.3f} % | "
            f"{r['n_compared']} / {r['n_skipped']} | {js(f)} | {js(a)} | {r['max_jump_dD']:.3g} |")
    lines += [
        "",
        "*solves* counts every solver call (rejected adaptive steps and predictor-confirm solves "
        "included); *rows* the equilibria in the result; *conv* the convolutions of all solves. "
        "*max rel ΔF*: the adaptive curve, cut at its jumps and interpolated by PCHIP (scipy's monotone "
        "cubic) on each piece (*linear*: the same, linearly, the curve as plotted), at every D of the fixed curve, |ΔF| / max(|F_fixed|, |pull-off F|) "
        "(`tengsim.continuation.compare_paths`); fixed D inside an adaptive jump interval are skipped. "
        "At the D both runs share (every 0.8) the states agree to the solver tolerance (max rel ΔF "
        "there: " + ", ".join(f"{r['group']} {r['max_rel_dF_same_D']:.1e}" for r in rows) + "). "
        "*max jump ΔD*: largest |ΔD_after| between jumps matched by branch and order (NaN if the "
        "numbers of jumps differ); the criterion is the smallest step.",
    ]
    return "\n".join(lines) + "\n"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--groups", nargs="+", default=["A", "B", "C"])
    ap.add_argument("--dx", type=float, default=0.2)
    ap.add_argument("--fixed-step", type=float, default=0.1)
    ap.add_argument("--refine", type=int, default=4)
    ap.add_argument("--factor", type=int, default=8, help="largest adaptive step / fixed step (power of 2)")
    ap.add_argument("--tol", type=float, default=0.15, help="adapt_tol")
    ap.add_argument("--adapt-h", type=float, default=0.5, help="adapt_h")
    ap.add_argument("--out", default=None)
    args = ap.parse_args(argv)
    rows = []
    for g in args.groups:
        r = run_group(g.upper(), args.dx, args.fixed_step, args.factor, args.tol, args.adapt_h, args.refine)
        print(json.dumps(r, default=str), flush=True)
        rows.append(r)
    md = table(rows, args)
    print(md)
    if args.out:
        out = Path(args.out)
        out.mkdir(parents=True, exist_ok=True)
        (out / "adaptive_path.md").write_text(md)
        (out / "adaptive_path.json").write_text(json.dumps(rows, indent=1, default=str))


if __name__ == "__main__":
    main()
