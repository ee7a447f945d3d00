"""Group-A arrays with height scatter: A/S(P) and V_OC(P) (Eq. 12) over the pressures of Fig. 8.

For each K (cells per side) and rms height scatter s, a periodic K × K super-cell of the paper's
group-A pyramid (N = 0.946, L̄ = 3.78, μ = 0.5, E* = 0.59 MPa, W = 54 mJ/m², L = 2 µm) is approached in
D (LJ93 law, periodic kernel, fast solver, dx = 0.2; D steps 0.025, then 0.0025 from 0.5 kPa on) until
the nominal pressure passes 150 kPa.  The state at a pressure P is the first approach state whose
pressure reaches P (what a load-controlled press reaches, jumps included).  A/S is the ``array_area`` observer's Greenwood area Σ Λc,k²/(K L̄)²
(Eq. 12's λc²/L², cell by cell) and, for comparison, the repulsive area fraction; V_OC =
σ (A/S) T/(ε_r ε0) with σ = 5.84 µC/m², ε_r = 2.40, T = 400 µm (``tengsim.device.voc_polymer``).

Usage: python scripts/scatter_study.py [--quick] [--out docs/data]; then --waviness for the waviness section.
Writes scatter_study.md, scatter_study.csv (and scatter_study_waviness.csv) and scatter_study.png in --out.
Convergence runs (issue 15): python scripts/scatter_study.py --dx 0.1 --K 4 --seeds 0 1 --scatter 0 2 5 10 20
appends each (dx, K, s, seed) run to scatter_convergence.csv / _runs.csv and rewrites scatter_convergence.md
(runs already there are skipped, so a study can be built one run at a time).
"""
from __future__ import annotations

import argparse
import csv
import sys
import time
from pathlib import Path

import numpy as np

import tengsim
from tengsim.cases.paper.units import paper_scaling
from tengsim.shapes.arrays import Array
from tengsim.device import voc_polymer

SIGMA, EPS_R, T = 5.84e-6, 2.40, 400e-6
TARGETS_KPA = np.arange(10, 151, 10)


def approach(shape, mu, dx, p_of_F, p_max_kpa=150.0, coarse=0.025, fine=0.0025, p_switch_kpa=0.5,
             kernel_params=None, d_max=20.0):
    """D-controlled approach of ``shape`` (periodic kernel with ``kernel_params``, e.g. a film; LJ93, fast
    solver) from D = −1 in steps of ``coarse`` until the pressure passes ``p_switch_kpa``, then of ``fine``
    until it passes ``p_max_kpa`` (or D passes ``d_max``); each state warm-started from the last.  Returns a
    list of row dicts (also used by scripts/fig8_array.py)."""
    from tengsim.analysis import apex_index
    from tengsim.kernels import make_kernel
    from tengsim.observers import ArrayArea, Context, Summary
    from tengsim.solvers import Problem, State, make_solver
    from tengsim.status import process_zone_width

    grid = shape.grid(dx)
    U0 = shape.gap(grid)
    law, kern = tengsim.LJ93(), make_kernel("periodic", grid, mu**1.5, **(kernel_params or {}))
    solver = make_solver("fast", tol=1e-6)
    apex = apex_index(U0)
    ctx = Context(grid, apex, U0, law, kern)
    obs, summ = ArrayArea(), Summary()
    state, D, rows = State.zero(grid.shape), -1.0, []
    while True:
        eq = solver.solve(Problem(U0 - D + 1.0, law, kern), state)
        state = eq.state
        s, a = summ(eq, ctx), obs(eq, ctx)
        p = p_of_F(s["F"])
        rows.append(dict(D=D, P_kPa=p, converged=eq.converged, in_law_range=s["min_gap"] + 1 >= law.g_safe,
                         n_conv=eq.n_conv, process_zone=process_zone_width(eq.H, grid.dx, apex, law), **a))
        if p >= p_max_kpa or D > d_max:
            return rows
        D = round(D + (fine if p >= p_switch_kpa else coarse), 10)


