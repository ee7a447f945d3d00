"""Sweep scaling: the same 16-point study with 1 and with 2 LocalCluster workers, alternating.

Reports points/hour of each (best of --repeat runs, and each run), the ratio, the co-running slowdown
of the points themselves (Σ compute seconds two at a time / one at a time), and the scheduler + I/O
overhead of each run.  Writes benchmarks/results/sweep_scaling.md and .json.

    python benchmarks/sweep_scaling.py --dx 0.025
    python benchmarks/sweep_scaling.py --dx 0.025 --from-json benchmarks/results/sweep_scaling.json  # the .md again
"""
import json
import os
import shutil
import sys
import tempfile
import threading
import time
from pathlib import Path


class LoadSampler:
    """1-minute load average sampled every 5 s while a run goes on (other jobs on the machine show here)."""

    def __init__(self):
        self.samples, self._stop = [], threading.Event()
        self._t = threading.Thread(target=self._run, daemon=True)

    def _run(self):
        while not self._stop.is_set():
            self.samples.append(os.getloadavg()[0])
            self._stop.wait(5.0)

    def __enter__(self):
        self._t.start()
        return self

    def __exit__(self, *exc):
        self._stop.set()
        self._t.join()

STUDY = {"base": {"contact": {"shape": "pyramid", "N": 0.946, "cell": 3.78, "dx": 0.045, "d_min": -1.0,
                              "d_max": 3.0, "d_step": 0.1}},
         "axes": {"contact.tabor": {"start": 0.3, "stop": 0.65, "num": 16}}}


def decompose(points, phase_start, phase_s):
    """Split the workers' time in the compute phase into solving (Σ compute seconds), overhead
    (everything a worker spends between the phase start and its last point's end that is not solving:
    scheduler round trips, the point's dataset, transfer) and tail idle (a worker with nothing
    left to do while the other finishes: load imbalance, not overhead)."""
    by_worker = {}
    for p in points:
        by_worker.setdefault(p["worker_pid"], []).append(p)
    phase_end = phase_start + phase_s
    overhead = tail = 0.0
    for ps in by_worker.values():
        last = max(p["finished_unix"] for p in ps)
        overhead += (last - phase_start) - sum(p["compute_seconds"] for p in ps)
        tail += phase_end - last
    return {"overhead_s": overhead, "tail_idle_s": tail, "workers_used": len(by_worker)}


def one_run(n, dx):
    """run_study of STUDY on a fresh `tengsim sweep --workers n` LocalCluster; one row of numbers."""
    import xarray as xr

    from tengsim.study import parse_study, run_study
    from tengsim.study.runner import connect

    tmp = Path(tempfile.mkdtemp())
    t0 = time.perf_counter()
    client, cluster = connect(workers=n)  # the LocalCluster `tengsim sweep --workers n` starts
    load_before = os.getloadavg()[0]
    t1 = time.perf_counter()
    with LoadSampler() as load:
        s = run_study(parse_study(STUDY, source="sweep_scaling"), tmp / "s", client=client, quiet=True)
    t2 = time.perf_counter()
    client.close()
    cluster.close()
    points = []
    for f in (tmp / "s" / "points").glob("*.nc"):
        with xr.open_dataset(f, engine="h5netcdf") as ds:
            points.append({k: ds.attrs[k] for k in ("compute_seconds", "worker_pid", "started_unix",
                                                      "finished_unix")})
    shutil.rmtree(tmp)
    secs = [float(p["compute_seconds"]) for p in points]
    compute = sum(secs)
    parts = decompose(points, s["compute_phase_start_unix"], s["compute_phase_s"])
    return {"workers": n, "load_average_1min_after": os.getloadavg()[0],
            "load_average_1min_before": load_before, "load_average_1min_during_max": max(load.samples),
            "point_seconds_min": min(secs), "point_seconds_max": max(secs), "cpus": os.cpu_count(),
            "points": s["points"], "ok": s["ok"], "startup_s": t1 - t0, "wall_s": t2 - t1,
            "compute_s": compute, "points_per_hour": s["points"] / (t2 - t1) * 3600,
            "overhead_fraction": (n * (t2 - t1) - compute) / compute,
            "compute_phase_s": s["compute_phase_s"], "assemble_s": s["assemble_s"],
            "scheduler_io_overhead_s": parts["overhead_s"], "tail_idle_s": parts["tail_idle_s"],
            "scheduler_io_overhead_fraction": parts["overhead_s"] / compute}


