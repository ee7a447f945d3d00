"""Contact figures: the approach–retraction curves, maps, sweeps and time series, and the one figure writer.

Agg backend.  The paper's Figs. 3–5 are in :mod:`tengsim.cases.paper.figures`."""
from __future__ import annotations

import numpy as np

from tengsim.io import save_figure


def pyplot():
    """matplotlib.pyplot on the Agg backend (files only): the one import of pyplot in tengsim."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    return plt


def save(fig, path) -> None:
    """Save a figure atomically (format from the suffix; 150 dpi, tight box) and close it."""
    try:
        save_figure(fig, path, dpi=150, bbox_inches="tight")
    finally:
        pyplot().close(fig)


def draw_branches(ax, res, x, y, color, label, jumps=True):
    """Approach solid and retraction dashed, broken at jumps (dots: filled after, open before)."""
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


def run_title(params: dict, keys=None) -> str:
    """The shape and its parameters, then the materials, of a run (its saved params): for a physical run
    'pyramid: pitch 10 µm, base 5 µm, height 3.5 µm; E* = 1 MPa, W = 50 mJ/m², ε = 100 nm, μ = 0.8'; for a
    dimensionless one the shape's numbers as given (``keys``: the shape's own keys, to leave out the run's)."""
    from tengsim.units import format_si

    p = params or {}
    cfg = p.get("config") if isinstance(p.get("config"), dict) else {}
    shape = str(cfg.get("shape") or p.get("shape") or "").lower()
    mu = p.get("tabor")
    if "eps_m" not in p:  # dimensionless: the shape's own numbers as given
        own = ", ".join(f"{k} {v}" for k, v in cfg.items() if k not in ("shape", "tabor") and not isinstance(v, dict)
                        and (keys is None or k in keys))
        return f"{shape}{': ' + own if own else ''}" + (f"; μ = {mu:.3g}" if isinstance(mu, (int, float)) else "")
    sizes = [f"{k[:-2].replace('_', ' ')} {format_si(v, 'm')}" for k, v in p.items()
             if k.endswith("_m") and k not in ("eps_m", "lateral_m") and isinstance(v, (int, float))]
    mats = [f"E* = {format_si(p['E_star_Pa'], 'Pa')}", f"W = {1e3 * p['W_J_m2']:.3g} mJ/m²",
            f"ε = {format_si(p['eps_m'], 'm')}"] + ([f"μ = {mu:.3g}"] if isinstance(mu, (int, float)) else [])
    return f"{shape}: {', '.join(sizes)}; {', '.join(mats)}"


def _scaled(values, unit):
    """(values in an engineering-prefixed unit, that unit): µm, kPa, µN, ... chosen from the largest value."""
    from tengsim.units import si_prefix

    v = np.asarray(values, dtype=float)
    big = float(np.nanmax(np.abs(v))) if v.size and np.isfinite(v).any() else 0.0
    f, u = si_prefix(big, unit)
    return v / f, u


def plot_curves(res, path, title: str = "", keys=None) -> None:
    """Force per cell and contact length against the approach, and contact length against the force
    (or the nominal pressure), of one run: approach solid, retraction dashed, jumps as dots.

    A physical run (columns F_N, contact_length_m, and pressure_Pa with a cell area) is drawn in physical
    units: lengths with an engineering prefix (nm/µm), the force per cell in µN with the nominal pressure
    (kPa) on a right-hand axis, the last panel against the pressure; titled with its shape, sizes and
    materials.  A dimensionless one in the units of Eq. (7), titled with its shape's numbers.
    """
    plt = pyplot()
    t = res.table
    params = res.params or {}
    eps = params.get("eps_m")
    physical = "F_N" in t and "contact_length_m" in t and eps
    pressure = physical and "pressure_Pa" in t
    if physical:
        D, du = _scaled(np.asarray(t["D"], float) * eps, "m")
        L, lu = np.asarray(t["contact_length_m"], float) * 1e6, "µm"  # the structures' own scale
        fN = np.asarray(t["F_N"], float) * 1e6  # force per cell in µN (left axis of the first panel)
        view = type(res)(table={**t, "D": D, "F": fN, "contact_length": L}, grid=res.grid)
        dl, fl, ll = f"rigid approach α ({du})", "force per cell f (µN)", f"contact length λc ({lu})"
        if pressure:
            pk, pu = _scaled(t["pressure_Pa"], "Pa")
            pl = f"nominal pressure p ({pu})"
            pview = type(res)(table={**t, "D": D, "F": pk, "contact_length": L}, grid=res.grid)
    else:
        view = res
        unit = params.get("lateral_unit") or "ℓ"
        dl, fl, ll = "rigid approach D (ε)", "force per cell F (3π W ℓ²/ε)", f"contact length Λc ({unit})"
    labels = [(dl, fl), (dl, ll), (pl if pressure else fl, ll)]
    fig, axs = plt.subplots(1, 3, figsize=(12.5, 3.9), constrained_layout=True)
    draw_branches(axs[0], view, "D", "F", "k", "")
    draw_branches(axs[1], view, "D", "contact_length", "k", "")
    draw_branches(axs[2], pview if pressure else view, "F", "contact_length", "k", "")
    for ax, (xl, yl) in zip(axs, labels):
        ax.set_xlabel(xl)
        ax.set_ylabel(yl)
        ax.grid(alpha=0.3)
    axs[0].legend(fontsize=8)
    if pressure:  # the same curve read as a nominal pressure: a right-hand axis (p = f / cell area)
        per = float(np.nanmax(np.abs(pk)) / np.nanmax(np.abs(fN))) if np.nanmax(np.abs(fN)) > 0 else 1.0
        right = axs[0].twinx()
        lo, hi = axs[0].get_ylim()
        right.set_ylim(lo * per, hi * per)
        right.set_ylabel(pl)
    head = run_title(params, keys)
    fig.suptitle(head + (f"\n{title}" if title else ""), fontsize=10)
    save(fig, path)


