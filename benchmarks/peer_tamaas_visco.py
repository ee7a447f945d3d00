"""Peer benchmark: tengsim's viscoelastic time drive (``tengsim.visco.TimeDrive`` with the hard-wall constrained
solver 'pk' under load control) against Tamaas 2.9's ``MaxwellViscoelastic`` (PyPI ``tamaas``) on the same
non-adhesive periodic rough surface and load history, side by side in one run.  Not part of tengsim or its
test suite.

Install the peer in its own environment (it runs in a subprocess; the two exchange .npz/.json files):

    python3 -m venv /work/venvs/tamaas && /work/venvs/tamaas/bin/pip install tamaas numpy scipy

Tamaas' conventions (the child's ``convention`` check, one step from rest): its solver is pressure (load)
controlled, one ``solve(p̄)`` one backward-Euler step of ``time_step`` (``solve_should_update`` True: the
state advanced inside solve, no separate ``updateState`` call); ``model.E`` is the relaxed Young's modulus
E∞ and ``shear_moduli`` the branches' shear moduli G_i, a branch adding E*_i = 2 G_i/(1 − ν) to
E*∞ = E∞/(1 − ν²).  Here ν = 0: G_i = E*_i/2.  Its history update has a unit slip (see the comment above
``_tamaas_model``): exact only when G∞ = E∞/(2(1 + ν)) = 1.  So the comparison runs Tamaas with every
modulus and p̄ divided by G∞ (tractions multiplied back; the same problem, the problem being linear in the
moduli and the load), and runs the documented units once more to show the slip.

Problem (both codes): benchmarks/peer_aspher.py's periodic self-affine surface (Hurst 0.8, seed 1) on n×n,
heights ×200 (rms 3.67 ε at 256²), cell L = 256 (dx = 2 at 128², 1 at 256²), hard wall, no adhesion, a
standard linear solid E*(t) = E*∞ + E*_1 e^{−t/τ} with E*∞ = 1, E*_1 = 2 (E*0 = 3), τ = 1, under the mean
pressure p̄(t): 0 → ``--p-max`` over [0, τ] (linear), held to 3τ, down to p_max/4 at 4τ, held to 5τ, in fixed
steps Δt = ``--dt`` (and Δt/2 with ``--halve``).  tengsim: its exact internal-variable update (w linear over a
step, tengsim.visco.memory; the surface at rest at t = 0), ``pk`` tolerance ``--tol`` (ε); Tamaas: its
relative tolerance ``--tamaas-tol``, one solve per step from t = Δt (at rest at t = 0).

Reported per step: the contact area fraction (pixels with p > 0) and the mean gap (ε; tengsim: −D, the
surface's mean at zero; Tamaas: mean(displacement − surface)), their largest differences over the history,
with ``--halve`` Tamaas' first-order steps extrapolated to Δt → 0 (2 A(Δt/2) − A(Δt)) against tengsim at Δt/2;
Tamaas' contact condition (the spread of u − h over p > 0, the penetration elsewhere), a numpy replica of its
update checked against it; the CPU time (time.process_time of each process) and its ratio.  One thread each.

    OPENBLAS_NUM_THREADS=1 python benchmarks/peer_tamaas_visco.py --sizes 128 256 --halve \
        --out benchmarks/results/peer_tamaas_visco.json
"""
from __future__ import annotations

import argparse
import importlib
import json
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

L, SCALE = 256.0, 200.0
E_INF, E1, TAU, NU = 1.0, 2.0, 1.0, 0.0          # E* (tengsim's units of W/ε per ε/ℓ: only ratios and κ = 1/E*)
T_KNOTS = (0.0, 1.0, 3.0, 4.0, 5.0)                # × τ
P_FRACTIONS = (0.0, 1.0, 1.0, 0.25, 0.25)          # × p_max


def heights(n: int) -> np.ndarray:
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    from peer_aspher import surface

    return SCALE * surface(n)


LIMIT_KNOTS = ((0.0, 0.5, 40.0), (0.0, 1.0, 1.0))  # the long hold (× τ, × p_max; run at Δt = τ/2): the relaxed limit


