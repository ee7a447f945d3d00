"""Same iterates: a refactor's behaviour check.  Runs a fixed set of equilibria and records, for each,
the solver's iterations, convolutions (FFT pairs), the force F = ∬P dA and the energy:

- the paper's pyramid groups A, B and C (tengsim.cases.paper), approach and retraction on coarse grids (A also
  periodic);
- the Maugis–Dugdale sphere (R = 1, μ = 1, free cell), walked into contact and down towards pull-off;
- a 256² rough periodic surface (tengsim.shapes.Rough, LJ 9-3), each D solved cold (from the zero state).

    python benchmarks/same_iterates.py --record benchmarks/results/same_iterates.json   # baseline
    python benchmarks/same_iterates.py --check benchmarks/results/same_iterates.json    # compare

``--check`` demands equal iterations and convolutions, and |ΔF|, |Δenergy| <= 1e-12 relative (absolute
where the value is below 1 in magnitude, e.g. F ≈ 0); it prints the largest differences and exits 1 on
any violation.
"""
from __future__ import annotations

import argparse
import json
import sys
import time

import numpy as np

TOL = 1e-12


def _row(case, D, eq_like):
    return dict(case=case, D=float(D), iterations=int(eq_like["iterations"]), n_conv=int(eq_like["n_conv"]),
                F=float(eq_like["F"]), energy=float(eq_like["energy"]))


def paper_groups():
    from tengsim.cases.paper.contact import RunSettings, run_group
    rows = []
    coarse = {"A": dict(dx=0.2, d_step=0.5, d_max=4.0), "B": dict(dx=0.3, d_step=1.0, d_max=8.0),
              "C": dict(dx=0.5, d_step=1.5, d_max=13.0)}
    runs = [(g, g, kw) for g, kw in coarse.items()] + [("A periodic", "A", dict(coarse["A"], boundary="periodic"))]
    for name, group, kw in runs:
        res = run_group(group, RunSettings(tol=1e-6, **kw))
        t = res.table
        for i in range(len(t["D"])):
            rows.append(_row(f"{name}/{t['branch'][i]}", t["D"][i], {k: t[k][i] for k in
                                                                     ("iterations", "n_conv", "F", "energy")}))
    return rows


def _eq_row(case, D, eq, grid):
    return _row(case, D, dict(iterations=eq.iterations, n_conv=eq.n_conv, F=float(eq.P.sum() * grid.area),
                              energy=eq.energy))


def md_sphere():
    from tengsim.kernels import FreeKernel
    from tengsim.laws import MaugisDugdale
    from tengsim.continuation import walk_states
    from tengsim.shapes import Paraboloid
    from tengsim.solvers import FastSolver
    mu = 1.0
    shape = Paraboloid(1.0, 4.0)
    grid = shape.grid(0.08)
    U0 = shape.gap(grid)
    kernel = FreeKernel(grid, mu ** 1.5)
    Ds = [0.0, 0.2, 0.4, 0.2, 0.0, -0.2, -0.4, -0.5]
    return [_eq_row("MD sphere", D, eq, grid) for D, eq in
            walk_states(U0, MaugisDugdale(smoothing=0.2), kernel, FastSolver(1e-7, max_iter=20000), Ds)]


def rough_cold():
    from tengsim.kernels import PeriodicKernel
    from tengsim.laws import LJ93
    from tengsim.grid import Grid
    from tengsim.shapes import Rough
    from tengsim.solvers import FastSolver, Problem, State
    shape = Rough(cell=32.0, hurst=0.8, rms_height=1.0, short_cutoff=2.0, seed=3)
    grid = Grid(256, 256, 32.0 / 256, 32.0 / 256)
    U0 = shape.gap(grid)
    kernel = PeriodicKernel(grid, 0.5 ** 1.5)
    solver = FastSolver(1e-6, max_iter=5000)
    rows = []
    for D in (0.5, 1.5):
        eq = solver.solve(Problem(U0 - D + 1.0, LJ93(), kernel), State.zero(grid.shape))
        rows.append(_eq_row("rough 256² cold", D, eq, grid))
    return rows


def run_all() -> list[dict]:
    rows = []
    for part in (paper_groups, md_sphere, rough_cold):
        t = time.perf_counter()
        got = part()
        print(f"{part.__name__}: {len(got)} equilibria, {time.perf_counter() - t:.1f} s", file=sys.stderr)
        rows += got
    return rows


def compare(base: list[dict], new: list[dict]) -> list[str]:
    """Violations (empty: the same iterates); prints the largest differences."""
    bad = []
    if len(base) != len(new):
        return [f"{len(new)} equilibria, the baseline has {len(base)}"]
    worst = {"F": (0.0, None), "energy": (0.0, None)}
    for b, n in zip(base, new):
        tag = f"{b['case']} D={b['D']:g}"
        if (b["case"], b["D"]) != (n["case"], n["D"]):
            bad.append(f"{tag}: now {n['case']} D={n['D']:g}")
            continue
        for k in ("iterations", "n_conv"):
            if b[k] != n[k]:
                bad.append(f"{tag}: {k} {b[k]} -> {n[k]}")
        for k in ("F", "energy"):
            d = abs(n[k] - b[k]) / max(1.0, abs(b[k]))
            if d > worst[k][0]:
                worst[k] = (d, tag)
            if d > TOL:
                bad.append(f"{tag}: {k} {b[k]!r} -> {n[k]!r} (rel {d:.2e})")
    for k, (d, tag) in worst.items():
        print(f"largest |Δ{k}| (relative, absolute below 1): {d:.3e}" + (f" at {tag}" if tag else ""))
    return bad


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    g = ap.add_mutually_exclusive_group(required=True)
    g.add_argument("--record", metavar="FILE", help="write the baseline (JSON)")
    g.add_argument("--check", metavar="FILE", help="compare with a baseline; exit 1 on any difference")
    a = ap.parse_args(argv)
    t = time.perf_counter()
    rows = run_all()
    print(f"{len(rows)} equilibria in {time.perf_counter() - t:.1f} s")
    if a.record:
        with open(a.record, "w") as f:
            json.dump({"tolerance": TOL, "equilibria": rows}, f, indent=1)
        return 0
    with open(a.check) as f:
        base = json.load(f)["equilibria"]
    bad = compare(base, rows)
    for line in bad[:20]:
        print("DIFFERS:", line)
    print(f"{len(bad)} violations" if bad else "same iterates: all equilibria agree")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