_SERIES = (("y", "displacement y", "m"), ("Q", "charge Q", "C"), ("I", "current I", "A"), ("V", "voltage V", "V"),
           ("power", "power into the load", "W"), ("V_oc", "open-circuit voltage $V_{OC}$", "V"),
           ("I_sc", "short-circuit current $I_{SC}$", "A"))


def plot_timeseries(data, path, title: str = "", period: float | None = None) -> None:
    """Device time series read back from a file (columns t, y, Q, I, V, V_oc, I_sc, power): one panel per
    series in engineering-prefixed units (mm, nC, µA, V, µW), no axis offsets; the power panel from
    V·I where the file has no power column.  With the waveform's ``period`` (s), each panel is scaled to
    the settled cycles and the first period (the start transient of Q(0) = 0) is shaded, clipped."""
    plt = pyplot()
    data = {k: np.asarray(data[k]) for k in ("t", *(k for k, _, _ in _SERIES)) if k in data}  # a Dataset too
    if "power" not in data and "V" in data and "I" in data:
        data["power"] = np.asarray(data["V"], float) * np.asarray(data["I"], float)
    have = [(k, word, u) for k, word, u in _SERIES if k in data]
    fig, axs = plt.subplots(len(have), 1, figsize=(7, 1.7 * len(have)), sharex=True, squeeze=False,
                            constrained_layout=True)
    from tengsim.units import si_prefix

    t_s = np.asarray(data["t"], float)
    t, tu = _scaled(t_s, "s")
    settled = t_s >= t_s[0] + period - 1e-12 if period and t_s[-1] - t_s[0] >= 2 * period - 1e-12 else None
    clipped = False
    for ax, (k, word, unit) in zip(axs[:, 0], have):
        raw = np.asarray(data[k], float)
        shown = raw if settled is None else raw[settled]  # the prefix suits what the panel shows
        f, u = si_prefix(float(np.nanmax(np.abs(shown))) if shown.size else 0.0, unit)
        y = raw / f
        ax.plot(t, y, lw=0.8)
        if settled is not None and np.ptp(y[settled]) > 0:
            lo, hi = float(np.min(y[settled])), float(np.max(y[settled]))
            pad = 0.08 * (hi - lo)
            if np.min(y) < lo - pad or np.max(y) > hi + pad:  # the start spike would hide the cycles
                ax.set_ylim(lo - pad, hi + pad)
                ax.axvspan(t[0], t[np.argmax(settled)], color="0.9", zorder=0)
                clipped = True
        ax.set_ylabel(f"{word}\n({u})", fontsize=8)
        ax.ticklabel_format(axis="y", useOffset=False, style="plain")
        ax.grid(alpha=0.3)
    axs[-1, 0].set_xlabel(f"time t ({tu})")
    note = "grey: first period, the start transient of Q(0) = 0, clipped" if clipped else ""
    if title or note:
        fig.suptitle("\n".join(x for x in (title, note) if x), fontsize=10)
    save(fig, path)


def _map_pressure(res, m) -> float | None:
    """The nominal pressure (Pa) of the row a map was saved at (same branch, same D), or None."""
    t = res.table
    if "pressure_Pa" not in t:
        return None
    br = np.asarray(t["branch"]).astype(str)
    D = np.asarray(t["D"], float)
    rows = np.flatnonzero((br == str(m["branch"])) & np.isclose(D, float(m["D"]), rtol=1e-9, atol=1e-9))
    return float(np.asarray(t["pressure_Pa"], float)[rows[0]]) if rows.size else None