def schedule(dt: float, p_max: float, knots=(T_KNOTS, P_FRACTIONS)):
    """(times, loads): the fixed steps of every segment, t = 0 first (the surface at rest, p̄ = 0)."""
    t, p = [0.0], [0.0]
    tk, pk_ = knots
    for (ta, tb), (pa, pb) in zip(zip(tk, tk[1:]), zip(pk_, pk_[1:])):
        k = int(round((tb - ta) * TAU / dt))
        for i in range(1, k + 1):
            t.append(ta * TAU + i * dt)
            p.append(p_max * (pa + (pb - pa) * i / k))
    return np.array(t), np.array(p)


# ---- tengsim -------------------------------------------------------------------------------------------------
def run_tengsim(h, dt, p_max, tol, knots=(T_KNOTS, P_FRACTIONS)):
    from tengsim.grid import Grid
    from tengsim.kernels import PeriodicKernel
    from tengsim.laws import Repulsive
    from tengsim.relaxation import Prony
    from tengsim.solvers import make_solver
    from tengsim.visco import FixedTimeSteps, History, TimeDrive

    importlib.import_module("tengsim.plugins")                          # the registries filled ('pk')

    n = h.shape[0]
    grid = Grid(n, n, L / n, L / n)
    t, p = schedule(dt, p_max, knots)
    hist = History(tuple(x * TAU for x in knots[0]), tuple(f * p_max for f in knots[1]), "pressure")
    drive = TimeDrive(-(h - h.mean()), Repulsive(), lambda kappa: PeriodicKernel(grid, kappa), 1.0 / E_INF,
                      make_solver("pk", tol=tol), Prony(E_INF, (E1,), (TAU,)), jump_h=np.inf, maps_at=(t[-1],))
    c0, w0 = time.process_time(), time.perf_counter()
    res = drive.run(hist, FixedTimeSteps(dt))
    cpu, wall = time.process_time() - c0, time.perf_counter() - w0
    if len(res.t) != len(t) or not np.allclose(res.t, t):
        raise RuntimeError(f"tengsim's steps ({len(res.t)}) differ from the schedule ({len(t)})")
    P_last = res.maps[t[-1]][1]
    area = res["area_repulsive"] / (L * L)
    check = abs(float(np.mean(P_last > 0)) - float(area[-1]))            # the column is the map's fraction
    return {"cpu": cpu, "wall": wall, "t": res.t.tolist(), "p": res["mean_pressure"].tolist(),
            "area": area.tolist(), "mean_gap": (-res["D"]).tolist(), "converged": int(res.converged.sum()),
            "n_conv": int(res["n_conv"].sum()), "area_column_vs_map": check}


# ---- Tamaas (child process) ----------------------------------------------------------------------------------
# Tamaas 2.9's MaxwellViscoelastic::solve / updateState (read from the shipped _tamaas.so: its symbols and their
# disassembly; no source is published with the wheel).  All in shear units: G∞ = model.E/(2(1 + ν)),
# γ_i = τ_i/(τ_i + Δt), G̃ = Σ G_i γ_i, α = G∞ + G̃, β = G̃.  Each solve(p̄):
#   M̄ = Σ γ_i M_i;  H = α·surface − β·U + M̄  (the ContactSolver's surface overwritten, restored after);
#   the Westergaard "influence" scaled by G∞, PolonskyKeerRey::solve(p̄) on H (so its displacement w = G∞ K[p],
#   in shear × length, the units of H), the influence unscaled, displacement = K[p] recomputed (length);
#   U_new = (displacement − M̄ + β U)/α;  updateState: M_i = γ_i (M_i + G_i (U_new − U)),  U = U_new, and the
#   model's displacement (field "viscoelastic_displacement" too) set to G∞·U.
# U_new mixes w's units with K[p]'s: it should read (w − M̄ + β U)/α = (G∞ K[p] − M̄ + β U)/α.  The two agree
# only when G∞ = 1 in the caller's units (E = 2(1 + ν)); otherwise U, hence every later H, is off by 1/G∞ in
# its K[p] part.  ``_tamaas29_replica`` re-implements both (around Tamaas' own elastic PolonskyKeerRey) and
# the child checks the faulty one against MaxwellViscoelastic to round-off; the problem is linear in the
# moduli and the load, so the solver run with every modulus and p̄ divided by G∞ (``unit_shear``) is the
# consistent scheme (checked against the replica's corrected form).
def _tamaas_model(tm, n, E, nu=NU):
    model = tm.ModelFactory.createModel(tm.model_type.basic_2d, [L, L], [n, n])
    model.E, model.nu = E, nu
    return model


