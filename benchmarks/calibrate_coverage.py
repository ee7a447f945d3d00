"""Coverage of tengsim calibrate's 95 % intervals over noise seeds (and its recovery), on tengsim's own curves.

    OPENBLAS_NUM_THREADS=1 python benchmarks/calibrate_coverage.py --seeds 40 --out benchmarks/results
    OPENBLAS_NUM_THREADS=1 python benchmarks/calibrate_coverage.py --free sigma,W,eps --seeds 20 --out ...
    OPENBLAS_NUM_THREADS=1 python benchmarks/calibrate_coverage.py --case paper --seeds 20 --out benchmarks/results

Truth: σ = 8 µC/m², W = 25 mJ/m², ε = 50 nm, E* = 10 MPa on two tiny pyramids (pitch 1 µm and 0.8 µm, base half
the pitch, height 0.2 µm; design tol 0.05), V_OC by Eq. 12 at 2.5 … 30 kPa every 2.5 kPa (12 points per curve, the
nodes' own pressures: the data are the model's), times (1 + 0.025 z), z standard normal, a new z per seed.
``--case paper``: the paper's groups A, B, C as in benchmarks/calibrate_paper.py (σ, W, ε free within W 30–80
mJ/m², ε 280–500 nm; 5 … 100 kPa, 2 % noise).

The first seed runs the whole calibration (``calibrate``: the (W, ε) grid, its zooms and the check at the best fit,
the designs kept in OUT/calibrate_coverage/designs); every seed then refits on that calibration's interpolation
(the surrogate is the same model for all: what varies is the noise), with the same room for the model's error.
Coverage: the fraction of seeds whose 95 % profile-likelihood interval holds the truth, with its binomial 95 %
range (Clopper–Pearson) for the count of seeds: consistent with 95 % when 0.95 lies inside it.
"""
from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

TRUE = {"sigma": 8e-6, "W": 25e-3, "eps": 50e-9}
G1 = {"shape": "pyramid", "pitch": "1um", "base": "0.5um", "height": "0.2um", "E_star": "10MPa", "eps": "50nm",
      "tol": 0.05}
G2 = {**G1, "pitch": "0.8um", "base": "0.4um"}
BOUNDS = {"W": ("10mJ/m2", "60mJ/m2"), "eps": ("30nm", "80nm")}


def _paper():
    sys.path.insert(0, str(Path(__file__).parent))
    import calibrate_paper as cp

    return {"true": cp.TRUE, "tables": [cp.table(L, 0.02) for L in cp.GROUPS.values()], "E_star": 0.59e6,
            "p_max": 100e3, "p_lo": 5e3, "p_hi": 100e3, "noise": 0.02,
            "bounds": {"W": ("30mJ/m2", "80mJ/m2"), "eps": ("280nm", "500nm")}}


CASES = {"tiny": lambda: {"true": TRUE, "tables": [G1, G2], "E_star": 10e6, "p_max": 50e3, "p_lo": 2.5e3,
                          "p_hi": 30e3, "noise": 0.025, "bounds": BOUNDS},
         "paper": _paper}


def truth(table, case=None):
    from tengsim.calibrate.surrogate import node_table
    from tengsim.design import plan_design, run_design

    c = case or CASES["tiny"]()
    t = c["true"]
    r = run_design(plan_design({**node_table(table, t["W"], t["eps"], c["E_star"], c["p_max"]), "sigma": t["sigma"]}))
    P = r.dataset["pressure"].values
    V = r.dataset["voc_eq12"].sel(branch="approach").values
    keep = (P >= c["p_lo"] - 1) & (P <= c["p_hi"] + 1)
    return P[keep], V[keep], r.status