def plot_maps(res, path, title: str = "", keys=None) -> None:
    """Saved pressure and gap maps of a contact result: one row per map, pressure and gap side by side,
    equal aspect, colour bars with units.  A physical run: x, y in µm, the contact pressure in kPa (or
    MPa), the gap in nm, each map titled with its nominal pressure; a dimensionless one in the units of
    Eq. (7) (P in W/ε, H in ε)."""
    from tengsim.errors import TengsimError
    from tengsim.units import format_si

    if not res.maps:
        raise TengsimError("the result holds no maps (run with --maps D1,D2,...)")
    if res.grid is None:
        raise TengsimError("the result has no grid, so its maps cannot be placed")
    plt = pyplot()
    g, p = res.grid, res.params or {}
    eps, lat = p.get("eps_m"), p.get("lateral_m")
    physical = bool(eps and lat and p.get("W_J_m2"))
    ext = np.array([g.x[0] - g.dx / 2, g.x[-1] + g.dx / 2, g.y[0] - g.dy / 2, g.y[-1] + g.dy / 2])
    if physical:
        ext, xu = _scaled(ext * lat, "m")
        xl, yl = f"x ({xu})", f"y ({xu})"
    else:
        unit = p.get("lateral_unit") or "ℓ"
        xl, yl = f"X ({unit})", f"Y ({unit})"
    n = len(res.maps)
    fig, axs = plt.subplots(n, 2, figsize=(9.0, 3.6 * n), squeeze=False, constrained_layout=True)
    for i, m in enumerate(res.maps):
        P, H = np.asarray(m["P"], float), np.asarray(m["H"], float)
        if physical:
            P, pu = _scaled(P * p["W_J_m2"] / eps, "Pa")
            H, hu = _scaled(H * eps, "m")
            plab, hlab = f"contact pressure ({pu}; compressive > 0)", f"gap ({hu})"
            pn = _map_pressure(res, m)
            at = (f"p = {format_si(pn, 'Pa')}" if pn is not None else "") + \
                f" (α = {format_si(float(m['D']) * eps, 'm')})"
        else:
            plab, hlab = r"pressure $P$ ($W_{ad}/\varepsilon$, Eq. 7)", r"gap $H$ ($\varepsilon$)"
            at = f"D = {float(m['D']):g} ε"
        lim = max(1e-12, float(np.nanpercentile(np.abs(P), 99.5)))
        panels = [(P, "RdBu_r", -lim, lim, plab), (H, "viridis", float(np.nanmin(H)), float(np.nanmax(H)), hlab)]
        for ax, (field, cmap, lo, hi, label) in zip(axs[i], panels):
            im = ax.imshow(field.T, origin="lower", extent=ext, cmap=cmap, vmin=lo, vmax=hi, interpolation="nearest")
            ax.set_aspect("equal")
            ax.set_xlabel(xl)
            ax.set_ylabel(yl)
            ax.set_title(f"{m['branch']}, {at.strip()}", fontsize=9)
            fig.colorbar(im, ax=ax, shrink=0.85).set_label(label)
    fig.suptitle(run_title(p, keys) + (f"\n{title}" if title else ""), fontsize=10)
    save(fig, path)


def plot_sweep(data, path, title: str = "") -> None:
    """Load-resistance sweep read back from a file (columns R, energy_per_cycle, average_power): mean
    power (and the peak power, if the file has it) and energy per cycle against R on a log axis (µW, µJ:
    engineering prefixes), the best load marked."""
    from tengsim.units import format_si, si_prefix

    plt = pyplot()
    R = np.asarray(data["R"], float)
    p = np.asarray(data["average_power"], float)
    e = np.asarray(data["energy_per_cycle"], float)
    order = np.argsort(R)
    R, p, e = R[order], p[order], e[order]
    k = int(np.nanargmax(p)) if np.isfinite(p).any() else None
    fig, axs = plt.subplots(1, 2, figsize=(10, 3.8), constrained_layout=True)
    p_raw, e_raw = p, e
    (p, pu), (e, eu) = _scaled(p, "W"), _scaled(e, "J")
    for ax, y, label in ((axs[0], p, f"power into the load ({pu})"), (axs[1], e, f"energy per cycle ({eu})")):
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
                    label=f"best load {R[k]:.3g} Ω: {format_si(p_raw[k], 'W')}, {format_si(e_raw[k], 'J')}/cycle")
        if ax is axs[0] and "peak_power" in data:  # the peak beside the mean, in the same unit
            fp = si_prefix(float(np.nanmax(np.abs(p_raw))), "W")[0]
            ax.plot(R, np.asarray(data["peak_power"], float)[order] / fp, "s--", ms=3, color="tab:gray",
                    label="peak power (solid: mean)")
    if k is not None:
        axs[0].legend(fontsize=8)
    if title:
        fig.suptitle(title)
    save(fig, path)


_OBS_TITLES = {"pull_off_F": "pull-off F", "jump_in_D": "jump-in D", "jump_out_D": "jump-out D",
               "transition_D": "transition D"}


def plot_resolution(res, path, title: str = "") -> None:
    """Convergence of an automatically refined run (``resolve = "auto"``, tengsim.run.resolve): one panel per
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
    plt = pyplot()
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
