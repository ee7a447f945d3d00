"""Finite-thickness film vs half-space for the paper's pyramid arrays (docs/validation.md, "Finite-thickness film").

Two studies, written as Markdown (with their parameters) to --out, and every curve as CSV beside it:

1. ``voc``: V_OC(P) by Eq. (12) of a periodic group-A (or --group) array on a half-space and on a bonded
   film of thickness t = r · pitch for r in --ratios (ν = --poisson), on a coarse grid: the largest
   relative change of V_OC over the common pressure range, so the ratio at which the half-space
   assumption moves V_OC(P) by more than 5 % can be read off.
2. ``law``: the paper's 400 µm film (ν = 0.49, bonded) under the 2 µm pyramids of group A, periodic,
   approached to 150 kPa (Fig. 8's range): the count of equilibria outside the law's range, against the
   same run on the half-space, and the pressure–approach slope once the array is flat, against the
   film's uniaxial-strain stiffness M/t (M = E(1 − ν)/((1 + ν)(1 − 2ν)), E = E*(1 − ν²)).

    python scripts/film_study.py --out film_study/film_study.md
"""
from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from tengsim import io
from tengsim.kernels import film
from tengsim.run.plan import ContactPlan
from tengsim.run.simulate import simulate
from tengsim.device.formulas import voc_polymer
from tengsim.shapes import Pyramid
from tengsim.cases.paper.contact import area_table_from_result
from tengsim.continuation import PathSpec
from tengsim.cases.paper.units import paper_scaling

SIGMA, EPS_R, T_POLY = 5.84e-6, 2.40, 400e-6  # Section 4 (Fig. 5): σ, ε_r, polymer thickness for Eq. (12)


def run(group, dx, d_max, d_step, thickness_m=None, poisson=0.49, substrate="bonded", d_min=-1.0, tol=1e-6,
        boundary="periodic"):
    sc = paper_scaling(group)
    kp = {}
    if thickness_m is not None:
        kp = {"thickness": thickness_m / sc.lateral, "poisson": poisson, "substrate": substrate}
    res = simulate(ContactPlan(Pyramid(sc.N, sc.cell), sc.mu, dx, PathSpec(d_min, d_max, d_step), boundary=boundary, solver_tol=tol, kernel_params=kp, extra=sc.params(), scaling=None))
    return sc, res


def voc_curve(res, group):
    tab = area_table_from_result(res, group)
    return tab.pressure_Pa, tab.area_fraction, voc_polymer(tab.area_fraction, SIGMA, EPS_R, T_POLY)


def across_jumps(pgrid, P, V, jump=0.05):
    """Pressures of ``pgrid`` that fall between two consecutive states of a curve whose V_OC differ by
    more than ``jump`` (relative): there the interpolated V_OC spans a jump of the load-controlled curve."""
    out = np.zeros(pgrid.shape, bool)
    for k in np.flatnonzero(np.abs(np.diff(V)) > jump * np.abs(V[:-1])):
        out |= (pgrid >= P[k]) & (pgrid <= P[k + 1])
    return out


