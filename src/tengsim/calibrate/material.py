"""The points of a fitted material's uncertainty, for material.toml's ``[[uncertainty.point]]``.

material.toml (written by :func:`tengsim.calibrate.write.material_text`, read by
:func:`tengsim.design.material_table`): ``[design]`` the best values (E_star, W, eps, sigma with units), which
replace a design's own; ``[uncertainty]`` the 95 % intervals and ``[[uncertainty.point]]`` the parameter points that
span the fitted uncertainty (:func:`band_points`): the best point with σ at both ends of its interval, and for each
free contact parameter the two ends of its profile interval (the other parameters at their profile optimum there,
σ profiled).  A prediction runs the design at each point and gives as its 95 % band the envelope of A/S and V_OC
over them (:func:`tengsim.design.predict_bands`).
"""
from __future__ import annotations

import math

import numpy as np


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
