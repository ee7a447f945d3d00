"""Figures of a design and of a comparison, in physical units (kPa, µm, V); each function returns its Figure.

:func:`design_figure`: A/S and the repulsive area, V_OC (Eq. 12 and Eq. 17 at the rest gap) and dV_OC/dP against
the nominal pressure, approach and retraction.  :func:`maps_figure`: the contact pressure maps (kPa) on the
approach at the asked pressures nearest the maps the run kept.  :func:`compare_figure`: several designs, one
categorical colour each, a filled marker for status ok and an open one otherwise.
"""
from __future__ import annotations

import numpy as np

from tengsim.plots import pyplot
from tengsim.status.levels import Status

BRANCH_STYLE = {"approach": "-", "retraction": "--"}


def title(plan, status: str | None = None) -> str:
    from tengsim.units import length_text

    sizes = plan.shape_text()
    mat = (f"E* {plan.E_star / 1e6:.3g} MPa, W {plan.W * 1e3:.3g} mJ/m², ε {length_text(plan.eps)}, "
           f"μ {plan.tabor:.2g}")
    st = f" — status {status}" if status else ""
    return f"{plan.shape}: {sizes}\n{mat}{st}"


def design_figure(result):
    """A/S (and the repulsive area), V_OC (Eq. 12, Eq. 17) and dV_OC/dP against pressure (kPa)."""
    plt = pyplot()
    ds = result.dataset
    P = ds["pressure"].values / 1e3
    fig, axes = plt.subplots(1, 3, figsize=(13, 4.2), constrained_layout=True)
    branches = ("approach", "retraction") if getattr(result.plan, "retraction", True) else ("approach",)
    ax = axes[0]
    for b in branches:
        ax.plot(P, ds["charged_area_fraction"].sel(branch=b), BRANCH_STYLE[b], color="C0", marker="o", ms=3,
                label=f"charged A/S, {b}")
        ax.plot(P, ds["repulsive_area_fraction"].sel(branch=b), BRANCH_STYLE[b], color="C7",
                label=f"repulsive area, {b}")
    ax.set_xlabel("nominal pressure (kPa)")
    ax.set_ylabel("area over cell area A/S (1)")
    ax.legend(fontsize=7)
    ax = axes[1]
    for b in branches:
        ax.plot(P, ds["voc_eq12"].sel(branch=b), BRANCH_STYLE[b], color="C1", marker="o", ms=3,
                label=f"Eq. 12 (polymer), {b}")
    ax.set_xlabel("nominal pressure (kPa)")
    ax.set_ylabel("open-circuit voltage, Eq. 12 (V)")
    tw = ax.twinx()
    for b in branches:
        tw.plot(P, ds["voc_eq17"].sel(branch=b), BRANCH_STYLE[b], color="C2", label=f"Eq. 17 (rest gap), {b}")
    tw.set_ylabel(f"open-circuit voltage at rest gap {ds.attrs['gap_m'] * 1e3:.3g} mm, Eq. 17 (V)", color="C2")
    h1, l1 = ax.get_legend_handles_labels()
    h2, l2 = tw.get_legend_handles_labels()
    ax.legend(h1 + h2, l1 + l2, fontsize=7)
    ax = axes[2]
    for b in branches:
        ax.plot(P, ds["dvoc_dp"].sel(branch=b) * 1e3, BRANCH_STYLE[b], color="C3", marker="o", ms=3, label=b)
    ax.set_xlabel("nominal pressure (kPa)")
    ax.set_ylabel("sensitivity dV_OC/dP, Eq. 12 (V/kPa)")
    ax.legend(fontsize=7)
    for a in (*axes, tw):
        a.ticklabel_format(axis="y", useOffset=False)
    only = "" if len(branches) == 2 else " — the approach only (retraction = false)"
    fig.suptitle(title(result.plan, result.status) + only, fontsize=10)
    return fig


