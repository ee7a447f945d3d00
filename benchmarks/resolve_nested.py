"""Nested start of the automatic refinement (issue 22 item 1): convolutions per grid with and without.

    python benchmarks/resolve_nested.py sphere|pyramid|periodic [--nested energy|unpredicted|off|both|all] [--rows]

Runs tengsim.resolve.run_contact(cfg) and prints params['resolution'] (convolutions per grid), the
observables and the jumps of every grid; --rows also breaks each grid's convolutions down by kind of row.
"""
from __future__ import annotations

import argparse
import json
import math
import time

import numpy as np

import tengsim.contact as tc
import tengsim.continuation as tcont
from tengsim.resolve import run_contact

CASES = {
    "sphere": dict(shape="sphere", law="md", tabor=1.0, cell=16.0, d_min=-2.0, d_max=0.5, d_step=0.05,
                   resolve="auto", dx=0.2, max_pixels=40000),
    "pyramid": dict(shape="pyramid", N=0.946, cell=3.78, tabor=0.5, d_min=-1.0, d_max=4.0, d_step=0.05,
                    resolve="auto"),
    "periodic": dict(shape="pyramid", N=0.946, cell=3.78, tabor=0.5, d_min=-1.0, d_max=4.0, d_step=0.05,
                     resolve="auto", boundary="periodic"),
    "periodic_sphere": dict(shape="sphere", law="md", tabor=1.0, cell=16.0, d_min=-2.0, d_max=0.5, d_step=0.05,
                            resolve="auto", dx=0.2, max_pixels=40000, boundary="periodic"),
}


def breakdown(res):
    t = res.table
    br, jump, on = np.asarray(t["branch"]), np.asarray(t["jump"], bool), np.asarray(t["on_grid"], bool)
    n = np.asarray(t["n_conv"], float)
    first = np.zeros(len(n), bool)
    for b in ("approach", "retraction"):
        idx = np.flatnonzero(br == b)
        if len(idx):
            first[idx[0]] = True
    return {"rows": int(len(n)), "first": int(n[first].sum()), "jump_rows": int(n[jump].sum()),
            "refined_rows": int(n[~on & ~jump].sum()), "other": int(n[on & ~jump & ~first].sum()),
            "max_row": int(n.max())}


def run(case, nested, rows):
    cfg = dict(CASES[case])
    levels = []
    orig = tc.simulate

    def spy(*a, **kw):
        r = orig(*a, **kw)
        levels.append(r)
        return r

    tc.simulate = spy
    spent = []  # every solve's convolutions, also those the table does not keep (a discarded jump try)
    solve0 = tcont.Branch.solve

    def solve(self, D, start):
        eq = solve0(self, D, start)
        while len(spent) < len(levels) + 1:
            spent.append(0)
        spent[len(levels)] += eq.n_conv
        return eq

    tcont.Branch.solve = solve
    kw = {} if nested is None else {"nested": nested}
    t0 = time.perf_counter()
    try:
        res = run_contact(cfg, **kw)
    finally:
        tc.simulate = orig
        tcont.Branch.solve = solve0
    wall = time.perf_counter() - t0
    tab = res.params["resolution"]
    out = {"case": case, "nested": nested, "wall": wall, "resolution": tab,
           "resolve_status": res.params["resolve_status"], "all_solves": spent,
           "hints": [[r.params.get(k, 0) for k in ("nested_hints", "nested_taken", "nested_conv")] for r in levels],
           "jumps": [[[j.branch, j.D_before, j.D_after] for j in r.jumps] for r in levels]}
    if rows:
        out["breakdown"] = [breakdown(r) for r in levels]
    return out


def show(o):
    tab = o["resolution"]
    names = [k for k in tab if k not in ("dx", "nx", "ny", "seconds", "convolutions", "status")]
    print(f"== {o['case']} nested={o['nested']} ({o['wall']:.0f} s, {o['resolve_status']})")
    for i in range(len(tab["dx"])):
        obs = "  ".join(f"{n}={tab[n][i]:.5g}" for n in names)
        print(f"  dx {tab['dx'][i]:.4f} {tab['nx'][i]}x{tab['ny'][i]} conv {tab['convolutions'][i]:6d} (all solves {o['all_solves'][i]:6d}) "
              f"{tab['seconds'][i]:6.1f}s {tab['status'][i]}  {obs}")
        print(f"     jumps {o['jumps'][i]}")
        print(f"     hints offered/taken/conv {o['hints'][i]}")
        if "breakdown" in o:
            print(f"     {o['breakdown'][i]}")


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("case", choices=sorted(CASES))
    ap.add_argument("--nested", choices=("energy", "unpredicted", "always", "correction", "off", "both", "all", "default"), default="both")
    ap.add_argument("--rows", action="store_true")
    ap.add_argument("--json")
    a = ap.parse_args()
    modes = {"energy": ["energy"], "unpredicted": ["unpredicted"], "always": ["always"], "correction": ["correction"], "off": [False], "both": [False, "energy"],
             "all": [False, "energy", "unpredicted"], "default": [None]}[a.nested]
    outs = []
    for m in modes:
        o = run(a.case, m, a.rows)
        show(o)
        outs.append(o)
    if a.json:
        with open(a.json, "w") as f:
            json.dump(outs, f, default=lambda x: None if isinstance(x, float) and math.isnan(x) else x)