def main(out=Path(__file__).parent / "results", dx=0.045, repeat=3):
    STUDY["base"]["contact"]["dx"] = dx
    rows = []
    for rep in range(repeat):  # 1 and 2 workers alternate, so that a slow spell of the host hits both
        for n in (1, 2):
            rows.append({"repeat": rep, **one_run(n, dx)})
            print({k: rows[-1][k] for k in ("repeat", "workers", "wall_s", "compute_s")}, file=sys.stderr)
    write_outputs(out, rows, dx, repeat)


def write_outputs(out, rows, dx, repeat):
    """OUT/sweep_scaling.json (the rows and the ratios) and OUT/sweep_scaling.md (the table) from ``rows``."""
    one = [r for r in rows if r["workers"] == 1]
    two = [r for r in rows if r["workers"] == 2]
    per_rep = [b["points_per_hour"] / a["points_per_hour"] for a, b in zip(one, two)]
    slowdown = [b["compute_s"] / a["compute_s"] - 1 for a, b in zip(one, two)]
    best = min(r["wall_s"] for r in one) / min(r["wall_s"] for r in two)
    summary = {"ratio_best_of": best, "ratio_per_repeat": per_rep, "co_run_slowdown": slowdown,
               "scheduler_io_overhead_fraction_max": max(r["scheduler_io_overhead_fraction"] for r in rows)}
    out.mkdir(parents=True, exist_ok=True)
    (out / "sweep_scaling.json").write_text(json.dumps({"rows": rows, **summary}, indent=2) + "\n")
    lo, hi = min(r["point_seconds_min"] for r in one), max(r["point_seconds_max"] for r in one)
    lines = ["# Sweep scaling: 1 vs 2 LocalCluster workers", "",
             f"Study: {one[0]['points']} dimensionless pyramid points (N = 0.946, L̄ = 3.78, dx = {dx}, "
             f"d_step = 0.1, μ = 0.3…0.65; one point {lo:.1f}–{hi:.1f} s on 1 worker), run {repeat} times with 1 "
             f"and 2 workers alternating, in one process (`python benchmarks/sweep_scaling.py --dx {dx}`).", "",
             "| run | workers | wall (s) | compute phase (s) | assembly (s) | Σ compute (s) | points/h | "
             "scheduler + I/O | tail idle (s) | load avg before / max during |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['repeat'] + 1} | {r['workers']} | {r['wall_s']:.1f} | {r['compute_phase_s']:.1f} | "
                     f"{r['assemble_s']:.1f} | {r['compute_s']:.1f} | {r['points_per_hour']:.0f} | "
                     f"{100 * r['scheduler_io_overhead_fraction']:.1f} % | {r['tail_idle_s']:.1f} | "
                     f"{r['load_average_1min_before']:.1f} / {r['load_average_1min_during_max']:.1f} |")
    lines += ["", f"Points/hour, 2 workers / 1 worker: **{best:.2f}** from the best wall of each; per run "
              + ", ".join(f"{x:.2f}" for x in per_rep) + ". The same points cost "
              + ", ".join(f"{100 * x:+.0f} %" for x in slowdown)
              + " more summed compute seconds two at a time than one at a time (co-running on the two vCPUs: "
              "shared cache and memory bandwidth, and whatever else the host runs on them); that alone caps "
              "the ratio at " + ", ".join(f"{2 / (1 + x):.2f}" for x in slowdown) + ".", "",
              "wall = run_study on a started cluster: validation, worker warm-up (imports), the compute phase "
              "(first submit to last point written) and the assembly of study.nc/csv. The compute phase "
              "splits, per worker, into solving (Σ compute), scheduler + I/O (the worker's time up to its last "
              "point's end that is not solving: round trips, building and sending the point's dataset; "
              "given as a fraction of Σ compute) and tail idle (waiting for the other worker's last point: "
              "load imbalance; submissions go longest first by an estimate, which equal-grid points do not "
              "separate).", "",
              f"Machine: {one[0].get('cpus', os.cpu_count())} CPUs. A load average above the CPU count means other jobs shared "
              "the cores: a second worker then gets no core of its own and the ratio measures the contention, "
              "not the sweep."]
    (out / "sweep_scaling.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    import argparse

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--dx", type=float, default=0.045, help="grid spacing of the points (smaller: longer points)")
    ap.add_argument("--repeat", type=int, default=3, help="runs of each worker count (alternating)")
    ap.add_argument("--out", type=Path, default=Path(__file__).parent / "results")
    ap.add_argument("--from-json", type=Path, default=None,
                    help="write the .json and .md from the rows of an earlier run's sweep_scaling.json, running nothing")
    a = ap.parse_args()
    if a.from_json is not None:
        rows = json.loads(a.from_json.read_text())["rows"]
        write_outputs(a.out, rows, a.dx, 1 + max(r["repeat"] for r in rows))
    else:
        main(a.out, a.dx, a.repeat)
