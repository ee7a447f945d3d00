"""A design's solver tolerance: its reported numbers with each equilibrium solved to max|r| <= 0.01 × tol (the
design's default, 1e-4 ε at tol = 1 %) against the same grid solved to 1e-6 ε (a contact run's default).

    python benchmarks/design_solver_tol.py                     # the README's pyramid and cone, the tests' small pyramid
    python benchmarks/design_solver_tol.py examples/own_design/cone.toml --grid 1

For each design: the design's first refinement grid (``--grid K``: the K-th), the path a design walks there, once
per solver tolerance; prints the largest relative change of A/S (approach and retraction, every asked pressure,
relative to max(A/S, 0.01)), the pull-off force, the jump D values and the hysteresis, the
iterations spent (discarded solves included) and the wall time of each, and writes them to ``--out`` (JSON).
"""
from __future__ import annotations

import argparse
import dataclasses
import json
import sys
import time
import tomllib
from pathlib import Path

import numpy as np

SMALL = {"shape": "pyramid", "pitch": "1um", "base": "0.5um", "height": "0.2um", "E_star": "5MPa", "W": "20mJ/m2",
         "eps": "50nm", "p_max": "50kPa", "p_step": "5kPa", "name": "tests' small pyramid"}


def one(table, grid_index, tol):
    from tengsim.continuation import walker
    from tengsim.design import plan_design
    from tengsim.design import walk as _walk
    from tengsim.run import grids as _grids, refine as _refine
    from tengsim.design.curves import branch_curves
    from tengsim.run.plan import plan_contact

    plan = plan_design(table)
    cplan = dataclasses.replace(plan_contact(plan.contact_table), solver_tol=tol)
    refinement = _refine.plan_refinement(cplan, plan)
    dx = refinement.dx
    d_max, _ = _refine.find_range(refinement)
    g = _grids.refinement_grids(cplan.shape, dx, grid_index + 1)[grid_index]
    spent = []
    solve = walker.Walker.solve

    def counting(self, D, start):
        eq = solve(self, D, start)
        spent.append(int(eq.iterations))
        return eq

    walker.Walker.solve = counting
    try:
        t0 = time.perf_counter()
        res = _walk._simulate(cplan, g.dx, d_max)
        wall = time.perf_counter() - t0
    finally:
        walker.Walker.solve = solve
    c = branch_curves(res, plan)
    jumps = {f"jump_{j.branch}_D": float(j.D_after) for j in res.jumps}
    return plan.name, f"{g.nx}x{g.ny}", {
        "area_approach": np.asarray(c["approach"]["area"], float),
        "area_retraction": np.asarray(c["retraction"]["area"], float),
        "pull_off": float(res.pull_off_force), "hysteresis": float(res.hysteresis), **jumps,
        "iterations": int(sum(spent)), "solves": len(spent), "wall_s": wall, "status": str(res.status)}


def rel(a, b, floor):
    a, b = np.atleast_1d(np.asarray(a, float)), np.atleast_1d(np.asarray(b, float))
    ok = np.isfinite(a) & np.isfinite(b)
    return float(np.max(np.abs(a[ok] - b[ok]) / np.maximum(np.abs(b[ok]), floor))) if ok.any() else 0.0


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("designs", nargs="*", help="design TOML files (default: the README's pyramid and cone, and "
                    "the tests' small pyramid)")
    ap.add_argument("--grid", type=int, default=0, help="which refinement grid (0: the first)")
    ap.add_argument("--tols", type=float, nargs=2, default=(1e-4, 1e-6), metavar=("DESIGN", "REFERENCE"))
    ap.add_argument("--out", type=Path, default=None, help="JSON file for the table")
    a = ap.parse_args(argv)
    tables = [tomllib.loads(Path(p).read_text())["design"] for p in a.designs] or [
        tomllib.loads(Path(p).read_text())["design"]
        for p in ("examples/own_design/pyramid.toml", "examples/own_design/cone.toml")] + [SMALL]
    rows = []
    print("| design | grid | A/S (both branches) | pull-off | hysteresis | jump D | iterations (design / reference) "
          "| wall s | status |")
    print("|---|---|---|---|---|---|---|---|---|")
    for t in tables:
        name, grid, x = one(t, a.grid, a.tols[0])
        _, _, y = one(t, a.grid, a.tols[1])
        jd = [abs(x[k] - y[k]) for k in x if k.startswith("jump_") and k in y]
        row = {"design": name, "grid": grid, "tol_design": a.tols[0], "tol_reference": a.tols[1],
               "area": max(rel(x["area_approach"], y["area_approach"], 0.01),
                           rel(x["area_retraction"], y["area_retraction"], 0.01)),
               "pull_off": rel(x["pull_off"], y["pull_off"], 1e-300),
               "hysteresis": rel(x["hysteresis"], y["hysteresis"], 1e-300),
               "jump_D_abs": max(jd) if jd else 0.0,
               "iterations": [x["iterations"], y["iterations"]], "wall_s": [x["wall_s"], y["wall_s"]],
               "status": [x["status"], y["status"]]}
        rows.append(row)
        print(f"| {name} | {grid} | {row['area']:.2e} | {row['pull_off']:.2e} | {row['hysteresis']:.2e} | "
              f"{row['jump_D_abs']:.3g} ε | {x['iterations']} / {y['iterations']} "
              f"({x['iterations'] / max(y['iterations'], 1):.2f}) | {x['wall_s']:.1f} / {y['wall_s']:.1f} | "
              f"{x['status']} / {y['status']} |", flush=True)
    if a.out is not None:
        a.out.parent.mkdir(parents=True, exist_ok=True)
        a.out.write_text(json.dumps(rows, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