def run_case(K, s, seed, dx=0.2, waviness=0.0, wavelength=1.0):
    sc = paper_scaling("A")
    arr = Array("pyramid", K=K, scatter_height=s, seed=seed, N=sc.N, cell=sc.cell, waviness_amplitude=waviness,
                waviness_wavelength=wavelength)
    t = approach(arr, sc.mu, dx, lambda F: sc.pressure(F / K**2) / 1e3)
    p_kpa = np.array([r["P_kPa"] for r in t])
    rows = []
    for target in TARGETS_KPA:
        idx = np.nonzero(p_kpa >= target)[0]
        if len(idx) == 0:
            rows.append(None)
            continue
        r = t[int(idx[0])]
        a = float(r["area_fraction_greenwood"])
        rows.append(dict(K=K, scatter=s, seed=seed, P_target_kPa=float(target), P_kPa=float(r["P_kPa"]),
                         D=float(r["D"]), A_S_greenwood=a, A_S_repulsive=float(r["area_fraction_repulsive"]),
                         cells_in_contact=int(r["cells_in_contact"]),
                         V_OC=float(voc_polymer(a, SIGMA, EPS_R, T)), in_law_range=bool(r["in_law_range"]),
                         converged=bool(r["converged"])))
    n_flag = sum(1 for r in t if not r["in_law_range"] and r["P_kPa"] <= 150)
    n_unconv = sum(1 for r in t if not r["converged"])
    return rows, t, n_flag, n_unconv, arr


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="K = 2, 4 only, one seed")
    ap.add_argument("--out", default="docs/data")
    ap.add_argument("--waviness", action="store_true",
                    help="only the waviness cases (K = 4, wavelength 4 cells), as a section of scatter_study.md")
    g = ap.add_argument_group("convergence runs (any of these selects them; results go to --name.* in --out, "
                              "runs already there are skipped)")
    g.add_argument("--dx", type=float, help="grid spacing in ε-lateral units (default 0.2)")
    g.add_argument("--K", type=int, nargs="+", help="cells per side (default 4)")
    g.add_argument("--seeds", type=int, nargs="+", help="seeds (default 0); s = 0 runs the first only")
    g.add_argument("--scatter", type=float, nargs="+", help="rms height scatter in %% (default 0)")
    g.add_argument("--name", default="scatter_convergence", help="file stem of the convergence data")
    g.add_argument("--force", action="store_true", help="re-run (replace) runs already in the data")
    args = ap.parse_args(argv)
    bad = check_args(args)
    if bad:
        print(f"scatter_study.py: error: {bad}", file=sys.stderr)
        return 2
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    if is_convergence(args):
        return convergence_part(out, args)
    if args.waviness:
        return waviness_part(out)
    scatters = (0.0, 0.01, 0.02, 0.05, 0.10, 0.20, 0.30)
    plan = [(2, (0, 1, 2)), (4, (0, 1)), (8, (0,))]
    if args.quick:
        plan = [(2, (0,)), (4, (0,))]
    all_rows, meta = [], []
    t0 = time.perf_counter()
    for K, seeds in plan:
        for s in scatters:
            for seed in (seeds if s > 0 else seeds[:1]):
                t1 = time.perf_counter()
                rows, states, n_flag, n_unconv, arr = run_case(K, s, seed)
                all_rows += [r for r in rows if r]
                meta.append(dict(K=K, scatter=s, seed=seed, seconds=time.perf_counter() - t1,
                                 n_flag=n_flag, n_states=len(states), n_unconverged=n_unconv,
                                 realised=float(arr.heights.std()),
                                 D_first=next((r["D"] for r in states if r["cells_in_contact"] > 0), np.nan),
                                 D_10=next((r["D"] for r in states if r["P_kPa"] >= 10), np.nan),
                                 D_150=states[-1]["D"]))
                print(f"K={K} s={s:.2f} seed={seed}: {meta[-1]['seconds']:.1f} s, flagged {n_flag}", file=sys.stderr,
                      flush=True)
    total = time.perf_counter() - t0
    with open(out / "scatter_study.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(all_rows[0]))
        w.writeheader()
        w.writerows(all_rows)
    write_md(out, all_rows, meta, total, scatters, plan)
    plot(out, all_rows, scatters, plan)


def waviness_part(out, K=4, cells=4, amplitudes=(0.25, 0.5, 1.0, 2.0)):
    """Plate/film waviness a·½[cos 2πX/λ + cos 2πY/λ] (λ = ``cells`` cells), no scatter; the section
    '## Waviness' of scatter_study.md is written (replaced) with A/S and V_OC at 10 … 150 kPa."""
    sc = paper_scaling("A")
    lam_m = cells * sc.L
    L = ["## Waviness", "",
         f"K = {K}, waviness wavelength λ = {cells} cells = {lam_m * 1e6:g} µm, no height scatter, amplitude a in ε "
         f"(ε = {sc.eps * 1e9:.0f} nm; peak to valley 2a). p_W = π E* a/λ is the non-adhesive full-contact pressure "
         "of a 1-D sinusoid of amplitude a (Westergaard; Johnson 1985 §13.2), a guide to the order of this 2-D "
         "form's.", "",
         "| a (ε) | a (nm) | p_W (kPa) | " + " | ".join(f"A/S @ {p} kPa" for p in (10, 50, 100, 150))
         + " | V_OC 10 → 150 kPa (V) | cells in contact 10 / 150 kPa | flagged | seconds |",
         "|" + "---|" * 10]
    rows_all = []
    for a in amplitudes:
        t1 = time.perf_counter()
        rows, states, n_flag, n_unconv, _ = run_case(K, 0.0, 0, waviness=a, wavelength=cells)
        rows_all += [r | {"waviness_eps": a} for r in rows if r]
        pick = {r["P_target_kPa"]: r for r in rows if r}
        pw = np.pi * sc.E_star * a * sc.eps / lam_m / 1e3
        L.append(f"| {a:g} | {a * sc.eps * 1e9:.0f} | {pw:.1f} | "
                 + " | ".join(f"{pick[p]['A_S_greenwood']:.3f}" if p in pick else "—" for p in (10., 50., 100., 150.))
                 + f" | {pick[10.]['V_OC']:.1f} → {pick[150.]['V_OC']:.1f} | "
                 f"{pick[10.]['cells_in_contact']} / {pick[150.]['cells_in_contact']} of {K * K} | {n_flag} | "
                 f"{time.perf_counter() - t1:.0f} |")
        print(f"waviness a={a}: done", file=sys.stderr, flush=True)
    with open(out / "scatter_study_waviness.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows_all[0]))
        w.writeheader()
        w.writerows(rows_all)
    path = out / "scatter_study.md"
    text = path.read_text() if path.exists() else ""
    findings = text[text.index("## Findings"):] if "## Findings" in text else ""
    head = text[:text.index("## Waviness")] if "## Waviness" in text else text[:len(text) - len(findings)]
    path.write_text(head.rstrip() + "\n\n" + "\n".join(L) + "\n\n" + findings)


def _mean(rows, K, s, P, key):
    v = [r[key] for r in rows if r["K"] == K and r["scatter"] == s and r["P_target_kPa"] == P]
    return (float(np.mean(v)), float(np.std(v)), len(v)) if v else (np.nan, np.nan, 0)


def write_md(out, rows, meta, total, scatters, plan):
    L = ["# Group-A arrays with height scatter: A/S(P) and V_OC(P) over the pressures of Fig. 8", "",
         "Generated by `scripts/scatter_study.py` (data: `scatter_study.csv`, figure: `scatter_study.png`).",
         "Periodic K × K super-cells of the group-A pyramid (N = 0.946, L̄ = 3.78, μ = 0.5, LJ93, dx = 0.2,",
         "D steps 0.025, then 0.0025 from 0.5 kPa on), approached in D until the nominal pressure passes",
         "150 kPa; the state at P is the first approach state whose pressure reaches P.",
         "A/S = Σ_cells Λc,k²/(K L̄)² (Greenwood contact",
         "length per cell, Eq. 12 cell by cell; observer `array_area`); V_OC = σ (A/S) T/(ε_r ε0),",
         "σ = 5.84 µC/m², ε_r = 2.40, T = 400 µm. Height scatter s: rms of the relative pyramid height",
         "(normal); mean ± std over seeds where more than one.", ""]
    Ps = (10, 50, 100, 150)
    L.append("| K | s | seeds | " + " | ".join(f"A/S @ {p} kPa" for p in Ps) + " | V_OC 10 → 150 kPa (V) | "
             "V_OC(150)/V_OC(10) | cells in contact @ 10 kPa |")
    L.append("|" + "---|" * (6 + len(Ps)))
    for K, seeds in plan:
        for s in scatters:
            a = [_mean(rows, K, s, p, "A_S_greenwood") for p in Ps]
            v10, v150 = _mean(rows, K, s, 10, "V_OC"), _mean(rows, K, s, 150, "V_OC")
            c10 = _mean(rows, K, s, 10, "cells_in_contact")
            cells = " | ".join(f"{m:.3f}" + (f" ± {sd:.3f}" if n > 1 else "") for m, sd, n in a)
            L.append(f"| {K} | {s:.0%} | {a[0][2]} | {cells} | {v10[0]:.1f} → {v150[0]:.1f} | "
                     f"{v150[0] / v10[0]:.3f} | {c10[0]:.1f} of {K * K} |")
    L += ["", "Runs (flagged: states up to 150 kPa compressed beyond the LJ law's range, g < g_safe):", "",
          "| K | s | seed | realised rms | states | flagged ≤ 150 kPa | unconverged | seconds |",
          "|---|---|---|---|---|---|---|---|"]
    for m in meta:
        L.append(f"| {m['K']} | {m['scatter']:.0%} | {m['seed']} | {m['realised']:.4f} | {m['n_states']} | "
                 f"{m['n_flag']} | {m['n_unconverged']} | {m['seconds']:.1f} |")
    L += ["", "D_first: first D with a cell in contact; D_10, D_150: first D at 10 and 150 kPa.", "",
          "| K | s | seed | D_first | D_10 | D_150 |", "|---|---|---|---|---|---|"]
    for m in meta:
        L.append(f"| {m['K']} | {m['scatter']:.0%} | {m['seed']} | {m['D_first']:.3f} | {m['D_10']:.4f} | "
                 f"{m['D_150']:.4f} |")
    L += ["", f"Total {total:.0f} s on this machine (2 shared cores).", ""]
    path = out / "scatter_study.md"
    keep = ""  # the waviness section and a hand-written '## Findings' section survive a re-run
    text = path.read_text() if path.exists() else ""
    for mark in ("## Waviness", "## Findings"):
        if mark in text:
            keep = text[text.index(mark):]
            break
    path.write_text("\n".join(L) + ("\n" + keep if keep else ""))

# ---- convergence runs (issue 15): --dx / --K / --seeds / --scatter ------------------------------

RUN_FIELDS = ("dx", "K", "scatter", "seed", "realised", "n_states", "n_out_of_range", "n_under_resolved",
              "n_unconverged", "min_process_zone", "D_first", "D_10", "D_150", "seconds")
PS_REPORT = (10.0, 50.0, 100.0, 150.0)


def is_convergence(args) -> bool:
    return any(v is not None for v in (args.dx, args.K, args.seeds, args.scatter))


def check_args(args) -> str | None:
    """The first bad option value as one line (None if all are fine)."""
    if args.dx is not None and not (np.isfinite(args.dx) and 0 < args.dx <= 1.0):
        return f"--dx must be in (0, 1], got {args.dx:g}"
    for k in args.K or ():
        if k < 1:
            return f"--K must be >= 1, got {k}"
    for sd in args.seeds or ():
        if sd < 0:
            return f"--seeds must be >= 0, got {sd}"
    for sc in args.scatter or ():
        if not (np.isfinite(sc) and 0 <= sc < 100):
            return f"--scatter must be in [0, 100) %, got {sc:g}"
    if is_convergence(args) and (args.quick or args.waviness):
        return "--quick/--waviness cannot be combined with --dx/--K/--seeds/--scatter"
    return None


def convergence_plan(args) -> list[tuple[float, int, float, int]]:
    """(dx, K, s, seed) of each asked run, s as a fraction; s = 0 takes the first seed only."""
    dx = 0.2 if args.dx is None else float(args.dx)
    seeds = args.seeds or [0]
    plan = []
    for K in args.K or [4]:
        for sp in args.scatter or [0.0]:
            s = round(sp / 100.0, 6)
            plan += [(dx, int(K), s, int(sd)) for sd in (seeds if s > 0 else seeds[:1])]
    return plan


def _key(r) -> tuple:
    return (round(float(r["dx"]), 6), int(r["K"]), round(float(r["scatter"]), 6), int(r["seed"]))


def read_csv(path: Path) -> list[dict]:
    if not path.exists():
        return []
    with open(path, newline="") as fh:
        return [{k: _num(v) for k, v in r.items()} for r in csv.DictReader(fh)]


def _num(v):
    if v in ("True", "False"):
        return v == "True"
    try:
        f = float(v)
    except (TypeError, ValueError):
        return v
    return int(f) if f.is_integer() and "." not in v and "e" not in v.lower() else f


def write_csv(path: Path, rows: list[dict]) -> None:
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)


def run_status(states, dx) -> dict:
    """Counts of flagged states up to 150 kPa (tengsim.status.flags: out of the law's range,
    under-resolved, not converged) and the smallest measured process zone."""
    from tengsim.status import NOT_CONVERGED, OUT_OF_LAW_RANGE, UNDER_RESOLVED, flags

    keep = [r for r in states if r["P_kPa"] <= 150]
    table = {k: np.array([r[k] for r in keep]) for k in ("D", "converged", "in_law_range", "process_zone")}
    f = flags(table, dx)
    pz = table["process_zone"].astype(float)
    return dict(n_out_of_range=int(f[OUT_OF_LAW_RANGE].sum()), n_under_resolved=int(f[UNDER_RESOLVED].sum()),
                n_unconverged=int(f[NOT_CONVERGED].sum()),
                min_process_zone=float(np.nanmin(pz)) if np.isfinite(pz).any() else float("nan"))


def convergence_part(out: Path, args) -> int:
    """Run the asked (dx, K, s, seed) cases one after another, skipping those already in
    ``<name>_runs.csv`` (unless --force); after each, append to ``<name>.csv`` / ``<name>_runs.csv`` and
    rewrite ``<name>.md``."""
    data, runs_path = out / f"{args.name}.csv", out / f"{args.name}_runs.csv"
    rows, runs = read_csv(data), read_csv(runs_path)
    for dx, K, s, seed in convergence_plan(args):
        key = (round(dx, 6), K, s, seed)
        if any(_key(m) == key for m in runs):
            if not args.force:
                print(f"dx={dx:g} K={K} s={s:.0%} seed={seed}: already in {runs_path.name}, skipped",
                      file=sys.stderr)
                continue
            rows = [r for r in rows if _key(r) != key]
            runs = [m for m in runs if _key(m) != key]
        t1 = time.perf_counter()
        res, states, _, _, arr = run_case(K, s, seed, dx=dx)
        sec = time.perf_counter() - t1
        rows += [dict(dx=dx) | r for r in res if r]
        meta = dict(dx=dx, K=K, scatter=s, seed=seed, realised=float(arr.heights.std()), n_states=len(states),
                         **run_status(states, dx),
                         D_first=next((r["D"] for r in states if r["cells_in_contact"] > 0), np.nan),
                         D_10=next((r["D"] for r in states if r["P_kPa"] >= 10), np.nan),
                         D_150=states[-1]["D"], seconds=round(sec, 2))
        runs.append(meta)
        rows.sort(key=lambda r: _key(r) + (r["P_target_kPa"],))
        runs.sort(key=_key)
        write_csv(data, rows)
        write_csv(runs_path, runs)
        write_convergence_md(out / f"{args.name}.md", rows, runs, args.name)
        print(f"dx={dx:g} K={K} s={s:.0%} seed={seed}: {sec:.1f} s, flagged {meta['n_out_of_range']} out of range, "
              f"{meta['n_under_resolved']} under-resolved, {meta['n_unconverged']} unconverged", file=sys.stderr,
              flush=True)
    return 0


def _at(rows, key, P, col="A_S_greenwood"):
    v = [r[col] for r in rows if _key(r) == key and float(r["P_target_kPa"]) == P]
    return float(v[0]) if v else float("nan")


def _ms(v, fmt="{:.3f}"):
    v = [x for x in v if x == x]
    if not v:
        return "—"
    return fmt.format(np.mean(v)) + (" ± " + fmt.format(np.std(v)) if len(v) > 1 else "")


def convergence_tables(rows, runs) -> list[str]:
    """Markdown lines: per (dx, K, s) means over seeds, the dx 0.1 vs 0.2 pairs (same K, s, seed) and
    the K trend of V_OC(150)/V_OC(10) at each dx.  V_OC ∝ A/S, so the ratio is A/S(150)/A/S(10)."""
    keys = sorted({_key(m) for m in runs})
    groups = sorted({k[:3] for k in keys})
    L = ["## A/S and V_OC(150)/V_OC(10), mean ± std over seeds", "",
         "| dx | K | s | seeds | " + " | ".join(f"A/S @ {p:g} kPa" for p in PS_REPORT)
         + " | V_OC(150)/V_OC(10) |", "|" + "---|" * (5 + len(PS_REPORT))]
    for dx, K, s in groups:
        ks = [k for k in keys if k[:3] == (dx, K, s)]
        a = [_ms([_at(rows, k, p) for k in ks]) for p in PS_REPORT]
        ratio = _ms([_at(rows, k, 150.0) / _at(rows, k, 10.0) for k in ks])
        L.append(f"| {dx:g} | {K} | {s:.0%} | {len(ks)} | " + " | ".join(a) + f" | {ratio} |")
    dxs = sorted({k[0] for k in keys})
    multi = [k for k in sorted({k[1:] for k in keys}) if sum((d,) + k in keys for d in dxs) > 1]
    if multi:
        L += ["", "## Grid: the same K, s, seed at each dx", "",
              "Δ: the row's V_OC(150)/V_OC(10) minus that at the finest dx of the group.", "",
              "| K | s | seed | dx | " + " | ".join(f"A/S @ {p:g} kPa" for p in PS_REPORT)
              + " | V_OC(150)/V_OC(10) | Δ |", "|" + "---|" * (6 + len(PS_REPORT))]
        for K, s, seed in multi:
            ks = [(d, K, s, seed) for d in dxs if (d, K, s, seed) in keys]
            ref = _at(rows, ks[0], 150.0) / _at(rows, ks[0], 10.0)
            for k in ks:
                r = _at(rows, k, 150.0) / _at(rows, k, 10.0)
                L.append(f"| {K} | {s:.0%} | {seed} | {k[0]:g} | "
                         + " | ".join(f"{_at(rows, k, p):.3f}" for p in PS_REPORT) + f" | {r:.3f} | {r - ref:+.3f} |")
    for dx in dxs:
        Ks = sorted({k[1] for k in keys if k[0] == dx})
        if len(Ks) < 2:
            continue
        L += ["", f"## Size: V_OC(150)/V_OC(10) against K at dx = {dx:g} (mean ± std over seeds; seeds)", "",
              "| s | " + " | ".join(f"K = {K}" for K in Ks) + " |", "|" + "---|" * (1 + len(Ks))]
        for s in sorted({k[2] for k in keys if k[0] == dx}):
            cells = []
            for K in Ks:
                ks = [k for k in keys if k[:3] == (dx, K, s)]
                cells.append(f"{_ms([_at(rows, k, 150.0) / _at(rows, k, 10.0) for k in ks])} ({len(ks)})"
                             if ks else "—")
            L.append(f"| {s:.0%} | " + " | ".join(cells) + " |")
    L += ["", "## Runs", "",
          "Run status of the states up to 150 kPa (`tengsim.status.flags`): out of the LJ law's range (g < g_safe), "
          "under-resolved (measured process zone ℓ < 0.75 dx on the apex row of the tallest pyramid), not "
          "converged; min ℓ: the smallest measured ℓ. D_first: first D with a cell in contact; D_10, D_150: "
          "first D at 10 and 150 kPa.", "",
          "| dx | K | s | seed | realised rms | states | out of range | under-resolved | unconverged | min ℓ | "
          "D_first | D_10 | D_150 | seconds |", "|" + "---|" * 14]
    for m in sorted(runs, key=_key):
        L.append(f"| {m['dx']:g} | {m['K']} | {m['scatter']:.0%} | {m['seed']} | {m['realised']:.4f} | "
                 f"{m['n_states']} | {m['n_out_of_range']} | {m['n_under_resolved']} | {m['n_unconverged']} | "
                 f"{m['min_process_zone']:.3g} | {m['D_first']:.3f} | {m['D_10']:.4f} | {m['D_150']:.4f} | "
                 f"{m['seconds']:.1f} |")
    L += ["", f"Total {sum(m['seconds'] for m in runs):.0f} s of runs on this machine (2 cores shared with "
          "other jobs), one run at a time."]
    return L


def write_convergence_md(path: Path, rows, runs, name) -> None:
    """Write ``path`` from the tables; a hand-written '## Findings' section already there survives."""
    head = ["# Convergence of the group-A scatter study in dx and K (issue 15)", "",
            f"Generated by `scripts/scatter_study.py --dx … --K … --seeds … --scatter … --name {name}` "
            f"(data: `{name}.csv`, one row per run and target pressure; runs: `{name}_runs.csv`). Same model as "
            "scatter_study.md: periodic K × K super-cells of the group-A pyramid (N = 0.946, L̄ = 3.78, μ = 0.5, "
            "LJ93, fast solver tol 1e-6), D steps 0.025, then 0.0025 from 0.5 kPa on; the state at P is the first "
            "approach state whose pressure reaches P; A/S = Σ Λc,k²/(K L̄)² (Eq. 12 cell by cell), "
            "V_OC = σ (A/S) T/(ε_r ε0). Pixels per cell: L̄/dx (19 at dx = 0.2, 38 at dx = 0.1).", ""]
    text = path.read_text() if path.exists() else ""
    keep = text[text.index("## Findings"):] if "## Findings" in text else ""
    path.write_text("\n".join(head + convergence_tables(rows, runs)) + "\n" + ("\n" + keep if keep else ""))


def plot(out, rows, scatters, plan):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    K = max(k for k, _ in plan)
    fig, ax = plt.subplots(1, 2, figsize=(10, 4))
    for s in scatters:
        P = TARGETS_KPA
        a = np.array([_mean(rows, K, s, p, "A_S_greenwood")[0] for p in P])
        v = np.array([_mean(rows, K, s, p, "V_OC")[0] for p in P])
        ax[0].plot(P, a, "o-", ms=3, label=f"s = {s:.0%}")
        ax[1].plot(P, v, "o-", ms=3, label=f"s = {s:.0%}")
    ax[0].set(xlabel="pressure (kPa)", ylabel="A/S (Greenwood, Eq. 12)", title=f"group A, K = {K}")
    ax[1].set(xlabel="pressure (kPa)", ylabel="V_OC (V), Eq. 12", title="σ 5.84 µC/m², ε_r 2.40, T 400 µm")
    ax[0].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "scatter_study.png", dpi=120)


if __name__ == "__main__":
    sys.exit(main())
