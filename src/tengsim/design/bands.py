"""A design's prediction band from a fitted material's uncertainty points (``tengsim design --material``).

:func:`tengsim.design.plan.plan_design` with a :class:`tengsim.design.material.Material` plans, beside the design
at the material's best values, one design per uncertainty point (:func:`tengsim.design.plan.plan_bands`: the
design's table with the point's values, every value within the design's own bounds, all checked before anything
runs).  After the design
ran, :func:`predict_bands` runs the points' designs (one per distinct (E*, W, ε): σ enters V_OC linearly) and gives
as the 95 % band the envelope of A/S and V_OC (Eq. 12) over them: the profile-likelihood band of a new geometry,
propagated through the contact model rather than linearised.  :func:`write_bands` writes bands.csv and bands.png.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
from tengsim.status.levels import Status


def _key(plan) -> tuple:
    return round(plan.E_star, 12), round(plan.W, 12), round(plan.eps, 12)


def predict_bands(result, progress=None) -> dict | None:
    """{'pressure', 'area', 'area_lower', 'area_upper', 'voc', 'voc_lower', 'voc_upper' (approach, Eq. 12), 'points',
    'statuses'}: the envelope over the design ``result`` and its plan's band points (module doc); None without
    points."""
    from tengsim.design.run import run_design
    from tengsim.device.formulas import eq12_volts_per_charge
    from tengsim.units import format_si

    plan = result.plan
    points = tuple(getattr(plan, "bands", ()) or ())
    if not points:
        return None
    ds = result.dataset
    A0 = np.asarray(ds["charged_area_fraction"].sel(branch="approach").values, float)
    V0 = np.asarray(ds["voc_eq12"].sel(branch="approach").values, float)
    statuses = [result.status]
    solved = {_key(plan): A0}  # the design itself
    todo = {}
    for bp in points:
        todo.setdefault(_key(bp), bp)
    todo = {k: bp for k, bp in todo.items() if k not in solved}
    for i, bp in enumerate(todo.values()):
        if progress is not None:
            progress(f"band: design {i + 1}/{len(todo)} at E* {format_si(bp.E_star, 'Pa')}, W "
                     f"{format_si(bp.W, 'J/m²')}, ε {format_si(bp.eps, 'm')}")
        r = run_design(bp)
        statuses.append(r.status)
        a = np.asarray(r.dataset["charged_area_fraction"].sel(branch="approach").values, float)
        if len(a) != len(A0):
            a = np.interp(plan.pressures, np.asarray(r.dataset["pressure"].values), a)
        solved[_key(bp)] = a
    k12 = eq12_volts_per_charge(plan.eps_r, plan.T)  # V_OC per σ per A/S (Eq. 12)
    A, V = [A0], [V0]
    for bp in points:
        a = solved[_key(bp)]
        A.append(a)
        V.append(bp.sigma * k12 * a)
    A, V = np.array(A), np.array(V)
    return {"pressure": np.asarray(plan.pressures, float), "area": A[0], "area_lower": np.nanmin(A, axis=0),
            "area_upper": np.nanmax(A, axis=0), "voc": V[0], "voc_lower": np.nanmin(V, axis=0),
            "voc_upper": np.nanmax(V, axis=0), "points": len(points), "statuses": tuple(statuses)}


BAND_FILES = ("bands.csv", "bands.png")
"""The files a prediction's band adds to a design's folder."""


def write_bands(bands: dict, out_dir, name: str = "") -> list:
    """DIR/bands.csv and DIR/bands.png of a prediction's bands."""
    from tengsim.io import csv_text, write_text
    from tengsim.plots import pyplot, save

    out = Path(out_dir)
    ok = all(s == Status.OK for s in bands["statuses"])
    header = {"band": "95 % (envelope over the material's uncertainty points, profile likelihood)",
              "designs": len(bands["statuses"]), "all_ok": ok}
    cols = {"pressure_kPa": bands["pressure"] / 1e3, "area_fraction": bands["area"],
            "area_fraction_lower": bands["area_lower"], "area_fraction_upper": bands["area_upper"],
            "voc_eq12_V": bands["voc"], "voc_eq12_lower_V": bands["voc_lower"], "voc_eq12_upper_V": bands["voc_upper"]}
    write_text(out / "bands.csv", csv_text(cols, header, missing=""))
    plt = pyplot()
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


__all__ = ["BAND_FILES", "predict_bands", "write_bands"]
