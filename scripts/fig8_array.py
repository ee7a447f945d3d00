"""Fig. 8 re-run with the A(P) of group-A arrays with height scatter (issue 15, "Arrays with scatter").

For each rms height scatter s (0, 5, 10, 20 %; seeds 0 and 1 where s > 0) a periodic K × K super-cell
(K = 4) of the paper's group-A pyramid (N = 0.946, L̄ = 3.78, μ = 0.5, E* = 0.59 MPa, W = 54 mJ/m²)
on the paper's 400 µm bonded film (ν = 0.49; thickness in X units = 400 µm / ℓ, ℓ from
``paper_scaling("A").lateral``; periodic film kernel, so the q = 0 mode has the film's finite
stiffness and the flat array stays in the LJ law's range) is approached in D (LJ93, fast solver,
dx = 0.2 as ``scripts/scatter_study.py``; D step ``--d-step``, each state warm-started from the last)
until the nominal pressure passes 150 kPa.  A/S at P is the ``array_area`` observer's Greenwood area
Σ Λc,k²/(K L̄)² (Eq. 12 cell by cell) of the first approach state whose pressure reaches P (what a
press under load control reaches).  The table A/S(10, 20, … 150 kPa) is the area model of the Fig. 8
device (``tengsim.cases.paper.fig8_params``), run through the 10 → 150 kPa staircase
(``run_fig8``); V_OC per step is ``fig8_summary``'s ``voc_steps_V`` (Eq. 17 after each release).
The reference is the single cell (K = 1, same film and settings) and, quoted from docs/device.md,
the converged free single cell's 18.24 V at every step.

Usage: python scripts/fig8_array.py [--out docs/data] [--quick]
Writes fig8_array.md, fig8_array.csv and fig8_array.png in --out.
"""
from __future__ import annotations

import argparse
import csv
import os
import sys
import time
from pathlib import Path

import numpy as np

import tengsim
from tengsim.cases.paper.units import paper_scaling
from tengsim.shapes.arrays import Array

TARGETS_KPA = np.arange(10, 151, 10)
T_FILM = 400e-6
NU = 0.49


def approach(shape, mu, dx, p_of_F, kernel_params, p_max_kpa=150.0, d_step=0.1, d_max=80.0):
    """D-controlled approach in fixed steps ``d_step``: scripts/scatter_study.py's, with the film."""
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from scatter_study import approach as stepped

    return stepped(shape, mu, dx, p_of_F, p_max_kpa, coarse=d_step, fine=d_step, kernel_params=kernel_params,
                   d_max=d_max)


def area_at_targets(states):
    """A/S of the first state whose pressure reaches each target (None where none does)."""
    p = np.array([r["P_kPa"] for r in states])
    out = []
    for target in TARGETS_KPA:
        idx = np.nonzero(p >= target)[0]
        out.append(states[int(idx[0])] if len(idx) else None)
    return out


def run_case(K, s, seed, dx, d_step, film=True):
    from tengsim.cases import paper
    from tengsim.device import AreaTable

    sc = paper_scaling("A")
    arr = Array("pyramid", K=K, scatter_height=s, seed=seed, N=sc.N, cell=sc.cell)
    kp = {"thickness": T_FILM / sc.lateral, "substrate": "bonded", "poisson": NU} if film else {}
    t0 = time.perf_counter()
    states = approach(arr, sc.mu, dx, lambda F: sc.pressure(F / K**2) / 1e3, kp, d_step=d_step)
    t_contact = time.perf_counter() - t0
    picks = area_at_targets(states)
    if any(r is None for r in picks):
        raise RuntimeError(f"K={K} s={s} seed={seed}: 150 kPa not reached")
    A = np.array([r["area_fraction_greenwood"] for r in picks])
    t1 = time.perf_counter()
    summ = paper.fig8_summary(paper.run_fig8(AreaTable(TARGETS_KPA * 1e3, A)))
    t_dev = time.perf_counter() - t1
    return dict(K=K, scatter=s, seed=seed, realised=float(arr.heights.std()), A=A,
                P_at=np.array([r["P_kPa"] for r in picks]), cells=[r["cells_in_contact"] for r in picks],
                voc=np.array(summ["voc_steps_V"], dtype=float), peak=np.array(summ["peak_voltage_steps_V"]),
                n_states=len(states), n_flag=sum(not r["in_law_range"] for r in states),
                n_unconv=sum(not r["converged"] for r in states), n_conv=sum(r["n_conv"] for r in states),
                D_150=states[-1]["D"], t_contact=t_contact, t_device=t_dev)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="docs/data")
    ap.add_argument("--K", type=int, default=4)
    ap.add_argument("--dx", type=float, default=0.2)
    ap.add_argument("--d-step", type=float, default=0.1)
    ap.add_argument("--quick", action="store_true", help="s = 0 and 20 %%, one seed, K = 2")
    args = ap.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    plan = [(1, 0.0, 0), (args.K, 0.0, 0)] + [(args.K, s, seed) for s in (0.05, 0.10, 0.20) for seed in (0, 1)]
    if args.quick:
        plan = [(1, 0.0, 0), (2, 0.0, 0), (2, 0.20, 0)]
    t0, rows = time.perf_counter(), []
    for K, s, seed in plan:
        r = run_case(K, s, seed, args.dx, args.d_step)
        rows.append(r)
        print(f"K={K} s={s:.2f} seed={seed}: contact {r['t_contact']:.0f} s ({r['n_states']} states, "
              f"flagged {r['n_flag']}), device {r['t_device']:.0f} s; V_OC {r['voc'][0]:.2f} -> {r['voc'][-1]:.2f} V",
              file=sys.stderr, flush=True)
    total = time.perf_counter() - t0
    with open(out / "fig8_array.csv", "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["K", "scatter", "seed", "P_step_kPa", "P_state_kPa", "A_S_greenwood", "cells_in_contact",
                    "V_OC_step_V", "peak_V_step_V"])
        for r in rows:
            for i, p in enumerate(TARGETS_KPA):
                w.writerow([r["K"], r["scatter"], r["seed"], p, f"{r['P_at'][i]:.4f}", f"{r['A'][i]:.6f}",
                            r["cells"][i], f"{r['voc'][i]:.6f}", f"{r['peak'][i]:.6f}"])
    write_md(out, rows, total, args)
    plot(out, rows)