def _tamaas29_replica(tm, surf, E, G, tau, dt, loads, tol, consistent):
    """Tractions of Tamaas 2.9's scheme (``consistent=False``) or of its corrected form, step by step."""
    n, Ginf = surf.shape[0], E / (2 * (1 + NU))
    G, tau = np.asarray(G, float), np.asarray(tau, float)
    gam = tau / (tau + dt)
    alpha, beta = Ginf + float((G * gam).sum()), float((G * gam).sum())
    U, M, out = np.zeros_like(surf), [np.zeros_like(surf) for _ in G], []
    for p in loads:
        Mbar = sum(g * m for g, m in zip(gam, M))
        H = np.ascontiguousarray(alpha * surf - beta * U + Mbar)
        mw = _tamaas_model(tm, n, 2 * (1 + NU))                         # its compliance: G∞ × that of E∞
        s = tm.PolonskyKeerRey(mw, H, tol, tm.PolonskyKeerRey.pressure, tm.PolonskyKeerRey.pressure)
        s.max_iter = 20000
        s.solve(float(p))
        P = np.array(mw.traction)
        if consistent:
            disp = np.array(mw.displacement)                             # w = G∞ K[p]: the units of H
        else:
            me = _tamaas_model(tm, n, E)
            me.traction[...] = P
            me.solveNeumann()
            disp = np.array(me.displacement)                             # K[p], as Tamaas 2.9 does
        Un = (disp - Mbar + beta * U) / alpha
        M = [g * (m + Gi * (Un - U)) for g, Gi, m in zip(gam, G, M)]
        U = Un
        out.append(P)
    return out


def _convention(tm, surf, p_bar, tol):
    """Tamaas' moduli convention by test: a glassy branch (τ ≫ Δt) and a relaxed one (τ ≪ Δt), one step from
    rest, against the elastic solves at E*0 = E*∞ + 2G/(1 − ν) and E*∞ (blind to the history: U = 0)."""
    n = surf.shape[0]
    G = E1 * (1 - NU) / 2

    def elastic(E_star):
        m = _tamaas_model(tm, n, E_star * (1 - NU ** 2))
        s = tm.PolonskyKeerRey(m, surf, tol, tm.PolonskyKeerRey.pressure, tm.PolonskyKeerRey.pressure)
        s.max_iter = 20000
        s.solve(p_bar)
        return np.array(m.traction, copy=True), float(np.mean(np.asarray(m.displacement) - surf))

    def visco(tau, dt):
        m = _tamaas_model(tm, n, E_INF * (1 - NU ** 2))
        s = tm.MaxwellViscoelastic(m, surf, tol, dt, [G], [tau])
        s.max_iter = 20000
        s.solve(p_bar)
        return np.array(m.traction, copy=True)

    out = {}
    for name, tau, E_star in (("glassy", 1e12, E_INF + E1), ("relaxed", 1e-12, E_INF)):
        pv, (pe, gap) = visco(tau, 1.0), elastic(E_star)
        out[name] = {"E_star": E_star, "max_dp": float(np.abs(pv - pe).max()), "max_p": float(pe.max()),
                     "area_visco": float(np.mean(pv > 0)), "area_elastic": float(np.mean(pe > 0)), "gap_elastic": gap}
    return out