def clopper(k, n):
    from scipy import stats

    lo = stats.beta.ppf(0.025, k, n - k + 1) if k > 0 else 0.0
    hi = stats.beta.ppf(0.975, k + 1, n - k) if k < n else 1.0
    return float(lo), float(hi)


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--seeds", type=int, default=40)
    ap.add_argument("--free", default="sigma,W")
    ap.add_argument("--case", default="tiny", choices=tuple(CASES))
    ap.add_argument("--noise", type=float, default=None, help="default: the case's (0.025 tiny, 0.02 paper)")
    ap.add_argument("--nodes", type=int, default=3)
    ap.add_argument("--out", default="benchmarks/results")
    a = ap.parse_args(argv)
    from tengsim.calibrate import calibrate, plan_calibration
    from tengsim.calibrate.data import Curve
    from tengsim.calibrate.fit import Model, fit
    from tengsim.calibrate.run import _fit_in_box

    case = CASES[a.case]()
    true = case["true"]
    if a.case == "paper" and a.free == "sigma,W":
        a.free = "sigma,W,eps"
    a.noise = case["noise"] if a.noise is None else a.noise
    out = Path(a.out)
    work = out / ("calibrate_coverage" + ("" if a.case == "tiny" else "_" + a.case))
    t0 = time.perf_counter()
    curves = [truth(g, case) for g in case["tables"]]
    assert all(c[2] == "ok" for c in curves)
    free = a.free
    bounds = {k: v for k, v in case["bounds"].items() if k in free}
    fixed_eps = {} if "eps" in free else {}
    rows, cal0 = [], None
    for seed in range(a.seeds):
        rng = np.random.default_rng(1000 + seed)
        cs = [Curve(f"seed {seed}", P, V * (1 + a.noise * rng.standard_normal(len(V))), ("approach",) * len(V))
              for P, V, _ in curves]
        prob = plan_calibration(case["tables"], cs, free, bounds)
        t = time.perf_counter()
        if cal0 is None:
            cal0 = calibrate(prob, work, n_nodes=a.nodes, zooms=2, expected_noise=a.noise,
                             progress=lambda s: print(f"  {s}", file=sys.stderr, flush=True))
            f = cal0.fit
        else:
            model = Model(prob, cal0.model.surrogates, cal0.model.geo)
            err = cal0.surrogate_error
            f = _fit_in_box(model, lambda m, box=None: fit(m, box, model_error=err))
        row = {"seed": seed, "seconds": time.perf_counter() - t, "scale": f.scale}
        for k in prob.free:
            lo, hi, olo, ohi = f.interval[k]
            row[k] = {"best": f.best[k], "lo": lo, "hi": hi, "open": [olo, ohi], "covers": lo <= true[k] <= hi}
        rows.append(row)
        print(json.dumps({k: (v if not isinstance(v, dict) else {kk: vv for kk, vv in v.items()})
                          for k, v in row.items()}, default=float), flush=True)
    n = len(rows)
    summary = {"case": a.case, "seeds": n, "free": free, "noise": a.noise, "truth": true,
               "designs_solved": cal0.nodes_solved,
               "surrogate_error": cal0.surrogate_error, "first_fit_s": rows[0]["seconds"],
               "wall_s": time.perf_counter() - t0}
    for k in rows[0]:
        if isinstance(rows[0][k], dict):
            cov = sum(r[k]["covers"] for r in rows)
            best = np.array([r[k]["best"] for r in rows])
            width = np.array([(r[k]["hi"] - r[k]["lo"]) / 2 / true[k] for r in rows])
            summary[k] = {"coverage": cov / n, "covered": cov, "binomial_95": clopper(cov, n),
                          "consistent_with_95": clopper(cov, n)[0] <= 0.95 <= clopper(cov, n)[1],
                          "median_best_rel_error": float(np.median(np.abs(best / true[k] - 1))),
                          "largest_best_rel_error": float(np.max(np.abs(best / true[k] - 1))),
                          "median_half_width_rel": float(np.median(width)),
                          "open_at_a_bound": sum(any(r[k]["open"]) for r in rows)}
    out.mkdir(parents=True, exist_ok=True)
    name = "calibrate_coverage" + ("" if a.case == "tiny" else "_" + a.case) + \
        ("" if free == "sigma,W" or a.case == "paper" else "_" + free.replace(",", "_")) + ".json"
    (out / name).write_text(json.dumps({"summary": summary, "rows": rows}, indent=1, default=float))
    print(json.dumps(summary, indent=1, default=float))


if __name__ == "__main__":
    main()