def write_md(out, rows, total, args):
    sc = paper_scaling("A")
    ref = rows[0]
    L = ["# Fig. 8 with the A(P) of group-A arrays with height scatter", "",
         "Generated by `scripts/fig8_array.py` (data: `fig8_array.csv`, figure: `fig8_array.png`).",
         f"Periodic K × K super-cells of the group-A pyramid (N = 0.946, L̄ = 3.78, μ = 0.5, LJ93, dx = {args.dx},",
         f"D step {args.d_step}) on the paper's 400 µm bonded film (ν = {NU}; t = 400 µm / ℓ = "
         f"{T_FILM / sc.lateral:.1f} in X units, ℓ = {sc.lateral * 1e6:.4f} µm), approached in D until the",
         "nominal pressure passes 150 kPa; A/S at each staircase pressure is the Greenwood area Σ Λc,k²/(K L̄)²",
         "(observer `array_area`) of the first approach state reaching it. That table drives the Fig. 8 device",
         "(`tengsim.cases.paper.run_fig8`, 10 → 150 kPa staircase at 2 Hz, 1 MΩ); V_OC per step is",
         "`fig8_summary`'s `voc_steps_V` (Eq. 17 at the rest gap after each release). Reference: the single cell",
         "(K = 1, same film and settings, first row) and the converged free single cell of docs/device.md",
         "(18.24 V at every step).", "",
         "| K | s | seed | realised rms | A/S @ 10 / 50 / 100 / 150 kPa | V_OC @ 10 / 50 / 100 / 150 kPa (V) | "
         "V_OC(150)/V_OC(10) | V_OC(150) − single cell (V) | states | out of law range | unconverged |",
         "|---|---|---|---|---|---|---|---|---|---|---|"]
    idx = [0, 4, 9, 14]
    for r in rows:
        L.append(f"| {r['K']} | {r['scatter']:.0%} | {r['seed']} | {r['realised']:.4f} | "
                 + " / ".join(f"{r['A'][i]:.4f}" for i in idx) + " | "
                 + " / ".join(f"{r['voc'][i]:.2f}" for i in idx)
                 + f" | {r['voc'][-1] / r['voc'][0]:.3f} | {r['voc'][-1] - ref['voc'][-1]:+.2f} | {r['n_states']} | "
                 f"{r['n_flag']} | {r['n_unconv']} |")
    L += ["", "V_OC per step (V), all 15 steps:", "",
          "| K | s | seed | " + " | ".join(f"{p}" for p in TARGETS_KPA) + " |",
          "|" + "---|" * (3 + len(TARGETS_KPA))]
    for r in rows:
        L.append(f"| {r['K']} | {r['scatter']:.0%} | {r['seed']} | " + " | ".join(f"{v:.2f}" for v in r["voc"]) + " |")
    L += ["", "Cells in contact at 10 / 150 kPa; D at 150 kPa; seconds (contact path, device run):", "",
          "| K | s | seed | cells 10 / 150 kPa | D_150 (ε) | convolutions | contact s | device s |",
          "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        L.append(f"| {r['K']} | {r['scatter']:.0%} | {r['seed']} | {r['cells'][0]} / {r['cells'][-1]} of "
                 f"{r['K'] ** 2} | {r['D_150']:.2f} | {r['n_conv']} | {r['t_contact']:.1f} | {r['t_device']:.1f} |")
    load = os.getloadavg()
    L += ["", f"Total {total:.0f} s on this machine (2 shared cores, load average {load[0]:.1f} at the end).", ""]
    path = out / "fig8_array.md"
    text = path.read_text() if path.exists() else ""
    keep = text[text.index("## Findings"):] if "## Findings" in text else ""
    path.write_text("\n".join(L) + ("\n" + keep if keep else ""))


def plot(out, rows):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(1, 2, figsize=(10, 4))
    for r in rows:
        lab = f"K={r['K']} s={r['scatter']:.0%} seed {r['seed']}"
        ls = "k--" if r["K"] == 1 else "o-"
        ax[0].plot(TARGETS_KPA, r["A"], ls, ms=3, label=lab)
        ax[1].plot(TARGETS_KPA, r["voc"], ls, ms=3, label=lab)
    ax[1].axhline(18.24, color="grey", lw=0.8, ls=":", label="free single cell (docs/device.md)")
    ax[0].set(xlabel="pressure (kPa)", ylabel="A/S (Greenwood, Eq. 12)", title="group A arrays, 400 µm film")
    ax[1].set(xlabel="staircase step pressure (kPa)", ylabel="V_OC per step (V), Eq. 17",
              title="Fig. 8 device with the array's A(P)")
    ax[1].legend(fontsize=6)
    fig.tight_layout()
    fig.savefig(out / "fig8_array.png", dpi=120)


if __name__ == "__main__":
    main()