def maps_figure(result):
    """Contact pressure maps (kPa) on the approach at the pressures the run kept maps for; None if none."""
    plt = pyplot()
    res = result.maps
    if res is None:
        return None
    maps = [m for m in res.maps if str(m["branch"]) == "approach"]
    if not maps:
        return None
    sc = res.scaling
    unit = sc.W / sc.eps  # W/ε: the pressure unit of Eq. (8), Pa
    lat = sc.lateral * 1e6
    a = res.branch("approach")
    asked = dict(result.summary.get("map_pressures_asked", {}))
    from tengsim.design.walk import peak_separation

    g_c = peak_separation(result.plan)
    fig, axes = plt.subplots(1, len(maps), figsize=(4.3 * len(maps), 4.1), constrained_layout=True, squeeze=False)
    for ax, m in zip(axes[0], maps):
        Pmap = np.asarray(m["P"], float) * unit / 1e3
        nx, ny = Pmap.shape
        hx, hy = nx * res.grid.dx * lat / 2, ny * res.grid.dy * lat / 2
        lim = float(np.nanmax(np.abs(Pmap))) or 1.0
        im = ax.imshow(Pmap.T, origin="lower", extent=[-hx, hx, -hy, hy], cmap="RdBu_r", vmin=-lim, vmax=lim)
        _edge_contour(ax, m, g_c, hx, hy)
        ax.set_xlabel("x (µm)")
        ax.set_ylabel("y (µm)")
        i = int(np.argmin(np.abs(np.asarray(a["D"], float) - m["D"])))
        nominal = float(a["pressure_Pa"][i]) / 1e3
        want = asked.get(round(float(m["D"]), 9))
        extra = f" (asked {want / 1e3:.3g} kPa)" if want is not None else ""
        ax.set_title(f"approach, {nominal:.3g} kPa{extra}", fontsize=9)
        fig.colorbar(im, ax=ax, label="contact pressure (kPa; < 0 adhesive)")
    if g_c is not None:
        fig.supxlabel(f"black contour: the charged area's edge, gap = {g_c:.4g} ε (the law's peak-tension "
                      "separation; the 2-D charged area lies inside)", fontsize=8)
    fig.suptitle(title(result.plan, result.status), fontsize=10)
    return fig


def _edge_contour(ax, m, g_c, hx, hy):
    """The contour g = g_c (the charged area's edge) of a kept map's gap H (g = H + 1), in black."""
    H = m.get("H") if isinstance(m, dict) else None
    if H is None or g_c is None:
        return
    g = np.asarray(H, float) + 1.0
    if not (np.nanmin(g) <= g_c <= np.nanmax(g)):
        return
    nx, ny = g.shape
    x = (np.arange(nx) + 0.5) / nx * 2 * hx - hx
    y = (np.arange(ny) + 0.5) / ny * 2 * hy - hy
    ax.contour(x, y, g.T, levels=[g_c], colors="k", linewidths=0.9)


def compare_figure(results):
    """A/S and V_OC (Eq. 12) on the approach against pressure for several designs (DesignResults or design.nc
    Datasets): one colour per design, a filled marker where its status is ok, an open one where it is not."""
    plt = pyplot()
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.5), constrained_layout=True)
    for i, r in enumerate(results):
        ds = getattr(r, "dataset", r)  # a DesignResult or a design.nc Dataset
        P = ds["pressure"].values / 1e3
        status = str(ds.attrs.get("status", "?"))
        ok = status == Status.OK
        style = dict(color=f"C{i % 10}", marker="o" if ok else "s", ms=4, mfc=None if ok else "none")
        label = f"{ds.attrs.get('design_name', ds.attrs.get('shape'))} (μ {float(ds.attrs['tabor']):.2g}; {status})"
        axes[0].plot(P, ds["charged_area_fraction"].sel(branch="approach"), "-", label=label, **style)
        axes[1].plot(P, ds["voc_eq12"].sel(branch="approach"), "-", label=label, **style)
    axes[0].set_xlabel("nominal pressure (kPa)")
    axes[0].set_ylabel("charged area over cell area A/S, approach (1)")
    axes[1].set_xlabel("nominal pressure (kPa)")
    axes[1].set_ylabel("open-circuit voltage, Eq. 12, approach (V)")
    axes[0].legend(fontsize=7)
    fig.suptitle("designs compared (filled marker: status ok; open: not converged)", fontsize=10)
    return fig


def save_design_figures(result, out_dir) -> list:
    """Write design.png (and maps.png when the run kept maps) into ``out_dir``; returns the paths."""
    from pathlib import Path

    plt = pyplot()
    out = []
    for name, make in (("design.png", design_figure), ("maps.png", maps_figure)):
        fig = make(result)
        if fig is None:
            continue
        path = Path(out_dir) / name
        from tengsim.io import save_figure

        try:
            save_figure(fig, path, dpi=110)  # atomic: a full disk names the path and leaves no partial file
        finally:
            plt.close(fig)
        out.append(path)
    return out
