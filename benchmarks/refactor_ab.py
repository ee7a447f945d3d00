"""A/B in one run: the fast solver before the issue-13 refactor (benchmarks/_fast_before.py) against the
package's, alternated in one process on the same problems; best of N each.

    OPENBLAS_NUM_THREADS=1 python benchmarks/refactor_ab.py --repeat 9 --out benchmarks/results

Cases: group A's full path at dx 0.1 (as run_benchmarks.py: pyramid N 0.946, cell 3.78, μ 0.5, free
kernel, D −1 → 4 → −1 in 0.1, refine_levels 0, tol 1e-6), and one cold equilibrium on the 256²
periodic rough surface of the engine tests (tol 1e-6 and 1e-8).  Runs alternate old/new and
swap which goes first each round (ABBA), so a drift of the machine's speed hits both alike.
Reports best-of-N wall and CPU seconds, the ratios new/old, and the convolutions counted by wrapping the
kernels' ``apply`` (they must be equal: same iterates).  Writes ``refactor_ab.md`` under ``--out``.
"""
from __future__ import annotations

import argparse
import platform
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from _fast_before import FastSolver as Before  # noqa: E402
from refactor_check import _group_a, _rough  # noqa: E402
from run_benchmarks import ConvCounter  # noqa: E402


def a_path(S):
    from tengsim.laws import LJ93
    from tengsim.path import PathSpec, run_path

    _, U0, K = _group_a(0.1)
    spec = PathSpec(-1.0, 4.0, 0.1, refine_levels=0)

    def run():
        return run_path(U0, LJ93(), K, S(1e-6), spec)
    return run, type(K)


def rough(S, n, tol):
    from tengsim.solvers import State

    prob = _rough(n)

    def run():
        return S(tol).solve(prob, State.zero(prob.g0.shape))
    return run, type(prob.kernel)


CASES = {
    "group A path, dx 0.1 (39², 102 rows), tol 1e-6": lambda S: a_path(S),
    "rough 256² periodic, cold, tol 1e-6": lambda S: rough(S, 256, 1e-6),
    "rough 256² periodic, cold, tol 1e-8": lambda S: rough(S, 256, 1e-8),
}


def timed(run, kcls):
    """(wall seconds, process CPU seconds, convolutions) of one run."""
    cnt = ConvCounter(kcls)
    try:
        t0, c0 = time.perf_counter(), time.process_time()
        run()
        return time.perf_counter() - t0, time.process_time() - c0, cnt.n
    finally:
        cnt.restore()


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeat", type=int, default=9)
    ap.add_argument("--out", type=Path, default=HERE / "results")
    a = ap.parse_args(argv)
    from tengsim.solvers import FastSolver as After

    rows = []
    for name, make in CASES.items():
        runs = {"old": make(Before), "new": make(After)}
        for k in runs:  # warm-up: imports, FFT plans, first-touch of the pages
            timed(*runs[k])
        t = {"old": [], "new": []}
        cpu = {"old": [], "new": []}
        conv = {}
        for i in range(a.repeat):
            order = ("old", "new") if i % 2 == 0 else ("new", "old")
            for k in order:
                s, c, nc = timed(*runs[k])
                t[k].append(s)
                cpu[k].append(c)
                conv.setdefault(k, nc)
                assert conv[k] == nc, (name, k, conv[k], nc)
        assert conv["old"] == conv["new"], (name, conv)
        bo, bn = min(t["old"]), min(t["new"])
        co, cn = min(cpu["old"]), min(cpu["new"])
        mo, mn = float(np.median(t["old"])), float(np.median(t["new"]))
        rows.append(dict(case=name, old=bo, new=bn, ratio=bn / bo, cpu_old=co, cpu_new=cn, cpu_ratio=cn / co,
                         med_ratio=mn / mo, conv=conv["new"]))
        print(f"{name}: wall old {bo:.4f} s, new {bn:.4f} s (best of {a.repeat}), new/old {bn / bo:.3f}; "
              f"CPU {co:.4f} / {cn:.4f} ({cn / co:.3f}); median wall new/old {mn / mo:.3f}; "
              f"{conv['new']} convolutions each", flush=True)

    cpu = platform.processor()
    try:
        cpu = next(l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name"))
    except (OSError, StopIteration):
        pass
    import scipy

    from tengsim import _fft
    lines = ["# FastSolver before/after the issue-13 refactor, one run", "",
             f"Command: `OPENBLAS_NUM_THREADS=1 python benchmarks/refactor_ab.py --repeat {a.repeat}`", "",
             f"Machine: {cpu}, {__import__('os').cpu_count()} cores; Python {platform.python_version()}, "
             f"numpy {np.__version__}, scipy {scipy.__version__}; FFT backend {_fft.BACKEND}.", "",
             "old = `benchmarks/_fast_before.py` (the solver at b76decc), new = `tengsim.solvers.FastSolver`; "
             f"alternated in one process (ABBA), best of {a.repeat} wall and process-CPU seconds per case "
             "(CPU time is the steadier measure when other processes share the cores; the solver runs on one "
             "thread at these sizes), and the ratio of the median wall times.", "",
             "| case | wall old [s] | wall new [s] | new/old | CPU old [s] | CPU new [s] | CPU new/old | "
             "median wall new/old | convolutions (each) |",
             "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['case']} | {r['old']:.4f} | {r['new']:.4f} | {r['ratio']:.3f} | {r['cpu_old']:.4f} | "
                     f"{r['cpu_new']:.4f} | {r['cpu_ratio']:.3f} | {r['med_ratio']:.3f} | {r['conv']} |")
    lines += ["", "Same iterates: the convolution counts are equal, and `benchmarks/refactor_check.py` finds "
              "iterations, convolutions, energies and residuals bit-identical to the old code's baseline.", ""]
    a.out.mkdir(parents=True, exist_ok=True)
    (a.out / "refactor_ab.md").write_text("\n".join(lines))
    print(f"wrote {a.out / 'refactor_ab.md'}")


if __name__ == "__main__":
    main()