def study_voc(group, ratios, dx, d_step, d_max, poisson, p_lo, p_hi, out_dir, boundary):
    """V_OC(P) for each t/pitch against a reference: the half-space for the free (isolated) cell; for the
    periodic array the thickest film (its half-space has no state between p_lo and p_hi, see docs)."""
    sc = paper_scaling(group)
    pgrid = np.geomspace(p_lo, p_hi, 41)
    rows, curves = [], {}
    t0 = time.perf_counter()
    _, hs = run(group, dx, d_max, d_step, boundary=boundary)
    curves["half-space"] = voc_curve(hs, group)
    results = {}
    for r in ratios:
        # D must also take up the film's mean compression t/M · p_hi to reach p_hi
        dm = d_max + 1.15 * p_hi * film.oedometric_compliance_si(r * sc.L, sc.E_star, poisson) / sc.eps
        _, res = run(group, dx, dm, d_step, thickness_m=r * sc.L, poisson=poisson, boundary=boundary)
        results[r] = res
        curves[f"t/pitch={r:g}"] = voc_curve(res, group)
    ref_name = "half-space" if boundary == "free" else f"t/pitch={max(ratios):g}"
    P0, _, V0 = curves[ref_name]
    v_ref = np.interp(pgrid, P0, V0, left=np.nan, right=np.nan)
    jumps_ref = across_jumps(pgrid, P0, V0)
    for r in ratios:
        P, A, V = curves[f"t/pitch={r:g}"]
        v = np.interp(pgrid, P, V, left=np.nan, right=np.nan)
        rel = np.abs(v - v_ref) / v_ref
        ok = np.isfinite(rel)
        smooth = ok & ~jumps_ref & ~across_jumps(pgrid, P, V)
        i = int(np.argmax(np.where(ok, rel, -1.0))) if ok.any() else 0
        res = results[r]
        rows.append({"t_over_pitch": r, "t_um": r * sc.L * 1e6,
                     "max_rel_change": float(rel[ok].max()) if ok.any() else float("nan"),
                     "max_rel_change_off_jumps": float(rel[smooth].max()) if smooth.any() else float("nan"),
                     "share_over_5pct": float((rel[ok] > 0.05).mean()) if ok.any() else float("nan"),
                     "at_P_kPa": float(pgrid[i] / 1e3),
                     "compared_kPa": (float(pgrid[ok][0] / 1e3), float(pgrid[ok][-1] / 1e3)) if ok.any() else None,
                     "V_at_10kPa": float(np.interp(1e4, P, V, left=np.nan, right=np.nan)),
                     "V_at_150kPa": float(np.interp(1.5e5, P, V, left=np.nan, right=np.nan)),
                     "P_min_kPa": float(P[0] / 1e3), "P_max_kPa": float(P[-1] / 1e3),
                     "out_of_law_range": int((~res.table["in_law_range"].astype(bool)).sum()),
                     "n_states": len(res.table["D"])})
    n = max(len(c[0]) for c in curves.values())
    cols = {}
    for k, (P, A, V) in curves.items():
        key = k.replace("/", "_").replace("=", "")
        cols[f"P_Pa_{key}"] = np.pad(P, (0, n - len(P)), constant_values=np.nan)
        cols[f"A_over_S_{key}"] = np.pad(A, (0, n - len(A)), constant_values=np.nan)
        cols[f"Voc_V_{key}"] = np.pad(V, (0, n - len(V)), constant_values=np.nan)
    io.write_csv(out_dir / f"film_voc_{group}_{boundary}.csv", cols,
                 header={"group": group, "boundary": boundary, "dx": dx, "d_step": d_step, "d_max": d_max,
                         "poisson": poisson, "substrate": "bonded", "sigma_C_m2": SIGMA, "eps_r": EPS_R,
                         "T_poly_m": T_POLY})
    Ph, _, Vh = curves["half-space"]
    ref_info = {"reference": ref_name, "P_min_kPa": float(Ph[0] / 1e3), "P_max_kPa": float(Ph[-1] / 1e3),
                "V_first": float(Vh[0]),
                "out_of_law_range": int((~hs.table["in_law_range"].astype(bool)).sum()),
                "n_states": len(hs.table["D"])}
    return rows, ref_info, time.perf_counter() - t0