def tamaas_child(npz, out, cfg):
    """One Tamaas run.  ``variant``: 'documented' (model.E = E∞, shear_moduli G_i, p̄: its documented use) or
    'unit_shear' (every modulus and p̄ divided by G∞, tractions multiplied back: the same problem, G∞ = 1)."""
    import tamaas as tm

    tm.set_log_level(tm.LogLevel.error)
    h = np.load(npz)["h"]
    n = h.shape[0]
    surf = np.ascontiguousarray(h - h.mean())
    dt, tol = cfg["dt"], cfg["tol"]
    t, p = schedule(dt, cfg["p_max"], cfg["knots"])
    E, G = E_INF * (1 - NU ** 2), E1 * (1 - NU) / 2                     # Young's E∞, the branch's shear G
    c = 1.0 if cfg["variant"] == "documented" else 2 * (1 + NU) / E   # 1/G∞
    conv = _convention(tm, surf, cfg["p_max"], tol) if cfg.get("convention") else None
    model = _tamaas_model(tm, n, E * c)
    solver = tm.MaxwellViscoelastic(model, surf, tol, dt, [G * c], [TAU])
    solver.max_iter = 20000
    area, gap, err, spread, pen, first = [0.0], [float("nan")], [0.0], [0.0], [0.0], []
    c0, w0 = time.process_time(), time.perf_counter()
    for pk in p[1:]:
        err.append(float(solver.solve(float(pk) * c)))
        tr, u = np.asarray(model.traction) / c, np.asarray(model.displacement)
        g, on = u - surf, tr > 0                                         # u: Tamaas' displacement (G∞·U)
        area.append(float(np.mean(on)))
        gap.append(float(np.mean(g)))
        spread.append(float(np.ptp(g[on])))                              # 0 where the contact condition holds
        pen.append(float(max(0.0, g[on].mean() - g.min())))              # penetration off contact (≥ 0 wanted)
        if len(first) < cfg.get("replica_steps", 0):
            first.append(np.array(tr))
    cpu, wall = time.process_time() - c0, time.perf_counter() - w0
    rep = None
    if first:                                                            # the replica, in the documented units
        got = _tamaas29_replica(tm, surf, E, [G], [TAU], dt, p[1:1 + len(first)], tol,
                                consistent=cfg["variant"] != "documented")
        rep = {"steps": len(first), "consistent": cfg["variant"] != "documented",
               "max_dp_rel": max(float(np.abs(a - b).max() / a.max()) for a, b in zip(first, got)),
               "max_darea": max(abs(float(np.mean(a > 0)) - float(np.mean(b > 0))) for a, b in zip(first, got))}
    with open(out, "w") as f:
        json.dump({"cpu": cpu, "wall": wall, "t": t.tolist(), "area": area, "mean_gap": gap, "solve_error": err,
                   "gap_spread_in_contact": spread, "penetration": pen, "variant": cfg["variant"],
                   "replica": rep, "convention": conv, "version": tm.__version__}, f)


def run_tamaas(h, python, tol, dt, p_max, knots=(T_KNOTS, P_FRACTIONS), variant="unit_shear", replica_steps=0,
               convention=False):
    with tempfile.TemporaryDirectory() as tmp:
        npz, out = os.path.join(tmp, "h.npz"), os.path.join(tmp, "out.json")
        np.savez(npz, h=h)
        env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
        cfg = {"tol": tol, "dt": dt, "p_max": p_max, "knots": knots, "variant": variant,
               "replica_steps": replica_steps, "convention": convention}
        got = subprocess.run([python, "-W", "ignore", os.path.abspath(__file__), "--tamaas-child", npz, out,
                              json.dumps(cfg)], env=env, capture_output=True, text=True)
        if got.returncode:
            return {"error": got.stderr.strip().splitlines()[-1] if got.stderr.strip() else "failed"}
        with open(out) as f:
            return json.load(f)


