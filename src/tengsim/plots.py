"""Contact figures: paper Figs. 3, 4, 5 and a generic approach–retraction plot.  Agg backend."""
from __future__ import annotations

import numpy as np

from tengsim.io import atomic_path

COLORS = {"A": "tab:blue", "B": "tab:orange", "C": "tab:green"}


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save(fig, path) -> None:
    """Save a figure atomically (format from the suffix) and close it: the one figure writer of tengsim."""
    from pathlib import Path

    plt = _plt()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format=Path(path).suffix.lstrip(".") or "png", dpi=150, bbox_inches="tight")
    plt.close(fig)


def _branches(ax, res, x, y, color, label, jumps=True):
    for b, ls in (("approach", "-"), ("retraction", "--")):
        t = res.branch(b)
        if len(t["D"]) == 0:
            continue
        xs, ys = t[x], t[y]
        # break the line at jumps so they show as gaps, mark them with dots
        j = np.flatnonzero(t["jump"])
        xs = np.insert(xs.astype(float), j, np.nan)
        ys = np.insert(ys.astype(float), j, np.nan)
        ax.plot(xs, ys, ls, color=color, lw=1.4, label=f"{label} {b}" if label else b)
        if jumps and len(j):
            ax.plot(t[x][j], t[y][j], "o", color=color, ms=3)
            ax.plot(t[x][j - 1], t[y][j - 1], "o", color=color, ms=3, mfc="none")


def plot_curves(res, path, title: str = "") -> None:
    """F(D), Λc(D) and Λc(F) of one run, approach solid and retraction dashed, jumps as dots.

    A physical run (columns F_N and contact_length_m, D in ε from its scaling) is drawn in
    µN, µm and nm; a dimensionless one in the units of Eq. (7).
    """
    plt = _plt()
    t = res.table
    eps = (res.params or {}).get("eps_m")
    physical = "F_N" in t and "contact_length_m" in t and eps
    if physical:
        view = type(res)(table={**t, "D": t["D"] * eps * 1e9, "F": t["F_N"] * 1e6,
                                "contact_length": t["contact_length_m"] * 1e6}, grid=res.grid)
        labels = [("approach α (nm)", "force per cell f (µN)"), ("approach α (nm)", r"contact length $\lambda_c$ (µm)"),
                  ("force per cell f (µN)", r"contact length $\lambda_c$ (µm)")]
    else:
        view = res
        labels = [("D", "F"), ("D", r"$\Lambda_c$"), ("F", r"$\Lambda_c$")]
    fig, axs = plt.subplots(1, 3, figsize=(12, 3.6))
    _branches(axs[0], view, "D", "F", "k", "")
    _branches(axs[1], view, "D", "contact_length", "k", "")
    _branches(axs[2], view, "F", "contact_length", "k", "")
    for ax, (xl, yl) in zip(axs, labels):
        ax.set_xlabel(xl)
        ax.set_ylabel(yl)
        ax.grid(alpha=0.3)
    axs[0].legend(fontsize=8)
    if title:
        fig.suptitle(title)
    save(fig, path)


def plot_fig3(results: dict, path, d_values=(1.0, 3.0, 6.0, 14.0)) -> None:
    """Fig. 3: pressure maps P(X, Y) on approach, rows = groups, columns = D."""
    plt = _plt()
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
    plt = _plt()
    fig, axs = plt.subplots(1, 3, figsize=(13, 3.8))
    for g, res in results.items():
        c = COLORS.get(g, None)
        _branches(axs[0], res, "D", "contact_length", c, g)
        _branches(axs[1], res, "F", "contact_length", c, g)
        _branches(axs[2], res, "D", "F", c, g)
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
    plt = _plt()
    fig, ax = plt.subplots(figsize=(5.2, 3.8))
    for g, (p, v) in curves.items():
        ax.plot(np.asarray(p) / 1e3, v, "-", color=COLORS.get(g), label=f"group {g}")
    ax.set_xlabel("pressure $f/L^2$ (kPa)")
    ax.set_ylabel("$V_{OC}$ (V), Eq. (12)")
    ax.set_xscale("log")
    ax.grid(alpha=0.3, which="both")
    ax.legend()
    save(fig, path)


