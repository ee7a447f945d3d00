#!/usr/bin/env python
"""Converged pyramid-contact results vs the paper's partial-to-full transitions (1.75 / 5.20 / 10.95).

Runs groups A, B, C (paper Section 3, Eq. 9) on an approach–retraction path, a grid-convergence
series, and the variants a reader might suspect behind the paper's numbers (periodic kernel,
contact-edge definition, Tabor parameter, coarse grids, a pyramid of slope 1), and writes

    <out>/runs/<case>.csv   one row per equilibrium: D, F and every contact-size measure
    <out>/summary.json      per case: transition D under each definition, jumps, pull-off, F(D)
    <out>/tables.md         the tables quoted in docs/paper_comparison.md
    <out>/lambda_vs_D.png   Λc(D) of the converged runs with the paper's transitions marked
    <out>/variants.png      transition D of every variant against the paper's three numbers

Usage:  python scripts/paper_study.py --out docs/data/paper_study [--quick] [--jobs 2]

Contact-size measures recorded at every equilibrium (all as a length comparable with 2N):
  L_axis   Greenwood tensile pressure peak along the X row through the apex (engine's Λc = |2Xc|)
  L_diag   tensile peak along the diagonals through the apex: Λc = |2Xc| with (Xc, Xc) the corner
           of the contact square, as the paper words it
  L_rep    √(area where P > 0)
  L_gap0   √(area where H < 0),  L_gap02  √(area where H < 0.2)
  floor    fraction of the valley floor (U0 = 2N, outside the pyramid base) with H < 0.2
The engine is used as is; the extra measures come from an observer (tengsim.observers) passed to
simulate, which sees the same (P, H) as the engine's own summary and adds its columns to the table.
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("TENGSIM_FFT_WORKERS", "1")

import numpy as np  # noqa: E402

from tengsim.analysis import tensile_peak_offset  # noqa: E402
from tengsim.run.plan import ContactPlan
from tengsim.run.simulate import simulate  # noqa: E402
from tengsim.shapes import HeightMap, Pyramid  # noqa: E402
from tengsim.continuation import PathSpec  # noqa: E402
from tengsim.cases.paper.units import paper_scaling  # noqa: E402

PAPER = {"A": 1.75, "B": 5.20, "C": 10.95}
GROUPS = ("A", "B", "C")


# ---------------------------------------------------------------------------------------------
# extra per-state measures: an observer, one call per recorded row
def _diag_length(P, dx, i0, j0):
    """Λc = 2·Xc from the tensile peak along the four half-diagonals from the apex (averaged)."""
    n = P.shape[0]
    offs = []
    for sx in (1, -1):
        for sy in (1, -1):
            k = np.arange(n)
            ii, jj = i0 + sx * k, j0 + sy * k
            ok = (ii >= 0) & (ii < n) & (jj >= 0) & (jj < P.shape[1])
            offs.append(tensile_peak_offset(P[ii[ok], jj[ok]]))
    # offset k along the diagonal is at X = k·dx, so Λc = |2Xc| = 2·k·dx
    return 2.0 * float(np.mean(offs)) * dx


class ContactSizes:
    """Observer: the contact-size measures of the module docstring; ``floor`` masks the valley floor."""

    columns = ("L_diag", "L_rep", "L_gap0", "L_gap02", "floor")

    def __init__(self, floor=None):
        self.floor = floor

    def __call__(self, eq, ctx):
        P, H, grid = eq.P, eq.H, ctx.grid
        a = grid.area
        floor = self.floor
        return dict(
            L_diag=_diag_length(P, grid.dx, *ctx.apex),
            L_rep=float(np.sqrt(np.count_nonzero(P > 0) * a)),
            L_gap0=float(np.sqrt(np.count_nonzero(H < 0) * a)),
            L_gap02=float(np.sqrt(np.count_nonzero(H < 0.2) * a)),
            floor=float(np.mean(H[floor] < 0.2)) if floor is not None and floor.any() else float("nan"),
        )


# ---------------------------------------------------------------------------------------------
def make_shape(group, variant, dx):
    sc = paper_scaling(group)
    N, cell = sc.N, sc.cell
    if variant == "slope1":
        # the pyramid on the same base [−N, N]² with slope 1 (height N): what a factor-2
        # mis-scaling of U0 = |X−Y| + |X+Y| would give
        g = Pyramid(N, cell).grid(dx)
        X, Y = g.mesh()
        U0 = np.minimum(np.maximum(np.abs(X), np.abs(Y)), N)
        return HeightMap(-U0, cell), g, N, U0 >= N - 1e-12
    shape = Pyramid(N, cell)
    g = shape.grid(dx)
    U0 = shape.gap(g)
    return shape, g, N, U0 >= 2 * N - 1e-12


def run_case(case):
    """One approach–retraction run; returns (case, rows dict, seconds)."""
    t0 = time.perf_counter()
    shape, grid, N, floor = make_shape(case["group"], case.get("variant", ""), case["dx"])
    spec = PathSpec(case["d_min"], case["d_max"], case["d_step"])
    sizes = ContactSizes(floor)
    res = simulate(ContactPlan(shape, case["mu"], case["dx"], spec, boundary=case["boundary"], solver_tol=case["tol"], grid=grid, observers=[sizes]))
    t = res.table
    rows = {k: np.asarray(t[k]) for k in ("branch", "D", "F", "contact_length", "on_grid", "jump",
                                          "converged", "min_gap")}
    rows["L_axis"] = rows.pop("contact_length")
    for k in sizes.columns:
        rows[k] = np.asarray(t[k])
    jumps = [dict(kind=j.kind, branch=j.branch, D_before=j.D_before, D_after=j.D_after,
                  F_before=j.F_before, F_after=j.F_after, L_before=j.length_before,
                  L_after=j.length_after) for j in res.jumps]
    info = dict(nx=grid.nx, dx_actual=grid.dx, seconds=time.perf_counter() - t0,
                all_converged=res.all_converged, n_rows=len(t["D"]), jumps=jumps,
                pull_off_F=res.pull_off_force, N=N)
    return case, rows, info


# ---------------------------------------------------------------------------------------------
def first_cross(D, L, jump, target):
    """First approach D where L >= target, linearly interpolated (the step's end after a jump)."""
    hit = np.flatnonzero(L >= target)
    if len(hit) == 0:
        return float("nan")
    i = hit[0]
    if i == 0:
        return float(D[0])
    if jump[i] or L[i] == L[i - 1]:
        return float(D[i])
    return float(D[i - 1] + (target - L[i - 1]) * (D[i] - D[i - 1]) / (L[i] - L[i - 1]))


DEFS = {  # name: (column, fraction of 2N)
    "axis95": ("L_axis", 0.95), "axis99": ("L_axis", 0.99),
    "diag95": ("L_diag", 0.95), "diag99": ("L_diag", 0.99),
    "rep95": ("L_rep", 0.95), "gap0_95": ("L_gap0", 0.95), "gap02_95": ("L_gap02", 0.95),
}


def analyse(case, rows, info):
    N = info["N"]
    full = 2 * N
    app = rows["branch"] == "approach"
    D, jump = rows["D"][app], rows["jump"][app].astype(bool)
    out = {k: first_cross(D, rows[col][app], jump, f * full) for k, (col, f) in DEFS.items()}
    fl = rows["floor"][app]
    out["floor50"] = first_cross(D, np.nan_to_num(fl), jump, 0.5)
    ji = [j for j in info["jumps"] if j["branch"] == "approach"]
    jo = [j for j in info["jumps"] if j["branch"] == "retraction"]
    out["jump_in"] = [round(0.5 * (j["D_before"] + j["D_after"]), 4) for j in ji]
    out["jump_out"] = [round(0.5 * (j["D_before"] + j["D_after"]), 4) for j in jo]
    out["pull_off_F"] = info["pull_off_F"]
    grid_rows = app & rows["on_grid"].astype(bool)
    for Dq in (1.0, 3.0, 6.0, 14.0):
        k = np.flatnonzero(np.abs(rows["D"][grid_rows] - Dq) < 1e-6)
        out[f"F_at_{Dq:g}"] = float(rows["F"][grid_rows][k[0]]) if len(k) else float("nan")
    out["L_axis_end"] = float(rows["L_axis"][app][-1])
    out["full_2N"] = full
    out.update(seconds=round(info["seconds"], 1), nx=info["nx"], dx=round(info["dx_actual"], 4),
               all_converged=info["all_converged"], n_rows=info["n_rows"])
    return out


# ---------------------------------------------------------------------------------------------
def cases(quick):
    base = dict(mu=0.5, boundary="free", d_min=-1.0, d_max=14.0, d_step=0.25 if quick else 0.1,
                tol=1e-5 if quick else 1e-6, variant="")
    dxs = ({"A": [0.2, 0.15], "B": [0.2], "C": [0.2]} if quick else
           {"A": [0.2, 0.1, 0.05], "B": [0.2, 0.1, 0.07], "C": [0.2, 0.1, 0.07]})
    vdx = 0.2 if quick else 0.1
    out = []

    def add(name, group, **kw):
        c = dict(base, name=f"{name}_{group}", study=name, group=group)
        c.update(kw)
        out.append(c)

    for g in GROUPS:
        for dx in dxs[g]:
            add(f"ref_dx{dx:g}", g, dx=dx)
        add("periodic", g, dx=vdx, boundary="periodic")
        for mu in (0.3, 1.0, 2.0):
            add(f"mu{mu:g}", g, dx=vdx, mu=mu)
        for dx in (0.3, 0.5):
            add(f"coarse_dx{dx:g}", g, dx=dx)
        add("slope1", g, dx=vdx, variant="slope1")
    # most expensive first (pixels × steps)
    out.sort(key=lambda c: -(paper_scaling(c["group"]).cell / c["dx"]) ** 2 * c.get("mu", 0.5))
    return out


def write_csv(path, rows):
    cols = list(rows)
    with open(path, "w") as f:
        f.write(",".join(cols) + "\n")
        for i in range(len(rows["D"])):
            vals = []
            for c in cols:
                v = rows[c][i]
                if c == "branch":
                    vals.append("a" if v == "approach" else "r")
                elif c in ("on_grid", "jump", "converged"):
                    vals.append(str(int(bool(v))))
                else:
                    vals.append(f"{float(v):.5g}")
            f.write(",".join(vals) + "\n")


def read_csv(path):
    data = np.genfromtxt(path, delimiter=",", names=True, dtype=None, encoding="utf-8")
    rows = {k: np.asarray(data[k]) for k in data.dtype.names}
    rows["branch"] = np.where(rows["branch"] == "a", "approach", "retraction")
    return rows


# ---------------------------------------------------------------------------------------------
def fmt(v, nd=2):
    if isinstance(v, list):
        return ", ".join(f"{x:.{nd}f}" for x in v) if v else "–"
    if v is None or (isinstance(v, float) and not np.isfinite(v)):
        return "–"
    return f"{v:.{nd}f}"


def tables(summary, quick):
    s = {c["name"]: c for c in summary}
    lines = []
    dxs = sorted({c["dx_nominal"] for c in summary if c["study"].startswith("ref_")}, reverse=True)
    lines.append("### Grid convergence (free kernel, μ = 0.5)\n")
    lines.append("| group | dx | n | axis 0.95 | axis 0.99 | diag 0.95 | diag 0.99 | √A(P>0) 0.95 | "
                 "√A(H<0) 0.95 | √A(H<0.2) 0.95 | floor in | jump-in D | jump-out D | pull-off F | "
                 "F(D=3) | F(D=6) | F(D=14) | Λc(14)/2N | s |")
    lines.append("|" + "---|" * 20)
    for g in GROUPS:
        for dx in dxs:
            c = s.get(f"ref_dx{dx:g}_{g}")
            if not c:
                continue
            lines.append(
                f"| {g} | {dx:g} | {c['nx']} | {fmt(c['axis95'])} | {fmt(c['axis99'])} | {fmt(c['diag95'])} | "
                f"{fmt(c['diag99'])} | {fmt(c['rep95'])} | {fmt(c['gap0_95'])} | {fmt(c['gap02_95'])} | "
                f"{fmt(c['floor50'])} | {fmt(c['jump_in'])} | {fmt(c['jump_out'])} | {fmt(c['pull_off_F'], 3)} | "
                f"{fmt(c['F_at_3'], 3)} | {fmt(c['F_at_6'], 3)} | {fmt(c['F_at_14'], 3)} | "
                f"{c['L_axis_end'] / c['full_2N']:.3f} | {c['seconds']:.0f} |")
    lines.append("\nColumns 'axis/diag/√A … 0.95' give the first approach D at which that contact size "
                 "reaches 0.95·2N (0.99·2N); 'floor in' the first D at which half the valley floor "
                 "has H < 0.2; jumps are the midpoints of the bracketing D (resolution d_step/16).\n")
    lines.append("### Variants against the paper (transition D; paper: A 1.75, B 5.20, C 10.95)\n")
    lines.append("| variant | group | axis 0.95 | axis 0.99 | diag 0.95 | diag 0.99 | √A(P>0) 0.95 | "
                 "√A(H<0.2) 0.95 | floor in | jump-in D | jump-out D | paper |")
    lines.append("|" + "---|" * 12)
    order = []
    ref = f"ref_dx{min(d for d in dxs if d >= 0.1 - 1e-9) if not quick else 0.2:g}"
    for st in [ref, "periodic", "mu0.3", "mu1", "mu2", "coarse_dx0.3", "coarse_dx0.5", "slope1"]:
        for g in GROUPS:
            c = s.get(f"{st}_{g}")
            if c:
                order.append(c)
    for c in order:
        lines.append(
            f"| {c['study']} | {c['group']} | {fmt(c['axis95'])} | {fmt(c['axis99'])} | {fmt(c['diag95'])} | "
            f"{fmt(c['diag99'])} | {fmt(c['rep95'])} | {fmt(c['gap02_95'])} | {fmt(c['floor50'])} | "
            f"{fmt(c['jump_in'])} | {fmt(c['jump_out'])} | {PAPER[c['group']]:.2f} |")
    # best single-definition match per variant (rms of the three groups' relative errors)
    lines.append("\n### How close does each (variant, definition) come to all three paper numbers?\n")
    lines.append("| variant | definition | A | B | C | max abs. error in D | max rel. error |")
    lines.append("|---|---|---|---|---|---|---|")
    studies = sorted({c["study"] for c in summary})
    scored = []
    for st in studies:
        trio = [s.get(f"{st}_{g}") for g in GROUPS]
        if any(t is None for t in trio):
            continue
        for d in list(DEFS) + ["floor50"]:
            v = [t[d] for t in trio]
            if not all(np.isfinite(v)):
                err = float("inf")
                rel = float("inf")
            else:
                err = max(abs(x - PAPER[g]) for x, g in zip(v, GROUPS))
                rel = max(abs(x - PAPER[g]) / PAPER[g] for x, g in zip(v, GROUPS))
            scored.append((rel, err, st, d, v))
    scored.sort(key=lambda t: t[0])
    for rel, err, st, d, v in scored[:12]:
        lines.append(f"| {st} | {d} | {fmt(v[0])} | {fmt(v[1])} | {fmt(v[2])} | {fmt(err)} | {rel:.0%} |")
    return "\n".join(lines) + "\n"


def plots(out, summary, rowsets, quick):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    s = {c["name"]: c for c in summary}
    fig, axs = plt.subplots(1, 3, figsize=(13, 4))
    for ax, g in zip(axs, GROUPS):
        refs = sorted([c for c in summary if c["study"].startswith("ref_") and c["group"] == g],
                      key=lambda c: c["dx_nominal"])
        c = refs[0]
        r = rowsets[c["name"]]
        full = c["full_2N"]
        for br, ls in (("approach", "-"), ("retraction", ":")):
            m = r["branch"] == br
            ax.plot(r["D"][m], r["L_axis"][m], ls, color="C0", label=f"axis peak ({br})")
            ax.plot(r["D"][m], r["L_diag"][m], ls, color="C1", label=f"diagonal peak ({br})")
        m = r["branch"] == "approach"
        ax.plot(r["D"][m], r["L_rep"][m], "-", color="C2", lw=0.8, label="√A(P>0) (approach)")
        pc = s.get(f"periodic_{g}")
        if pc is not None and pc["name"] in rowsets:
            rp = rowsets[pc["name"]]
            mp = rp["branch"] == "approach"
            ax.plot(rp["D"][mp], rp["L_axis"][mp], "-", color="C3", lw=0.8, label="periodic, axis (approach)")
        ax.axhline(full, color="k", lw=0.6)
        ax.axhline(0.95 * full, color="k", lw=0.6, ls="--")
        ax.axvline(PAPER[g], color="r", lw=1.2, ls="--", label=f"paper transition D={PAPER[g]}")
        ax.set_title(f"group {g} (2N={full:.2f}, dx={c['dx_nominal']:g})")
        ax.set_xlabel("D")
        ax.set_ylabel("Λc")
        ax.set_xlim(-1, 14)
    axs[0].legend(fontsize=6.5, loc="lower right")
    fig.tight_layout()
    fig.savefig(out / "lambda_vs_D.png", dpi=90)
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(7, 4))
    studies = [st for st in ["ref_dx0.05", "ref_dx0.07", "ref_dx0.1", "ref_dx0.2", "periodic", "mu0.3",
                             "mu1", "mu2", "coarse_dx0.3", "coarse_dx0.5", "slope1"]
               if any(c["study"] == st for c in summary)]
    for k, g in enumerate(GROUPS):
        for j, st in enumerate(studies):
            c = s.get(f"{st}_{g}")
            if not c:
                continue
            x = j + 0.2 * (k - 1)
            ax.plot([x], [c["axis95"] / PAPER[g]], "o", color=f"C{k}", ms=4,
                    label=f"group {g}, axis 0.95" if j == 0 else None)
            ax.plot([x], [c["diag95"] / PAPER[g]], "s", mfc="none", color=f"C{k}", ms=4,
                    label=f"group {g}, diag 0.95" if j == 0 else None)
    ax.axhline(1.0, color="r", ls="--", lw=1)
    ax.set_xticks(range(len(studies)))
    ax.set_xticklabels(studies, rotation=40, ha="right", fontsize=7)
    ax.set_ylabel("computed / paper transition D")
    ax.legend(fontsize=6.5, ncol=2)
    fig.tight_layout()
    fig.savefig(out / "variants.png", dpi=90)
    plt.close(fig)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default="docs/data/paper_study")
    ap.add_argument("--quick", action="store_true", help="coarse grids and steps (minutes)")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--only", default="", help="comma list of study names to run (others reused)")
    ap.add_argument("--report-only", action="store_true", help="rebuild summary/tables/plots from runs/")
    args = ap.parse_args(argv)
    out = Path(args.out)
    (out / "runs").mkdir(parents=True, exist_ok=True)
    todo = cases(args.quick)
    if args.only:
        keep = set(args.only.split(","))
        todo_run = [c for c in todo if c["study"] in keep]
    else:
        todo_run = todo
    infos = {}
    info_path = out / "run_info.json"
    if info_path.exists():
        infos = json.loads(info_path.read_text())
    if not args.report_only:
        t0 = time.perf_counter()
        with ProcessPoolExecutor(max_workers=args.jobs) as ex:
            futs = [ex.submit(run_case, c) for c in todo_run]
            for f in as_completed(futs):
                case, rows, info = f.result()
                write_csv(out / "runs" / f"{case['name']}.csv", rows)
                infos[case["name"]] = dict(info, case=case)
                print(f"{case['name']:>22s}  n={info['nx']:4d}  {info['seconds']:7.1f} s  "
                      f"converged={info['all_converged']}", flush=True)
                info_path.write_text(json.dumps(infos, indent=1, default=float))
        print(f"total wall {time.perf_counter() - t0:.0f} s", flush=True)
    summary, rowsets = [], {}
    for c in todo:
        p = out / "runs" / f"{c['name']}.csv"
        if not p.exists() or c["name"] not in infos:
            continue
        rows = read_csv(p)
        rowsets[c["name"]] = rows
        a = analyse(c, rows, infos[c["name"]])
        summary.append(dict(name=c["name"], study=c["study"], group=c["group"], mu=c["mu"],
                            boundary=c["boundary"], dx_nominal=c["dx"], paper=PAPER[c["group"]], **a))
    (out / "summary.json").write_text(json.dumps(summary, indent=1, default=float))
    (out / "tables.md").write_text(tables(summary, args.quick))
    plots(out, summary, rowsets, args.quick)
    print((out / "tables.md").read_text())


if __name__ == "__main__":
    sys.exit(main())
