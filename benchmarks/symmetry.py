"""Symmetry on vs off (issue 22, item 3): the same run on the irreducible block and on the full grid.

    OPENBLAS_NUM_THREADS=1 python benchmarks/symmetry.py --groups A B C --dx 0.1 0.05 --repeat 2 \
        --out benchmarks/results/symmetry
    OPENBLAS_NUM_THREADS=1 python benchmarks/symmetry.py --issue --repeat 2   # the issue's pyramid command only

Per group and dx, one process: the path (approach and retraction, default D −1 → 4 in 0.25; ``--d-max``,
``--d-step``) run with ``symmetry='auto'`` and ``'off'`` alternately, ``--repeat`` times each, the fastest
kept (the machine is shared: ratios taken in the same run are what this reports).  Columns: wall seconds,
convolutions per equilibrium, the speed-up off/on, max|ΔF|/max|F|, and the peak memory (tracemalloc, one
separate untimed run each: NumPy's arrays, so the solver's workspace, the kernel's spectra and FFT buffers,
the maps) and its ratio on/off.  ``--issue``: `tengsim contact pyramid --N 0.946 --cell 3.78 --tabor 0.5
--dx 0.05 --d-min -1 --d-max 4 --d-step 0.05` with and without ``--symmetry off`` (through run_contact).
"""
from __future__ import annotations

import argparse
import json
import time
import tracemalloc
from pathlib import Path

import numpy as np

from tengsim.run.plan import ContactPlan
from tengsim.cases.paper.contact import group_shape
from tengsim.cases.paper.units import paper_scaling
from tengsim.run.simulate import simulate
from tengsim.continuation import PathSpec


def _runner(group, dx, d_max, d_step, boundary, tol):
    if group == "issue":
        cfg = dict(shape="pyramid", N=0.946, cell=3.78, tabor=0.5, dx=0.05, d_min=-1.0, d_max=4.0, d_step=0.05)
        return lambda sym: simulate({**cfg, "symmetry": sym})
    shape, mu = group_shape(group), paper_scaling(group).mu
    spec = PathSpec(-1.0, d_max, d_step)
    return lambda sym: simulate(ContactPlan(shape, mu, dx, spec, boundary=boundary, solver_tol=tol, symmetry=sym))


def _peak(fn):
    tracemalloc.start()
    try:
        fn()
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


def measure(group, dx, repeat, d_max, d_step, boundary="free", tol=1e-6):
    run = _runner(group, dx, d_max, d_step, boundary, tol)
    best, res = {"auto": np.inf, "off": np.inf}, {}
    for _ in range(repeat):
        for sym in ("auto", "off"):  # alternating: drifts of the machine's speed hit both alike
            t = time.perf_counter()
            r = run(sym)
            best[sym] = min(best[sym], time.perf_counter() - t)
            res[sym] = r
    peak = {sym: _peak(lambda: run(sym)) for sym in ("auto", "off")}
    on, off = res["auto"], res["off"]
    F1, F0 = np.asarray(on.table["F"], float), np.asarray(off.table["F"], float)
    same_rows = len(F1) == len(F0)
    row = dict(group=group, dx=on.params["dx"], grid=f"{on.params['nx']}x{on.params['ny']}",
               block=f"{on.params.get('block_nx', '-')}x{on.params.get('block_ny', '-')}",
               symmetry=on.params["symmetry"], equilibria=len(F1),
               wall_on=best["auto"], wall_off=best["off"], speedup=best["off"] / best["auto"],
               conv_per_eq_on=float(np.mean(on.table["n_conv"])), conv_per_eq_off=float(np.mean(off.table["n_conv"])),
               dF_rel=(float(np.max(np.abs(F1 - F0)) / np.max(np.abs(F0))) if same_rows else float("nan")),
               rows_on=len(F1), rows_off=len(F0),
               peak_MiB_on=peak["auto"] / 2**20, peak_MiB_off=peak["off"] / 2**20,
               memory_ratio=peak["auto"] / peak["off"])
    return row


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--groups", nargs="+", default=["A", "B", "C"])
    ap.add_argument("--dx", nargs="+", type=float, default=[0.1, 0.05])
    ap.add_argument("--d-max", type=float, default=4.0)
    ap.add_argument("--d-step", type=float, default=0.25)
    ap.add_argument("--boundary", default="free")
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--issue", action="store_true", help="only the issue's pyramid command")
    ap.add_argument("--no-issue", action="store_true", help="skip the issue's pyramid command")
    ap.add_argument("--out", default=None, help="folder for symmetry.json and symmetry.md")
    a = ap.parse_args(argv)
    cases = [] if a.issue else [(g, dx) for g in a.groups for dx in a.dx]
    if not a.no_issue:
        cases.append(("issue", 0.05))
    rows = []
    head = ("group", "dx", "grid", "block", "symmetry", "equilibria", "wall_on", "wall_off", "speedup",
            "conv_per_eq_on", "conv_per_eq_off", "dF_rel", "peak_MiB_on", "peak_MiB_off", "memory_ratio")
    print(" | ".join(head), flush=True)
    for g, dx in cases:
        r = measure(g, dx, a.repeat, a.d_max, a.d_step, a.boundary)
        rows.append(r)
        print(" | ".join(f"{r[k]:.3g}" if isinstance(r[k], float) else str(r[k]) for k in head), flush=True)
    if a.out:
        out = Path(a.out)
        out.mkdir(parents=True, exist_ok=True)
        (out / "symmetry.json").write_text(json.dumps(rows, indent=1))
        lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
        lines += ["| " + " | ".join(f"{r[k]:.3g}" if isinstance(r[k], float) else str(r[k]) for k in head) + " |"
                  for r in rows]
        (out / "symmetry.md").write_text("\n".join(lines) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