def plot_timeseries(data, path, title: str = "") -> None:
    """Device time series read back from a file (columns t, y, Q, I, V, V_oc, I_sc)."""
    plt = _plt()
    names = [("y", "y (m)"), ("Q", "Q (C)"), ("I", "I (A)"), ("V", "V (V)"), ("V_oc", "$V_{OC}$ (V)"),
             ("I_sc", "$I_{SC}$ (A)")]
    have = [(k, lab) for k, lab in names if k in data]
    fig, axs = plt.subplots(len(have), 1, figsize=(7, 1.6 * len(have)), sharex=True, squeeze=False)
    t = np.asarray(data["t"])
    for ax, (k, lab) in zip(axs[:, 0], have):
        ax.plot(t, np.asarray(data[k]), lw=0.8)
        ax.set_ylabel(lab)
        ax.grid(alpha=0.3)
    axs[-1, 0].set_xlabel("t (s)")
    if title:
        fig.suptitle(title)
    save(fig, path)


def plot_maps(res, path, title: str = "") -> None:
    """Saved pressure and gap maps of a contact result: one row per map, P (Eq. 8) and H side by side,
    on the cell's X, Y axes (for the pyramid in units of ε m/n, Eq. 7), equal aspect, colour bars with
    units (P in W/ε, H in ε)."""
    from tengsim.errors import TengsimError

    if not res.maps:
        raise TengsimError("the result holds no maps (run with --maps D1,D2,...)")
    if res.grid is None:
        raise TengsimError("the result has no grid, so its maps cannot be placed")
    plt = _plt()
    g = res.grid
    unit = r"$\varepsilon m/n$" if res.params.get("shape") == "Pyramid" else "dimensionless"  # Eq. 7
    ext = [g.x[0] - g.dx / 2, g.x[-1] + g.dx / 2, g.y[0] - g.dy / 2, g.y[-1] + g.dy / 2]
    n = len(res.maps)
    fig, axs = plt.subplots(n, 2, figsize=(9.0, 3.6 * n), squeeze=False, constrained_layout=True)
    for i, m in enumerate(res.maps):
        P, H = np.asarray(m["P"], float), np.asarray(m["H"], float)
        lim = max(1e-12, float(np.nanpercentile(np.abs(P), 99.5)))
        panels = [(P, "RdBu_r", -lim, lim, r"pressure $P$ ($W_{ad}/\varepsilon$, Eq. 7)"),
                  (H, "viridis", float(np.nanmin(H)), float(np.nanmax(H)), r"gap $H$ ($\varepsilon$)")]
        for ax, (field, cmap, lo, hi, label) in zip(axs[i], panels):
            im = ax.imshow(field.T, origin="lower", extent=ext, cmap=cmap, vmin=lo, vmax=hi, interpolation="nearest")
            ax.set_aspect("equal")
            ax.set_xlabel(f"$X$ ({unit})")
            ax.set_ylabel(f"$Y$ ({unit})")
            ax.set_title(f"{m['branch']}, D = {m['D']:g}", fontsize=9)
            fig.colorbar(im, ax=ax, shrink=0.85).set_label(label)
    if title:
        fig.suptitle(title)
    save(fig, path)


