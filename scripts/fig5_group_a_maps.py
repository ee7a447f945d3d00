"""Why Fig. 5 group A's V_OC (and Fig. 8's A/S) falls with pressure: the pressure maps of group A (paper scaling,
μ = 0.5, free cell, dx 0.1, the reproduce's grid) at 10 and 150 kPa on the contact branch, with the charged area's
edge (g = 3^{1/6}) and the X row through the apex, whose innermost tensile minimum is the paper's Λc/2.

    OPENBLAS_NUM_THREADS=1 python scripts/fig5_group_a_maps.py docs/data/fig5_group_a_maps.png

Prints, per pressure: D, the nominal pressure, Λc, the base 2N, the paper's A/S = (Λc/L̄)², the 2-D charged area
and the repulsive area (docs/paper_comparison.md, "Fig. 5 group A's falling V_OC").
"""
import sys

import numpy as np


def main(out):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from tengsim.analysis import apex_index, charged_area, contact_length, tensile_peak_offset
    from tengsim.cases.paper.contact import group_shape
    from tengsim.cases.paper.units import paper_scaling
    from tengsim.continuation import walk_states
    from tengsim.kernels import FreeKernel
    from tengsim.laws import LJ93
    from tengsim.solvers import FastSolver

    sc = paper_scaling("A")
    shape = group_shape("A")
    grid = shape.grid(0.1)
    U0 = shape.gap(grid)
    apex = apex_index(U0)
    kernel = FreeKernel(grid, sc.mu ** 1.5)
    g_c = LJ93().peak_separation
    Ds = np.r_[np.arange(-1.0, 1.71, 0.1), 1.878, 3.045]   # the load-controlled states at 10 and 150 kPa
    fig, axes = plt.subplots(1, 3, figsize=(14, 4.2), constrained_layout=True)
    kept = []
    for D, eq in walk_states(U0, LJ93(), kernel, FastSolver(1e-8, max_iter=30000), Ds):
        if D < 1.8:
            continue
        p = sc.pressure(float(eq.P.sum() * grid.area / (3 * np.pi)))
        lam = contact_length(eq.P, grid, apex)
        A2 = charged_area(eq.H, grid, g_c) / (grid.nx * grid.ny * grid.area)
        rep = np.count_nonzero(eq.P > 0) / eq.P.size
        print(f"D {D:.3f}  {p / 1e3:7.2f} kPa  Λc {lam:.4f}  2N {2 * sc.N:.4f}  paper A/S {(lam / sc.cell) ** 2:.4f}  "
              f"2-D A/S {A2:.4f}  repulsive {rep:.4f}")
        kept.append((D, p, eq, lam))
    lat = sc.length(1.0) * 1e6
    unit = sc.force(1.0) / (3 * np.pi * sc.length(1.0) ** 2)  # W/ε in Pa: the local pressure of Eq. (8)
    for ax, (D, p, eq, lam) in zip(axes[:2], kept):
        Pk = eq.P * unit / 1e3
        h = grid.nx * grid.dx * lat / 2
        lim = float(np.max(np.abs(Pk)))
        im = ax.imshow(Pk.T, origin="lower", extent=[-h, h, -h, h], cmap="RdBu_r", vmin=-lim, vmax=lim)
        x = (np.arange(grid.nx) + 0.5) / grid.nx * 2 * h - h
        ax.contour(x, x, (eq.H + 1).T, levels=[g_c], colors="k", linewidths=0.8)
        b = sc.N * lat
        ax.plot([-b, b, b, -b, -b], [-b, -b, b, b, -b], ":", color="C2", lw=1)
        ax.axvline(lam / 2 * lat, color="C1", lw=0.8)
        ax.axvline(-lam / 2 * lat, color="C1", lw=0.8)
        ax.set_title(f"group A, {p / 1e3:.0f} kPa (D {D:.2f} ε)", fontsize=9)
        ax.set_xlabel("x (µm)")
        ax.set_ylabel("y (µm)")
        fig.colorbar(im, ax=ax, label="contact pressure (kPa; < 0 tensile)")
    ax = axes[2]
    for (D, p, eq, lam), c in zip(kept, ("C0", "C3")):
        i0, j0 = apex
        row = eq.P[:, j0] * unit / 1e3
        x = (np.arange(grid.nx) - i0) * grid.dx * lat
        ax.plot(x, row, color=c, label=f"{p / 1e3:.0f} kPa: Λc/2 = {lam / 2 * lat:.3f} µm")
        ax.axvline(lam / 2 * lat, color=c, lw=0.8, ls="--")
    ax.axvline(sc.N * lat, color="C2", ls=":", label=f"pyramid base edge N = {sc.N * lat:.3f} µm")
    ax.set_xlim(0, grid.nx * grid.dx * lat / 2)
    ax.set_xlabel("x along the row through the apex (µm)")
    ax.set_ylabel("pressure (kPa)")
    ax.legend(fontsize=7)
    fig.suptitle("black: charged area's edge g = 3$^{1/6}$ ε (the whole cell is inside); orange: ±Λc/2, the paper's "
                 "innermost tensile minimum; green dotted: the pyramid's base", fontsize=9)
    fig.savefig(out, dpi=110)


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "fig5_group_a_maps.png")
