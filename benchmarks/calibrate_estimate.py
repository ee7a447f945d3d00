"""How well calibrate's printed estimate of the whole run holds (issue 48, item 7): a three-parameter case.

    OPENBLAS_NUM_THREADS=1 python benchmarks/calibrate_estimate.py --out benchmarks/results

σ, W and ε free on two small pyramids (pitch 1 and 0.8 µm, base half the pitch, height 0.2/0.16 µm, E* 10 MPa,
tol 0.05: tests/test_calibrate.py's geometries), data made by tengsim at σ = 8 µC/m², W = 25 mJ/m², ε = 50 nm with
2.5 % noise (seed 7), bounds W 10–60 mJ/m², ε 30–90 nm, 3 nodes per axis, 2 zooms. Every progress line is kept with
its time; each estimate of the whole run ("about X more") is set against the time that was in fact left.
Written: OUT/calibrate_estimate.json (the estimates, the actual wall and CPU time, designs expected and solved).
"""
from __future__ import annotations

import argparse
import json
import re
import shutil
import sys
import time
from pathlib import Path

import numpy as np

TRUE = {"sigma": 8e-6, "W": 25e-3, "eps": 50e-9}
G1 = {"shape": "pyramid", "pitch": "1um", "base": "0.5um", "height": "0.2um", "E_star": "10MPa", "eps": "50nm",
      "tol": 0.05}
G2 = {**G1, "pitch": "0.8um", "base": "0.4um", "height": "0.16um"}
UNITS = {"s": 1.0, "min": 60.0, "h": 3600.0}


def seconds(text: str) -> float:
    m = re.fullmatch(r"\s*([\d.]+)\s*(s|min|h)\s*", text)
    return float(m.group(1)) * UNITS[m.group(2)] if m else float("nan")


def curve(table, sigma, W, eps, p_max=50e3):
    from tengsim.calibrate.surrogate import node_table
    from tengsim.design import plan_design, run_design

    r = run_design(plan_design({**node_table(table, W, eps, 10e6, p_max), "sigma": sigma}))
    P = r.dataset["pressure"].values
    V = r.dataset["voc_eq12"].sel(branch="approach").values
    keep = (P > 0) & (P <= 30e3 + 1)
    return P[keep], V[keep]


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", default="benchmarks/results")
    ap.add_argument("--nodes", type=int, default=3)
    ap.add_argument("--zooms", type=int, default=2)
    a = ap.parse_args(argv)
    from tengsim.calibrate import calibrate, plan_calibration
    from tengsim.calibrate.data import Curve

    out = Path(a.out)
    work = out / "calibrate_estimate"
    shutil.rmtree(work, ignore_errors=True)
    rng = np.random.default_rng(7)
    curves = []
    for name, g in (("g1", G1), ("g2", G2)):
        P, V = curve(g, TRUE["sigma"], TRUE["W"], TRUE["eps"])
        curves.append(Curve(name, P, V * (1 + 0.025 * rng.standard_normal(len(V))), ("approach",) * len(V)))
    prob = plan_calibration([G1, G2], curves, "sigma,W,eps", "W=10mJ/m2:60mJ/m2,eps=30nm:90nm")
    lines = []
    t0, c0 = time.perf_counter(), time.process_time()

    def progress(msg):
        lines.append((time.perf_counter() - t0, msg))
        print(f"[{lines[-1][0]:7.1f} s] {msg}", file=sys.stderr)

    cal = calibrate(prob, work, n_nodes=a.nodes, zooms=a.zooms, progress=progress)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    est = []
    for t, msg in lines:
        m = re.search(r"the whole calibration: about (.+?) more \((\d+) designs expected", msg)
        if m:
            left = wall - t
            est.append({"at_s": round(t, 1), "estimate_left_s": seconds(m.group(1)), "designs_expected_left":
                        int(m.group(2)), "actual_left_s": round(left, 1),
                        "ratio": round(seconds(m.group(1)) / left, 3) if left > 0 else None})
    res = {"wall_s": round(wall, 1), "cpu_s": round(cpu, 1), "designs_solved": cal.nodes_solved,
           "designs_cached": cal.nodes_cached, "estimates": est, "first_line": lines[0][1] if lines else "",
           "best": {k: float(v) for k, v in cal.fit.best.items()} if hasattr(cal.fit, "best") else None}
    (out / "calibrate_estimate.json").write_text(json.dumps(res, indent=1))
    print(json.dumps(res, indent=1))


if __name__ == "__main__":
    main()
