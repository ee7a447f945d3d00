"""A fitted material for new designs: material.toml read, and a design's prediction with bands.

material.toml (written by :func:`tengsim.calibrate.write.material_text`): ``[design]`` the best values (E_star, W,
eps, sigma with units), which replace a design's own; ``[uncertainty]`` the 95 % intervals and
``[[uncertainty.point]]`` the parameter points that span the fitted uncertainty: the best point with σ at both ends
of its interval, and for each free contact parameter the two ends of its profile interval (the other parameters at
their profile optimum there, σ profiled).  A prediction runs the design at each point (converged designs, status
ok) and gives as its 95 % band the envelope of A/S and V_OC over them (:func:`predict_bands`): the profile-likelihood
band of a new geometry, propagated through the contact model rather than linearised.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from tengsim.errors import TengsimError

MATERIAL_KEYS = ("E_star", "W", "eps", "sigma")


def band_points(cal) -> list:
    """[{name: SI}] of the points spanning the fitted uncertainty (module doc)."""
    f, prob = cal.fit, cal.problem
    base = {k: v for k, v in prob.fixed.items()}
    best = {**base, **f.best}
    pts = []
    if "sigma" in prob.free:
        for s in f.interval["sigma"][:2]:
            pts.append({**best, "sigma": s})
    for j, name in enumerate(prob.contact_free):
        axis = f.grid_theta[:, j]
        for end in f.interval[name][:2]:
            target = math.log(end)
            near = np.abs(axis - target) <= np.min(np.abs(axis - target)) + 1e-12
            k = np.flatnonzero(near)[np.argmin(f.grid_dev[near])]
            ph = cal.model.physical(f.grid_theta[k][None, :])
            pt = {**base, "sigma": float(f.grid_sigma[k])}
            for n in ("W", "eps", "E_star"):
                if n in prob.contact_free:
                    pt[n] = float(ph[n][0])
            pts.append(pt)
    return pts


def read_material(path) -> dict:
    """{'values': {key: text}, 'points': [{key: text}], 'intervals': {...}} of a material.toml; a file that is not
    one: one line."""
    from tengsim.calibrate.data import read_toml

    data = read_toml(path, f"--material {path}")
    vals = data.get("design", data.get("material"))
    if not isinstance(vals, dict) or not any(k in vals for k in MATERIAL_KEYS):
        raise TengsimError(f"--material {path}: no [design] table with E_star, W, eps or sigma (a material.toml "
                           "that tengsim calibrate writes)")
    bad = sorted(k for k in vals if k not in MATERIAL_KEYS)
    if bad:
        raise TengsimError(f"--material {path}: {', '.join(bad)}: not a material key ({', '.join(MATERIAL_KEYS)})")
    unc = data.get("uncertainty", {}) or {}
    pts = [dict(x) for x in unc.get("point", [])]
    return {"values": dict(vals), "points": pts, "path": str(path)}


def predict_bands(plan, result, material: dict, progress=None) -> dict | None:
    """{'pressure', 'area_lower', 'area_upper', 'voc_lower', 'voc_upper' (approach, Eq. 12), 'points', 'statuses'}:
    the envelope over the design run at each of the material's points (module doc; one design per
    distinct (E*, W, ε): σ scales V_OC); None without points."""
    from tengsim.design import plan_design, run_design

    if not material["points"]:
        return None
    ds = result.dataset
    A = [np.asarray(ds["charged_area_fraction"].sel(branch="approach").values, float)]
    V = [np.asarray(ds["voc_eq12"].sel(branch="approach").values, float)]
    statuses = [result.status]
    table = dict(plan.contact_table)
    own = {k: getattr(plan, k) for k in ("eps_r", "T", "gap", "tol")}
    from tengsim.calibrate.problem import KINDS, label, text
    from tengsim.units import parse_quantity

    def si(pt, k):
        return round(parse_quantity(pt[k], KINDS[k], k), 12) if k in pt else None

    solved = {(round(plan.E_star, 12), round(plan.W, 12), round(plan.eps, 12)): A[0]}  # the design itself
    contact = [k for k in MATERIAL_KEYS if k != "sigma"]
    todo = {}
    for pt in material["points"]:
        key = tuple(si(pt, k) if k in pt else round(getattr(plan, k), 12) for k in contact)
        if key not in solved:
            todo.setdefault(key, pt)
    for i, (key, pt) in enumerate(todo.items()):  # σ enters linearly: one design per (E*, W, ε)
        if progress is not None:
            progress(f"band: design {i + 1}/{len(todo)} at " + ", ".join(
                f"{label(k)} {text(k, si(pt, k))}" for k in contact if k in pt))
        t = {**{k: v for k, v in table.items() if k not in MATERIAL_KEYS}, **own,
             **{k: pt[k] for k in contact if k in pt}, "p_min": plan.pressures[0], "p_max": plan.pressures[-1],
             "p_step": (plan.pressures[-1] - plan.pressures[0]) / max(len(plan.pressures) - 1, 1), "maps": False}
        r = run_design(plan_design(t))
        statuses.append(r.status)
        a = np.asarray(r.dataset["charged_area_fraction"].sel(branch="approach").values, float)
        if len(a) != len(A[0]):
            a = np.interp(plan.pressures, np.asarray(r.dataset["pressure"].values), a)
        solved[key] = a
    A, V = [A[0]], [V[0]]
    from tengsim.device.params import EPS0

    k12 = plan.T / (plan.eps_r * EPS0)  # V_OC per σ per A/S (Eq. 12)
    for pt in material["points"]:
        key = tuple(si(pt, k) if k in pt else round(getattr(plan, k), 12) for k in contact)
        a = solved[key]
        A.append(a)
        V.append((si(pt, "sigma") if "sigma" in pt else plan.sigma) * k12 * a)
    A, V = np.array(A), np.array(V)
    return {"pressure": np.asarray(plan.pressures, float), "area": A[0], "area_lower": np.nanmin(A, axis=0),
            "area_upper": np.nanmax(A, axis=0), "voc": V[0], "voc_lower": np.nanmin(V, axis=0),
            "voc_upper": np.nanmax(V, axis=0), "points": len(material["points"]), "statuses": tuple(statuses)}


def write_bands(bands: dict, out_dir, name: str = "") -> list:
    """DIR/bands.csv and DIR/bands.png of a prediction's bands."""
    from tengsim.io import csv_text, write_text
    from tengsim.plots import _plt, save

    out = Path(out_dir)
    ok = all(s == "ok" for s in bands["statuses"])
    header = {"band": "95 % (envelope over the material's uncertainty points, profile likelihood)",
              "designs": len(bands["statuses"]), "all_ok": ok}
    cols = {"pressure_kPa": bands["pressure"] / 1e3, "area_fraction": bands["area"],
            "area_fraction_lower": bands["area_lower"], "area_fraction_upper": bands["area_upper"],
            "voc_eq12_V": bands["voc"], "voc_eq12_lower_V": bands["voc_lower"], "voc_eq12_upper_V": bands["voc_upper"]}
    write_text(out / "bands.csv", csv_text(cols, header, missing=""))
    plt = _plt()
    fig, axes = plt.subplots(1, 2, figsize=(9, 3.4))
    P = bands["pressure"] / 1e3
    for ax, k, lab in ((axes[0], "area", "charged area A/S"), (axes[1], "voc", "V_OC, Eq. 12 (V)")):
        ax.fill_between(P, bands[f"{k}_lower"], bands[f"{k}_upper"], where=np.ones(np.shape(P), bool), alpha=0.3,
                        lw=0)  # ``where`` given: matplotlib 3.6.0 with numpy 1.24 (the floors) fails on its default
        ax.plot(P, bands[k], color="C0")
        ax.set_xlabel("nominal pressure (kPa)")
        ax.set_ylabel(lab)
    axes[0].set_title(f"{name} with the fitted material's 95 % band", fontsize=9)
    save(fig, out / "bands.png")
    return [out / "bands.csv", out / "bands.png"]