def study_law(group, dx, d_step, thickness_m, poisson, p_target, out_dir):
    t0 = time.perf_counter()
    sc = paper_scaling(group)
    # the film's mean compliance sets how far D must go to reach p_target: w̄ = p t/M (in ε)
    oed = film.oedometric_compliance_si(thickness_m, sc.E_star, poisson)
    d_max = 14.0 + 1.15 * p_target * oed / sc.eps
    _, res = run(group, dx, d_max, d_step, thickness_m=thickness_m, poisson=poisson)
    _, hs = run(group, dx, 14.0, d_step)
    a = res.branch("approach")
    P = sc.pressure(a["F"])
    D = a["D"]
    flat = (P > 20e3) & (P < p_target * 1.2)
    slope = float(np.polyfit(D[flat], P[flat], 1)[0]) if flat.sum() > 2 else float("nan")  # Pa per ε
    expected = sc.eps / oed  # M/t in Pa per ε
    table = res.table
    out = {
        "group": group, "thickness_m": thickness_m, "poisson": poisson, "substrate": "bonded", "dx": dx,
        "d_step": d_step, "d_max": d_max, "n_states": len(table["D"]),
        "out_of_law_range": int((~table["in_law_range"].astype(bool)).sum()),
        "not_converged": int((~table["converged"].astype(bool)).sum()),
        "P_max_kPa": float(P.max() / 1e3), "slope_Pa_per_eps": slope, "M_over_t_Pa_per_eps": expected,
        "halfspace_n_states": len(hs.table["D"]),
        "halfspace_out_of_law_range": int((~hs.table["in_law_range"].astype(bool)).sum()),
        "halfspace_P_max_kPa": float(sc.pressure(hs.branch("approach")["F"]).max() / 1e3),
        "seconds": time.perf_counter() - t0,
    }
    nu_rows = []
    for nu in (0.45, 0.49, 0.499, 0.4999, 0.5):
        oed_nu = film.oedometric_compliance_si(thickness_m, sc.E_star, nu)
        dm = 14.0 + 1.15 * p_target * oed_nu / sc.eps
        _, rn = run(group, dx, dm, d_step, thickness_m=thickness_m, poisson=nu)
        an = rn.branch("approach")
        Pn, Dn = sc.pressure(an["F"]), an["D"]
        fl = (Pn > 20e3) & (Pn < p_target * 1.2)
        nu_rows.append({"poisson": nu, "d_max": dm, "n_states": len(rn.table["D"]),
                        "out_of_law_range": int((~rn.table["in_law_range"].astype(bool)).sum()),
                        "P_max_kPa": float(Pn.max() / 1e3),
                        "slope_Pa_per_eps": float(np.polyfit(Dn[fl], Pn[fl], 1)[0]) if fl.sum() > 2 else float("nan"),
                        "M_over_t_Pa_per_eps": sc.eps / oed_nu if oed_nu > 0 else float("inf")})
    out["by_poisson"] = nu_rows
    out["seconds"] = time.perf_counter() - t0
    io.write_csv(out_dir / f"film_law_{group}.csv",
                 {"D_eps": D, "pressure_Pa": P, "contact_length": a["contact_length"],
                  "in_law_range": a["in_law_range"].astype(int)},
                 header={k: v for k, v in out.items() if k != "by_poisson"
                         and (not isinstance(v, float) or np.isfinite(v))})
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", default="film_study/film_study.md")
    ap.add_argument("--group", default="A")
    ap.add_argument("--ratios", default="0.25,0.5,0.75,1,2,5,10,200")
    ap.add_argument("--dx", type=float, default=0.2)
    ap.add_argument("--d-step", type=float, default=0.1)
    ap.add_argument("--d-max", type=float, default=14.0, help="D_max of the half-space run (ε); film runs add "
                    "their mean compression at 150 kPa")
    ap.add_argument("--poisson", type=float, default=0.49)
    ap.add_argument("--only", choices=("voc", "law"), default=None)
    ap.add_argument("--boundaries", default="free,periodic")
    args = ap.parse_args(argv)
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    lines = ["# Finite-thickness film vs half-space (scripts/film_study.py)", ""]
    if args.only in (None, "law"):
        r = study_law(args.group, args.dx, args.d_step, 400e-6, args.poisson, 150e3, out.parent)
        lines += ["## 400 µm bonded film under group-A pyramids, periodic, to 150 kPa", "",
                  "| quantity | value |", "|---|---|"] + [f"| {k} | {v:.6g} |" if isinstance(v, float)
                                                          else f"| {k} | {v} |" for k, v in r.items()
                                                          if k != "by_poisson"] + [""]
        lines += ["### ν → 0.5 (same film, D-controlled, D up to 14 ε + 1.15 × 150 kPa · t/M)", "",
                  "| ν | D_max (ε) | states | out of law range | P_max (kPa) | slope dP/dD (Pa/ε) | M/t (Pa/ε) |",
                  "|---|---|---|---|---|---|---|"]
        lines += [f"| {w['poisson']:g} | {w['d_max']:.4g} | {w['n_states']} | {w['out_of_law_range']} | "
                  f"{w['P_max_kPa']:.4g} | {w['slope_Pa_per_eps']:.5g} | {w['M_over_t_Pa_per_eps']:.5g} |"
                  for w in r["by_poisson"]] + [""]
        print(r, flush=True)
    if args.only in (None, "voc"):
        ratios = [float(x) for x in args.ratios.split(",")]
        for boundary in args.boundaries.split(","):
            rows, ref, secs = study_voc(args.group, ratios, args.dx, args.d_step, args.d_max, args.poisson,
                                        1e3, 150e3, out.parent, boundary)
            lines += [f"## V_OC(P), Eq. (12), group {args.group}, {boundary} kernel: bonded film (ν = {args.poisson}) "
                      f"vs {ref['reference']}", "",
                      f"dx = {args.dx}, d_step = {args.d_step}, D ≤ {args.d_max} ε (+ the film's mean "
                      "compression at "
                      "150 kPa); relative change of V_OC against the reference on 41 log-spaced pressures 1–150 kPa, "
                      f"where both curves have states; {secs:.0f} s. Half-space run: P from {ref['P_min_kPa']:.4g} "
                      f"to {ref['P_max_kPa']:.4g} kPa, first V_OC {ref['V_first']:.4g} V, "
                      f"{ref['out_of_law_range']} of {ref['n_states']} states out of the law's range.",
                      "'off jumps' leaves out pressures where either curve's V_OC jumps by > 5 % between two "
                      "consecutive states (a small shift of a jump gives any relative change there); "
                      "'share > 5 %' is the share of the compared pressures changed by more than 5 %.",
                      "", "| t/pitch | t (µm) | max rel. change of V_OC | at P (kPa) | off jumps | share > 5 % | "
                      "compared over (kPa) | V(10 kPa) | V(150 kPa) | P range (kPa) | out of law range / states |",
                      "|---|---|---|---|---|---|---|---|---|---|---|"]
            for w in rows:
                cmp = "—" if w["compared_kPa"] is None else f"{w['compared_kPa'][0]:.3g}–{w['compared_kPa'][1]:.3g}"
                lines.append(f"| {w['t_over_pitch']:g} | {w['t_um']:g} | {w['max_rel_change']:.3g} | "
                             f"{w['at_P_kPa']:.3g} | {w['max_rel_change_off_jumps']:.3g} | "
                             f"{w['share_over_5pct']:.2f} | {cmp} | {w['V_at_10kPa']:.5g} | {w['V_at_150kPa']:.5g} | "
                             f"{w['P_min_kPa']:.3g}–{w['P_max_kPa']:.4g} | "
                             f"{w['out_of_law_range']} / {w['n_states']} |")
            lines.append("")
            print("\n".join(lines[-len(rows) - 4:]), flush=True)
    out.write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
