"""Sweep scaling: the same 8-point study with 1 and with 2 LocalCluster workers (one run each).

Reports points/hour of each (wall time of run_study on a started cluster, and with cluster start-up),
the ratio, and the scheduler + I/O overhead: (workers × wall − Σ point compute seconds) / Σ compute.
Writes benchmarks/results/sweep_scaling.md and .json.   python benchmarks/sweep_scaling.py
"""
import json
import logging
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
         "axes": {"contact.tabor": {"start": 0.3, "stop": 0.65, "num": 8}}}


def main(out=Path(__file__).parent / "results", dx=0.045):
    STUDY["base"]["contact"]["dx"] = dx
    import xarray as xr
    from dask.distributed import Client, LocalCluster

    from tengsim.study import parse_study, run_study
    from tengsim.study.execute import WORKER_ENV

    rows = []
    for n in (1, 2):
        tmp = Path(tempfile.mkdtemp())
        t0 = time.perf_counter()
        cluster = LocalCluster(n_workers=n, threads_per_worker=1, env=dict(WORKER_ENV), dashboard_address=":0",
                               silence_logs=logging.ERROR)
        client = Client(cluster)
        load_before = os.getloadavg()[0]
        t1 = time.perf_counter()
        with LoadSampler() as load:
            s = run_study(parse_study(STUDY, source="sweep_scaling"), tmp / "s", client=client, quiet=True)
        t2 = time.perf_counter()
        client.close()
        cluster.close()
        secs = [float(xr.open_dataset(f, engine="h5netcdf").attrs["compute_seconds"])
                for f in (tmp / "s" / "points").glob("*.nc")]
        compute = sum(secs)
        rows.append({"workers": n, "load_average_1min_after": os.getloadavg()[0],
                     "load_average_1min_before": load_before, "load_average_1min_during_max": max(load.samples),
                     "load_average_1min_during_mean": sum(load.samples) / len(load.samples),
                     "point_seconds_min": min(secs), "point_seconds_max": max(secs), "cpus": os.cpu_count(),
                     "points": s["points"], "ok": s["ok"], "startup_s": t1 - t0, "wall_s": t2 - t1,
                     "compute_s": compute, "points_per_hour": s["points"] / (t2 - t1) * 3600,
                     "points_per_hour_with_startup": s["points"] / (t2 - t0) * 3600,
                     "overhead_fraction": (n * (t2 - t1) - compute) / compute,
                     "compute_phase_s": s["compute_phase_s"], "assemble_s": s["assemble_s"],
                     "overhead_fraction_compute_phase": (n * s["compute_phase_s"] - compute) / compute})
        shutil.rmtree(tmp)
        print(rows[-1], file=sys.stderr)
    ratio = rows[1]["points_per_hour"] / rows[0]["points_per_hour"]
    out.mkdir(parents=True, exist_ok=True)
    (out / "sweep_scaling.json").write_text(json.dumps({"rows": rows, "ratio_2_vs_1": ratio}, indent=2) + "\n")
    lines = ["# Sweep scaling: 1 vs 2 LocalCluster workers", "",
             f"Study: 8 dimensionless pyramid points (N = 0.946, L̄ = 3.78, dx = {dx}, d_step = 0.1, μ = 0.3…0.65; "
             f"one point {rows[0]['point_seconds_min']:.1f}–{rows[0]['point_seconds_max']:.1f} s on 1 worker); "
             f"one run each, same machine, in one process (`python benchmarks/sweep_scaling.py --dx {dx}`).", "",
             "| workers | start-up (s) | wall (s) | compute phase (s) | assembly (s) | Σ compute (s) | points/h | "
             "points/h incl. start-up | overhead (wall) | overhead (compute phase) |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['workers']} | {r['startup_s']:.1f} | {r['wall_s']:.1f} | {r['compute_phase_s']:.1f} | "
                     f"{r['assemble_s']:.1f} | {r['compute_s']:.1f} | "
                     f"{r['points_per_hour']:.0f} | {r['points_per_hour_with_startup']:.0f} | "
                     f"{100 * r['overhead_fraction']:.0f} % | {100 * r['overhead_fraction_compute_phase']:.0f} % |")
    lines += ["", f"Ratio of points/hour (wall of run_study), 2 workers / 1 worker: **{ratio:.2f}**.", "",
              "wall = run_study on a started cluster: validation, worker warm-up (imports), the compute phase "
              "(first submit to last point written) and the assembly of study.nc/csv. "
              "overhead = (workers × time − Σ point compute seconds) / Σ compute: scheduler round trips, "
              "result transfer and the client's NetCDF write of each point (compute phase), plus warm-up and "
              "assembly (wall).", "",
              f"Machine: {os.cpu_count()} CPUs; 1-minute load average before / during (mean, max) / after each run: "
              + ", ".join(f"{r['load_average_1min_before']:.1f} / {r['load_average_1min_during_mean']:.1f}, "
                          f"{r['load_average_1min_during_max']:.1f} / {r['load_average_1min_after']:.1f} "
                          f"({r['workers']} worker(s))" for r in rows)
              + ". A load above the CPU count means other jobs shared the cores: a second worker then "
              "gets no core of its own and the ratio measures the contention, not the sweep."]
    (out / "sweep_scaling.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    import argparse

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--dx", type=float, default=0.045, help="grid spacing of the points (smaller: longer points)")
    ap.add_argument("--out", type=Path, default=Path(__file__).parent / "results")
    a = ap.parse_args()
    main(a.out, a.dx)
