"""Calibration of the grid-status criterion (tengsim.status) against grid convergence (issue 22 item 2).

For each registered shape and law, a coarse → fine sequence of grids runs the same short approach–
retraction path around jump-in and pull-off; every run's observables (pull-off force, jump-in D,
jump-out D) are compared with the finest grid's.  A run whose observables moved by more than 1 %
(pull-off: relative; jump D: 0.01 ε, the D scale) must not be ``ok``; a run within 1 % must not be
flagged.  The old criterion (the cohesive window on the apex row only, snap number > 1) is
reported beside the new one (every contact edge, walls, snap number > SNAP_LIMIT).

    python benchmarks/status_calibration.py [--only NAME ...] [--out benchmarks/results/status_calibration.md]

writes a Markdown table (and a .json beside it).  Small cells and short paths: the whole table takes
a few minutes on one core.
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

from tengsim.run.plan import ContactPlan
import tengsim as ts
from tengsim import status as st
from tengsim.laws import make_law
from tengsim.registry import SHAPES

HERE = Path(__file__).resolve().parent
TOL = 0.01       # 1 %: the resolve tolerance of issue 22
D_SCALE = 1.0    # jump D moves are measured in ε (the law's range is ≈ 1 ε)

# name, shape (registry name, fields), law (name, params), μ, boundary, dx sequence (coarse → fine), path
CASES = [
    ("sphere-lj-mu1", ("sphere", dict(cell=5.0)), ("lj93", {}), 1.0, "free", [0.6, 0.4, 0.28, 0.2, 0.1],
     (-2.5, 0.5, 0.25, 5)),
    ("sphere-lj-mu3", ("sphere", dict(cell=4.0)), ("lj93", {}), 3.0, "free", [0.3, 0.2, 0.14, 0.1, 0.05],
     (-5.0, 0.25, 0.25, 5)),
    ("sphere-md-mu1", ("sphere", dict(cell=5.0)), ("md", {}), 1.0, "free", [0.2, 0.14, 0.1, 0.08, 0.067, 0.05],
     (-2.0, 0.25, 0.25, 5)),
    ("sphere-exp-mu1", ("sphere", dict(cell=5.0)), ("exp", {}), 1.0, "free", [0.4, 0.28, 0.2, 0.1],
     (-2.5, 0.5, 0.25, 5)),
    ("sphere-repulsive", ("sphere", dict(cell=4.0)), ("repulsive", {}), 1.0, "free", [0.4, 0.2, 0.1],
     (-0.5, 1.0, 0.25, 0)),
    ("pyramid-lj-A", ("pyramid", dict(N=0.946, cell=3.78)), ("lj93", {}), 0.5, "free", [0.4, 0.2, 0.1, 0.05],
     (-1.0, 2.0, 0.25, 5)),
    ("cone-lj-mu1", ("cone", dict(slope=1.0, cell=6.0)), ("lj93", {}), 1.0, "free", [0.4, 0.2, 0.1, 0.05],
     (-2.0, 1.0, 0.25, 5)),
    ("hemisphere-lj-mu1", ("hemisphere", dict(radius=2.0, cell=6.0)), ("lj93", {}), 1.0, "free",
     [0.4, 0.2, 0.1, 0.05], (-2.0, 0.5, 0.25, 5)),
    ("cube-lj-mu1", ("cube", dict(half_width=1.0, height=5.0, cell=3.0)), ("lj93", {}), 1.0, "free",
     [0.2, 0.1, 0.05, 0.025, 0.0167], (-3.0, 0.3, 0.25, 5)),
    ("cube-lj-mu2.4", ("cube", dict(half_width=1.0, height=5.0, cell=3.0)), ("lj93", {}), 2.4, "free",
     [0.2, 0.1, 0.05, 0.025], (-6.0, 0.3, 0.25, 5)),
    ("cube-lj-mu5", ("cube", dict(half_width=1.0, height=5.0, cell=3.0)), ("lj93", {}), 5.0, "free",
     [0.1, 0.05, 0.025], (-10.0, 0.3, 0.25, 4)),
    ("line-lj-mu2.4", ("line", dict(half_width=1.0, height=5.0, cell=3.0)), ("lj93", {}), 2.4, "periodic",
     [0.2, 0.1, 0.05, 0.025], (-6.0, 0.3, 0.25, 5)),
    ("punch-md-mu2.4", ("flat_punch", dict(radius=1.0, step=5.0, cell=3.0)), ("md", dict(smoothing=0.4)), 2.4,
     "free", [0.2, 0.1, 0.05, 0.025], (-6.0, 0.3, 0.25, 5)),
    ("array-scatter-lj-mu1", ("array", dict(pattern="sphere", K=2, cell=4.0, scatter_height=0.3, seed=1)),
     ("lj93", {}), 1.0, "periodic", [0.4, 0.2, 0.1], (-2.5, 0.5, 0.25, 5)),
    ("array-tilt-lj-mu1", ("array", dict(pattern="sphere", K=1, cell=5.0, scatter_tilt=0.2, seed=2)),
     ("lj93", {}), 1.0, "periodic", [0.4, 0.2, 0.1], (-2.5, 0.5, 0.25, 5)),
    ("rough-lj-mu1", ("rough", dict(cell=8.0, hurst=0.8, rms_height=0.5, short_cutoff=1.0, seed=3)),
     ("lj93", {}), 1.0, "periodic", [0.4, 0.2, 0.1], (-1.5, 0.5, 0.25, 5)),
]


class OldZone:
    """The old criterion's measure: the cohesive window along the X row through the apex."""

    columns = ("old_zone",)

    def __call__(self, eq, ctx):
        return {"old_zone": st.process_zone_width(eq.H, ctx.grid.dx, ctx.apex, ctx.law)}


