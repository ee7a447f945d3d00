"""The paper's contact figures: Fig. 3 (pressure maps), Fig. 4 (Λc and F against D and F), Fig. 5 (V_OC against
pressure), one colour per group."""
from __future__ import annotations

import numpy as np

from tengsim.plots import draw_branches, pyplot, save

COLORS = {"A": "tab:blue", "B": "tab:orange", "C": "tab:green"}


def plot_fig3(results: dict, path, d_values=(1.0, 3.0, 6.0, 14.0)) -> None:
    """Fig. 3: pressure maps P(X, Y) on approach, rows = groups, columns = D."""
    plt = pyplot()
    groups = list(results)
    fig, axs = plt.subplots(len(groups), len(d_values), figsize=(3.4 * len(d_values), 2.9 * len(groups)),
                            squeeze=False, constrained_layout=True)
    for i, g in enumerate(groups):
        res = results[g]
        maps = {round(m["D"], 9): m for m in res.maps if m["branch"] == "approach"}
        for j, D in enumerate(d_values):
            ax = axs[i, j]
            m = maps.get(round(D, 9))
            if m is None:
                ax.set_axis_off()
                continue
            P = m["P"]
            lim = max(1e-9, float(np.percentile(np.abs(P), 99.5)))
            ext = [res.grid.x[0], res.grid.x[-1], res.grid.y[0], res.grid.y[-1]]
            im = ax.imshow(P.T, origin="lower", extent=ext, cmap="RdBu_r", vmin=-lim, vmax=lim)
            ax.set_title(f"group {g}, D = {D:g}", fontsize=9)
            ax.set_xlabel("X")
            if j == 0:
                ax.set_ylabel("Y")
            fig.colorbar(im, ax=ax, shrink=0.8)
    fig.suptitle("Pressure P (Eq. 8; positive = compressive, colour scale symmetric), approach")
    save(fig, path)


def plot_fig4(results: dict, path, paper_transition: dict | None = None) -> None:
    """Fig. 4: (a) Λc(D), (b) Λc(F), (c) F(D) for the groups; approach solid, retraction dashed."""
    plt = pyplot()
    fig, axs = plt.subplots(1, 3, figsize=(13, 3.8))
    for g, res in results.items():
        c = COLORS.get(g, None)
        draw_branches(axs[0], res, "D", "contact_length", c, g)
        draw_branches(axs[1], res, "F", "contact_length", c, g)
        draw_branches(axs[2], res, "D", "F", c, g)
        if paper_transition and g in paper_transition:
            axs[0].axvline(paper_transition[g], color=c, lw=0.8, ls=":")
    labels = [("D", r"$\Lambda_c$", "(a)"), ("F", r"$\Lambda_c$", "(b)"), ("D", "F", "(c)")]
    for ax, (xl, yl, tag) in zip(axs, labels):
        ax.set_xlabel(xl)
        ax.set_ylabel(yl)
        ax.set_title(tag, loc="left")
        ax.grid(alpha=0.3)
    axs[0].legend(fontsize=7, ncol=1)
    if paper_transition:
        axs[0].text(0.98, 0.02, "dotted: paper's transition D", transform=axs[0].transAxes,
                    ha="right", fontsize=7)
    save(fig, path)


def plot_fig5(curves: dict, path) -> None:
    """Fig. 5: V_OC (Eq. 12) against pressure f/L² (kPa), one curve per group.

    ``curves`` maps group → (pressure_Pa, voc_V)."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(5.2, 3.8))
    for g, (p, v) in curves.items():
        ax.plot(np.asarray(p) / 1e3, v, "-", color=COLORS.get(g), label=f"group {g}")
    ax.set_xlabel("pressure $f/L^2$ (kPa)")
    ax.set_ylabel("$V_{OC}$ (V), Eq. (12)")
    ax.set_xscale("log")
    ax.grid(alpha=0.3, which="both")
    ax.legend()
    save(fig, path)
