"""Same iterates before and after the FastSolver refactor (issue 13): iterations, convolutions, energies.

    OPENBLAS_NUM_THREADS=1 python benchmarks/refactor_check.py --record   # on the old code: writes the baseline
    OPENBLAS_NUM_THREADS=1 python benchmarks/refactor_check.py            # on the new code: asserts equality
    OPENBLAS_NUM_THREADS=1 python benchmarks/refactor_check.py --solver before   # the frozen copy (sanity)

Cases (~20 s in all on 2 cores): group A's full path at dx 0.1 (as run_benchmarks.py: −1 → 4 → −1 in
0.1, refine_levels 0, tol 1e-6); group A at dx 0.2, tol 1e-8, warm D sequence (the engine tests');
one group-A equilibrium with the sweeps forced into 97-point blocks and 3 threads; the periodic
rough surface of the tests at 64² and 128² (tol 1e-10) and 256² (tol 1e-8 and 1e-6), cold; a convex
Hertz case (Repulsive law, E ~ 1e3).  Per equilibrium it records iterations, convolutions, message,
energy and residual (as float.hex); the check requires equal iterations, convolutions and messages,
and energies / residuals equal to 1e-12 relative (it reports how many are bit-identical).
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
BASELINE = HERE / "results" / "refactor_baseline.json"


def solver_class(which):
    if which == "before":
        sys.path.insert(0, str(HERE))
        from _fast_before import FastSolver
    else:
        from tengsim.solvers import FastSolver
    return FastSolver


def _group_a(dx):
    from tengsim.shapes import Pyramid
    from tengsim.kernels import FreeKernel

    shape = Pyramid(0.946, 3.78)
    grid = shape.grid(dx)
    return grid, shape.gap(grid), FreeKernel(grid, 0.5 ** 1.5)


def _rough(n, seed=3):
    from tengsim.shapes import random_rough
    from tengsim.laws import LJ93
    from tengsim.kernels import PeriodicKernel
    from tengsim.solvers import Problem

    surf = random_rough(n, n * 0.25, hurst=0.8, rms_height=1.0, short_cutoff=2.0, seed=seed)
    grid = surf.grid()
    U0 = surf.gap(grid)
    return Problem(U0 - float(np.quantile(U0, 0.05)) + 1.0, LJ93(), PeriodicKernel(grid, 0.5 ** 1.5))


def _rec(eq):
    return dict(iterations=int(eq.iterations), n_conv=int(eq.n_conv), message=eq.message,
                energy=float(eq.energy).hex(), residual=float(eq.residual).hex())


def case_a_path(S):
    from tengsim.laws import LJ93
    from tengsim.path import PathSpec, run_path

    _, U0, K = _group_a(0.1)
    res = run_path(U0, LJ93(), K, S(1e-6), PathSpec(-1.0, 4.0, 0.1, refine_levels=0))
    T = res.table
    return [dict(iterations=int(i), n_conv=int(c), message="converged" if ok else "not converged",
                 energy=float(e).hex(), residual=float(r).hex())
            for i, c, ok, e, r in zip(T["iterations"], T["n_conv"], T["converged"], T["energy"], T["residual"])]


def case_a_sequence(S):
    from tengsim.laws import LJ93
    from tengsim.solvers import Problem, State

    grid, U0, K = _group_a(0.2)
    st, out = State.zero(grid.shape), []
    for D in (0.0, 0.5, 1.0, 1.5, 2.0, 2.5):
        eq = S(1e-8).solve(Problem(U0 - D + 1.0, LJ93(), K), st)
        st = eq.state
        out.append(_rec(eq))
    return out


def case_a_blocks(S):
    import os

    import tengsim.solvers._sweep as sweep
    from tengsim.laws import LJ93
    from tengsim.solvers import Problem, State

    grid, U0, K = _group_a(0.1)
    old, env = sweep.BLOCK, os.environ.get("TENGSIM_THREADS")
    sweep.BLOCK, os.environ["TENGSIM_THREADS"] = 97, "3"
    try:
        return [_rec(S(1e-8).solve(Problem(U0 - 1.5 + 1.0, LJ93(), K), State.zero(grid.shape)))]
    finally:
        sweep.BLOCK = old
        if env is None:
            del os.environ["TENGSIM_THREADS"]
        else:
            os.environ["TENGSIM_THREADS"] = env


def _rough_case(n, tol):
    def run(S):
        from tengsim.solvers import State

        prob = _rough(n)
        return [_rec(S(tol, max_iter=3000).solve(prob, State.zero(prob.g0.shape)))]
    return run


def case_hertz(S):
    from tengsim.shapes import Paraboloid
    from tengsim.laws import Repulsive
    from tengsim.kernels import FreeKernel
    from tengsim.solvers import Problem, State

    shape = Paraboloid(0.1, 9.0)
    grid = shape.grid(0.2)
    K = FreeKernel(grid, 10.0)
    return [_rec(S(1e-6).solve(Problem(shape.gap(grid) - D + 1.0, Repulsive(), K), State.zero(grid.shape)))
            for D in (60.0, 150.0)]


CASES = {
    "A_path_dx0.1_tol1e-6": case_a_path,
    "A_sequence_dx0.2_tol1e-8": case_a_sequence,
    "A_blocks97_threads3_tol1e-8": case_a_blocks,
    "rough64_tol1e-10": _rough_case(64, 1e-10),
    "rough128_tol1e-10": _rough_case(128, 1e-10),
    "rough256_tol1e-8": _rough_case(256, 1e-8),
    "rough256_tol1e-6": _rough_case(256, 1e-6),
    "hertz_repulsive_tol1e-6": case_hertz,
}


def run_all(S):
    return {name: fn(S) for name, fn in CASES.items()}


def compare(ref, new):
    """(list of failures, number of bit-identical energies, total equilibria)."""
    bad, same, total = [], 0, 0
    for name, rows in ref.items():
        got = new[name]
        if len(got) != len(rows):
            bad.append(f"{name}: {len(got)} equilibria, baseline {len(rows)}")
            continue
        for i, (a, b) in enumerate(zip(rows, got)):
            total += 1
            for k in ("iterations", "n_conv", "message"):
                if a[k] != b[k]:
                    bad.append(f"{name}[{i}] {k}: {b[k]} vs baseline {a[k]}")
            for k in ("energy", "residual"):
                x, y = float.fromhex(a[k]), float.fromhex(b[k])
                if abs(x - y) > 1e-12 * max(abs(x), abs(y), 1e-300):
                    bad.append(f"{name}[{i}] {k}: {y!r} vs baseline {x!r}")
            same += a["energy"] == b["energy"] and a["residual"] == b["residual"]
    return bad, same, total


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--record", action="store_true", help="write the baseline from the chosen solver")
    ap.add_argument("--solver", choices=["package", "before"], default="package")
    ap.add_argument("--baseline", type=Path, default=BASELINE)
    a = ap.parse_args(argv)
    res = run_all(solver_class(a.solver))
    summary = {k: (sum(r["iterations"] for r in v), sum(r["n_conv"] for r in v)) for k, v in res.items()}
    for k, (it, nc) in summary.items():
        print(f"{k:32s} iterations {it:6d}  convolutions {nc:6d}")
    if a.record:
        a.baseline.parent.mkdir(parents=True, exist_ok=True)
        a.baseline.write_text(json.dumps(res, indent=0))
        print(f"wrote {a.baseline}")
        return 0
    bad, same, total = compare(json.loads(a.baseline.read_text()), res)
    print(f"{total} equilibria: {same} bit-identical (energy and residual), {len(bad)} differences")
    for b in bad[:40]:
        print("  " + b)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