def make_shape(name, fields):
    if name == "array":
        from tengsim.shapes.arrays import Array

        f = dict(fields)
        return Array(pattern=f.pop("pattern"), K=f.pop("K"), scatter_height=f.pop("scatter_height", 0.0),
                     scatter_tilt=f.pop("scatter_tilt", 0.0), seed=f.pop("seed", 0), **f)
    return SHAPES.get(name)(**fields)


def observables(res) -> dict:
    t = res.table
    jumps = res.jumps
    ins = [j for j in jumps if j.branch == "approach"]
    outs = [j for j in jumps if j.branch == "retraction"]
    return dict(pull_off=res.pull_off_force,
                jump_in=ins[0].D_after if ins else float("nan"),
                jump_out=outs[-1].D_after if outs else float("nan"),
                F_max=float(np.max(t["F"])))


def run_case(case) -> list[dict]:
    name, (sname, fields), (lname, lparams), mu, boundary, dxs, (d_min, d_max, d_step, levels) = case
    law = make_law(lname, **lparams)
    out = []
    for dx in dxs:
        shape = make_shape(sname, fields)
        path = ts.PathSpec(d_min, d_max, d_step, refine_levels=levels)
        t0 = time.perf_counter()
        res = ts.simulate(ContactPlan(shape, mu, dx, path, boundary=boundary, law=law, observers=[OldZone()]))
        t = res.table
        pz = np.asarray(t["process_zone"], float)
        old = np.asarray(t["old_zone"], float)
        snap = float(res.params["pixel_snap_number"])
        with np.errstate(invalid="ignore"):
            old_flag = bool(np.any(old < 0.75 * res.grid.dx) or (snap > 1.0 and np.isfinite(old).any()))
        out.append(dict(case=name, shape=sname, law=lname, mu=mu, dx=float(res.grid.dx), nx=res.grid.nx,
                        zone=float(np.nanmin(pz)) if np.isfinite(pz).any() else float("nan"),
                        old_zone=float(np.nanmin(old)) if np.isfinite(old).any() else float("nan"),
                        snap=snap, face=float(res.params.get("face_uncertainty", 0.0)), status=res.status,
                        old_status="under_resolved" if old_flag else "ok",
                        converged=bool(res.all_converged), seconds=round(time.perf_counter() - t0, 1),
                        **observables(res)))
        print(json.dumps(out[-1]), flush=True)
    return judge(out)


def restatus(r: dict) -> str:
    """A run's status from its summary (narrowest zone, snap number, face uncertainty) under the current
    thresholds of tengsim.status: the same rules as the rows' (``--retable``)."""
    if not r["converged"]:
        return "not_converged"
    z = r["zone"]
    judged = z == z
    bad = judged and (z < st.RESOLUTION * r["dx"] or r["snap"] > st.SNAP_LIMIT or r["face"] > st.FACE_LIMIT)
    return "under_resolved" if bad else "ok"