def plot_sweep(data, path, title: str = "") -> None:
    """Load-resistance sweep read back from a file (columns R, energy_per_cycle, average_power): mean
    power and energy per cycle against R on a log axis, the best load marked."""
    plt = _plt()
    R = np.asarray(data["R"], float)
    p = np.asarray(data["average_power"], float)
    e = np.asarray(data["energy_per_cycle"], float)
    order = np.argsort(R)
    R, p, e = R[order], p[order], e[order]
    k = int(np.nanargmax(p)) if np.isfinite(p).any() else None
    fig, axs = plt.subplots(1, 2, figsize=(10, 3.8), constrained_layout=True)
    for ax, y, label in ((axs[0], p, "mean power (W)"), (axs[1], e, "energy per cycle (J)")):
        ax.plot(R, y, "o-", ms=3)
        ax.set_xscale("log")
        if np.all(y[np.isfinite(y)] > 0):
            ax.set_yscale("log")
        ax.set_xlabel(r"load $R$ ($\Omega$)")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3, which="both")
        if k is not None:
            ax.axvline(R[k], color="k", ls=":", lw=1)
            ax.plot(R[k], y[k], "*", color="tab:red", ms=10,
                    label=f"best load {R[k]:.3g} Ω: {p[k]:.3g} W, {e[k]:.3g} J/cycle")
    if k is not None:
        axs[0].legend(fontsize=8)
    if title:
        fig.suptitle(title)
    save(fig, path)


_OBS_TITLES = {"pull_off_F": "pull-off F", "jump_in_D": "jump-in D", "jump_out_D": "jump-out D",
               "transition_D": "transition D"}


def plot_resolution(res, path, title: str = "") -> None:
    """Convergence of an automatically refined run (``resolve = "auto"``, tengsim.resolve): one panel per
    observable against the grid spacing dx (log axis, finest right), each grid's status marked, the
    Richardson-extrapolated value as a line and its error estimate (± |error|) as a band."""
    from tengsim.errors import TengsimError

    tab = res.params.get("resolution")
    if not isinstance(tab, dict) or not tab.get("dx"):
        raise TengsimError("the result holds no resolution table (run with --resolve auto)")
    rich = res.params.get("richardson") or {}
    fixed = ("dx", "nx", "ny", "seconds", "convolutions", "status")

    def num(v):
        return np.array([np.nan if x is None else x for x in v], dtype=float)

    names = [k for k in tab if k not in fixed and np.isfinite(num(tab[k])).any()]
    if not names:
        raise TengsimError("the resolution table has no finite observable")
    plt = _plt()
    dx = num(tab["dx"])
    st = [str(s) for s in tab.get("status", ["?"] * len(dx))]
    ncol = min(len(names), 4)  # at most four panels a row: a page's width
    nrow = -(-len(names) // ncol)
    fig, axs = plt.subplots(nrow, ncol, figsize=(3.6 * ncol, 3.2 * nrow), squeeze=False, constrained_layout=True)
    for ax in axs.flat[len(names):]:
        ax.set_visible(False)
    for ax, n in zip(axs.flat, names):
        f = num(tab[n])
        ax.plot(dx, f, "-", color="tab:blue", lw=1)
        for ok in (True, False):
            m = np.array([(s == "ok") == ok for s in st])
            if m.any():
                ax.plot(dx[m], f[m], "o" if ok else "x", color="tab:blue" if ok else "tab:red",
                        label="status ok" if ok else "status not ok")
        r = rich.get(n) or {}
        ext, err = r.get("extrapolated"), r.get("error")
        if ext is not None and err is not None and np.isfinite(ext) and np.isfinite(err):
            ax.axhline(ext, color="k", lw=0.8, ls="--", label=f"Richardson {ext:.5g} (p = {r.get('order', np.nan):.2g})")
            ax.axhspan(ext - abs(err), ext + abs(err), color="0.8", alpha=0.6, lw=0)
        ax.set_xscale("log")
        ax.set_xticks(dx, [f"{d:.3g}" for d in dx], fontsize=7, rotation=45)
        ax.minorticks_off()
        ax.invert_xaxis()
        ax.set_xlabel("dx")
        ax.set_title(_OBS_TITLES.get(n, n) if not n.startswith("A_S_at_") else
                     f"A/S at {n[len('A_S_at_'):-2].replace('p', '.')} Pa", fontsize=9)
        ax.legend(fontsize=7)
    fig.suptitle(title + (f"  [{res.params.get('resolve_status', '?')}, tol {res.params.get('resolve_tol', '?')}]"))
    save(fig, path)