# ---- comparison ----------------------------------------------------------------------------------------------
def compare(a, b):
    """Largest |Δ area| and |Δ mean gap| of two runs over their common times (t > 0)."""
    ta, tb = np.round(np.asarray(a["t"]), 9), np.round(np.asarray(b["t"]), 9)
    common, ia, ib = np.intersect1d(ta, tb, return_indices=True)
    keep = common > 0
    ia, ib = ia[keep], ib[keep]
    da = np.abs(np.asarray(a["area"])[ia] - np.asarray(b["area"])[ib])
    dg = np.abs(np.asarray(a["mean_gap"])[ia] - np.asarray(b["mean_gap"])[ib])
    return {"max_area": float(da.max()), "t_max_area": float(common[keep][da.argmax()]),
            "max_gap": float(dg.max()), "t_max_gap": float(common[keep][dg.argmax()])}


def richardson(a, b):
    """Tamaas' backward Euler extrapolated to Δt → 0 from runs at Δt (a) and Δt/2 (b): 2 b − a (first order)."""
    ta, tb = np.round(np.asarray(a["t"]), 9), np.round(np.asarray(b["t"]), 9)
    common, ia, ib = np.intersect1d(ta, tb, return_indices=True)
    ext = {k: (2 * np.asarray(b[k])[ib] - np.asarray(a[k])[ia]).tolist() for k in ("area", "mean_gap")}
    return {"t": common.tolist(), **ext}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[128, 256])
    ap.add_argument("--dt", type=float, default=0.05, help="time step (s, τ = 1 s)")
    ap.add_argument("--halve", action="store_true", help="also run both codes at dt/2 (time-step convergence, "
                                                         "and Tamaas extrapolated to dt → 0)")
    ap.add_argument("--p-max", type=float, default=0.1, help="the held mean pressure (W/ε; E*∞ = 1)")
    ap.add_argument("--tol", type=float, default=1e-8, help="tengsim pk's gap residual (ε)")
    ap.add_argument("--tamaas-tol", type=float, default=1e-10, help="Tamaas' relative tolerance")
    ap.add_argument("--replica-steps", type=int, default=8, help="steps of the numpy replica of Tamaas 2.9's "
                                                                  "update checked against its solver (0: none)")
    ap.add_argument("--tamaas-python", default="/work/venvs/tamaas/bin/python")
    ap.add_argument("--out", default=None, help="a JSON file for the rows (each per-step series summarised)")
    ap.add_argument("--series", action="store_true", help="write the per-step series whole in --out")
    ap.add_argument("--no-limit", action="store_true", help="skip the long hold (the relaxed limit)")
    ap.add_argument("--tamaas-child", nargs=3, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.tamaas_child:
        npz, out, cfg = args.tamaas_child
        tamaas_child(npz, out, json.loads(cfg))
        return 0
    for name, v in (("--dt", args.dt), ("--p-max", args.p_max)):
        if not v > 0:
            print(f"{name} must be > 0, got {v:g}", file=sys.stderr)
            return 2
    if args.replica_steps < 0:
        print(f"--replica-steps must be >= 0, got {args.replica_steps}", file=sys.stderr)
        return 2
    os.environ.setdefault("TENGSIM_FFT_WORKERS", "1")
    rows = []
    load = os.getloadavg()
    dts = [args.dt, args.dt / 2] if args.halve else [args.dt]
    py, ttol, R = args.tamaas_python, args.tamaas_tol, args.replica_steps
    for n in args.sizes:
        h = heights(n)
        row = {"n": n, "rms": float(h.std()), "load": load, "p_max": args.p_max, "runs": {}}
        for i, dt in enumerate(dts):
            tam = run_tamaas(h, py, ttol, dt, args.p_max, replica_steps=R if i == 0 else 0, convention=i == 0)
            ten = run_tengsim(h, dt, args.p_max, args.tol)
            row["runs"][f"{dt:g}"] = {"dt": dt, "tamaas": tam, "tengsim": ten,
                                      "diff": compare(ten, tam) if "error" not in tam else None}
        ten0 = row["runs"][f"{dts[0]:g}"]["tengsim"]
        doc = run_tamaas(h, py, ttol, dts[0], args.p_max, variant="documented", replica_steps=R)
        row["documented"] = {"dt": dts[0], "tamaas": doc, "diff": compare(ten0, doc) if "error" not in doc else None}
        if len(dts) == 2:
            a, b = (row["runs"][f"{d:g}"] for d in dts)
            row["halving"] = {"tengsim": compare(a["tengsim"], b["tengsim"])}
            if a["diff"] and b["diff"]:
                row["halving"]["tamaas"] = compare(a["tamaas"], b["tamaas"])
                ext = richardson(a["tamaas"], b["tamaas"])
                row["extrapolated"] = {"tamaas": ext, "diff": compare(b["tengsim"], ext)}
        if not args.no_limit:  # the long hold: both against the elastic solves at E*∞ and E*0 (Tamaas' PKR)
            ten = run_tengsim(h, 0.5 * TAU, args.p_max, args.tol, LIMIT_KNOTS)
            row["limit"] = {"dt": 0.5 * TAU, "t_end": LIMIT_KNOTS[0][-1] * TAU, "tengsim_area": ten["area"][-1],
                            "tengsim_gap": ten["mean_gap"][-1], "tengsim_cpu": ten["cpu"],
                            "elastic": row["runs"][f"{dts[0]:g}"]["tamaas"].get("convention")}
            for variant in ("unit_shear", "documented"):
                tam = run_tamaas(h, py, ttol, 0.5 * TAU, args.p_max, LIMIT_KNOTS, variant=variant)
                row["limit"][variant] = {"area": tam.get("area", [float("nan")])[-1],
                                         "gap": tam.get("mean_gap", [float("nan")])[-1], "cpu": tam.get("cpu")}
        rows.append(row)
        print(json.dumps({"n": n, **{k: (v["diff"], v["tengsim"]["cpu"], v["tamaas"].get("cpu"))
                                     for k, v in row["runs"].items()},
                          "documented": row["documented"]["diff"],
                          "extrapolated": row.get("extrapolated", {}).get("diff")}), flush=True)
    if args.out:
        with open(args.out, "w") as f:
            json.dump(rows if args.series else compact(rows), f, indent=1)
    report(rows)
    return 0


def _line(r, label, dt, steps, m, t, d):
    ratio = f"{m['cpu'] / t['cpu']:.2f}" if t and t.get("cpu") else ""
    tcpu = f"{t['cpu']:.3g}" if t and t.get("cpu") else ""
    print(f"| {r['n']}² | {label} | {dt} | {steps} | {m['cpu']:.3g} | {tcpu} | {ratio} | "
          f"{d['max_area']:.1e} (t = {d['t_max_area']:g}) | {d['max_gap']:.1e} (t = {d['t_max_gap']:g}) |")


SERIES = ("t", "p", "area", "mean_gap", "solve_error", "gap_spread_in_contact", "penetration")
"""The per-step series of a run: summarised in --out unless --series."""


def compact(x):
    """``x`` (the rows) with each per-step series replaced by its length, ends and range: the comparison's numbers
    stay, the file stays small."""
    if isinstance(x, list):
        return [compact(v) for v in x]
    if not isinstance(x, dict):
        return x
    out = {}
    for k, v in x.items():
        if k in SERIES and isinstance(v, list) and len(v) > 2:
            f = [float(a) for a in v]
            out[k] = {"steps": len(f), "first": f[0], "last": f[-1], "min": min(f), "max": max(f)}
        else:
            out[k] = compact(v)
    return out


def report(rows):
    print("| grid | Tamaas run | Δt (τ) | steps | tengsim CPU s | Tamaas CPU s | CPU ratio tengsim/Tamaas | "
          "max Δ area | max Δ mean gap (ε) |")
    print("|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        for v in r["runs"].values():
            t, m, d = v["tamaas"], v["tengsim"], v["diff"]
            if d is None:
                print(f"| {r['n']}² | G∞ = 1 | {v['dt']:g} | | {m['cpu']:.3g} | {t['error']} | | | |")
                continue
            _line(r, "G∞ = 1", f"{v['dt']:g}", len(m["t"]) - 1, m, t, d)
        if r.get("extrapolated"):
            dts = list(r["runs"])
            _line(r, "G∞ = 1, 2A(Δt/2) − A(Δt)", "→ 0", "", r["runs"][dts[1]]["tengsim"], None,
                  r["extrapolated"]["diff"])
        doc = r["documented"]
        if doc["diff"]:
            m = r["runs"][f"{doc['dt']:g}"]["tengsim"]
            _line(r, "documented (2.9 bug)", f"{doc['dt']:g}", len(m["t"]) - 1, m, doc["tamaas"], doc["diff"])
        if "halving" in r:
            hv = r["halving"]
            print(f"| {r['n']}² | Δt → Δt/2 | | | area {hv['tengsim']['max_area']:.1e}, "
                  f"gap {hv['tengsim']['max_gap']:.1e} "
                  f"| area {hv.get('tamaas', {}).get('max_area', float('nan')):.1e}, gap "
                  f"{hv.get('tamaas', {}).get('max_gap', float('nan')):.1e} | | | |")
    for r in rows:
        for label, t in (("G∞ = 1", next(iter(r["runs"].values()))["tamaas"]), ("documented", r["documented"]["tamaas"])):
            if "area" not in t:
                continue
            rep = t.get("replica")
            if rep:
                print(f"{r['n']}² Tamaas {label}: numpy replica ({'corrected' if rep['consistent'] else '2.9'} update, "
                      f"{rep['steps']} steps) max|Δp|/max p {rep['max_dp_rel']:.1e}, max|Δ area| {rep['max_darea']:.1e}")
            print(f"{r['n']}² Tamaas {label}: contact condition, largest spread of u − h over p > 0 "
                  f"{max(t['gap_spread_in_contact']):.2e} ε, largest penetration off contact {max(t['penetration']):.2e} ε")
        if r.get("limit") and r["limit"]["elastic"]:
            lm, c = r["limit"], r["limit"]["elastic"]
            print(f"{r['n']}² held p̄ to t = {lm['t_end']:g} τ (Δt = {lm['dt']:g}): area tengsim "
                  f"{lm['tengsim_area']:.5f}, Tamaas G∞ = 1 {lm['unit_shear']['area']:.5f}, documented "
                  f"{lm['documented']['area']:.5f}; elastic (Tamaas PKR) at E*∞ {c['relaxed']['area_elastic']:.5f}, "
                  f"at E*0 {c['glassy']['area_elastic']:.5f}; mean gap tengsim {lm['tengsim_gap']:.4f}, Tamaas G∞ = 1 "
                  f"{lm['unit_shear']['gap']:.4f}, documented {lm['documented']['gap']:.4f}, elastic at E*∞ "
                  f"{c['relaxed']['gap_elastic']:.4f}")
        v = next(iter(r["runs"].values()))
        if v["tamaas"].get("convention"):
            c = v["tamaas"]["convention"]
            print(f"{r['n']}² Tamaas convention (one step from rest): glassy vs elastic E*={c['glassy']['E_star']:g}: "
                  f"max|Δp| {c['glassy']['max_dp']:.1e} (p max {c['glassy']['max_p']:.3g}); relaxed vs "
                  f"E*={c['relaxed']['E_star']:g}: {c['relaxed']['max_dp']:.1e}")
        for key, v in r["runs"].items():
            m, t = v["tengsim"], v["tamaas"]
            if "area" not in t:
                continue
            idx = [i for i, s in enumerate(m["t"]) if any(abs(s - k * TAU) < 1e-9 for k in T_KNOTS[1:])
                   or abs(s - 0.5 * TAU) < 1e-9 or abs(s - 2 * TAU) < 1e-9]
            print(f"{r['n']}² Δt={key}: t: area tengsim / Tamaas G∞ = 1, mean gap tengsim / Tamaas: " + "; ".join(
                f"{m['t'][i]:g}: {m['area'][i]:.5f} / {t['area'][i]:.5f}, {m['mean_gap'][i]:.4f} / "
                f"{t['mean_gap'][i]:.4f}" for i in idx))


if __name__ == "__main__":
    sys.exit(main())