def judge(out: list[dict], again: bool = False) -> list[dict]:
    """Errors against the finest grid of one case (the last row) and the verdict of each coarser run
    (``again``: the status worked out anew from the run's summary, :func:`restatus`)."""
    fine = out[-1]
    for r in out:
        if again:
            r["status"] = restatus(r)
        e_po = abs(r["pull_off"] / fine["pull_off"] - 1) if fine["pull_off"] < 0 else 0.0
        e_in = abs(r["jump_in"] - fine["jump_in"]) / D_SCALE if np.isfinite(fine["jump_in"]) else 0.0
        e_out = abs(r["jump_out"] - fine["jump_out"]) / D_SCALE if np.isfinite(fine["jump_out"]) else 0.0
        e_in = e_in if np.isfinite(e_in) else 1.0  # a jump on the finest grid and none here: moved
        e_out = e_out if np.isfinite(e_out) else 1.0
        r.update(err_pull_off=e_po, err_jump_in=e_in, err_jump_out=e_out)
        r["moved"] = bool(max(e_po, e_in, e_out) > TOL) if r is not fine else False
        r["verdict"] = (("reference" if r["status"] == "ok" else "reference, flagged") if r is fine else
                        "right" if r["moved"] == (r["status"] != "ok") else
                        "missed" if r["moved"] else "over-strict")
    return out


def table(rows) -> str:
    head = ("| case | dx | zone (new) | zone/dx | snap s | face | pull-off | Δ pull-off | Δ jump-in D | Δ jump-out D "
            "| old status | new status | verdict |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|\n")
    lines = []
    for r in rows:
        z = r["zone"]
        lines.append(f"| {r['case']} | {r['dx']:.3g} | {z:.3g} | {z / r['dx']:.2f} | {r['snap']:.2f} | "
                     f"{100 * r['face']:.2g} % | {r['pull_off']:.4g} | {100 * r['err_pull_off']:.2f} % | "
                     f"{r['err_jump_in']:.3f} | "
                     f"{r['err_jump_out']:.3f} | {r['old_status']} | {r['status']} | {r['verdict']} |")
    return head + "\n".join(lines) + "\n"


def main(argv=None):
    ap = argparse.ArgumentParser(description="Calibrate tengsim.status against grid convergence.")
    ap.add_argument("--only", nargs="*", default=None, help="case names (default: all)")
    ap.add_argument("--out", default=str(HERE / "results" / "status_calibration.md"))
    ap.add_argument("--retable", metavar="JSON", help="re-judge and re-tabulate the runs of an earlier JSON")
    a = ap.parse_args(argv)
    names = [c[0] for c in CASES]
    bad = [n for n in (a.only or []) if n not in names]
    if bad:
        ap.error(f"unknown case {bad[0]!r} (cases: {', '.join(names)})")
    rows = []
    t0 = time.time()
    if a.retable:
        old = json.loads(Path(a.retable).read_text())
        for name in dict.fromkeys(r["case"] for r in old):
            rows += judge([r for r in old if r["case"] == name], again=True)
    for case in CASES if not a.retable else ():
        if a.only and case[0] not in a.only:
            continue
        rows += run_case(case)
    out = Path(a.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    n = sum(not r["verdict"].startswith("reference") for r in rows)
    right = sum(r["verdict"] == "right" for r in rows)
    old_right = sum(not r["verdict"].startswith("reference") and r["moved"] == (r["old_status"] != "ok")
                    for r in rows)
    text = (f"# Status calibration (benchmarks/status_calibration.py)\n\n"
            f"Observables against the finest grid of each case; 'moved': pull-off off by > {100 * TOL:g} % or "
            f"a jump D off by > {TOL:g} ε.  New criterion right on {right} of {n} runs, the old one on "
            f"{old_right} of {n}.  Compute: {sum(r['seconds'] for r in rows):.0f} s, the runs' own times (2 shared cores; "
            f"this table: {time.time() - t0:.0f} s).\n\n" + table(rows))
    out.write_text(text)
    out.with_suffix(".json").write_text(json.dumps(rows, indent=1))
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
