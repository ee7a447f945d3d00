"""Design maps of a study directory: lines over one axis, heat maps over two, V_OC(P) coloured by an axis."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from tengsim.errors import TengsimError
from tengsim.io import read_dataset

MAP_VARS = ("S_V_per_kPa", "linear_range_Pa", "P_sat_Pa", "pull_off_Pa", "area_fraction_0", "V_sat")
_LABEL = {"S_V_per_kPa": "sensitivity dV_OC/dP, lowest region (V/kPa)", "linear_range_Pa": "linear range (kPa)",
          "P_sat_Pa": "saturation pressure (kPa)", "pull_off_F": "pull-off force per cell (F of Eq. 10)",
          "pull_off_Pa": "pull-off pressure (kPa; tensile < 0)",
          "area_fraction_0": "charged area A/S at zero load", "V_sat": "saturation voltage V_sat (V)"}
_KPA = ("linear_range_Pa", "P_sat_Pa", "pull_off_Pa")
STATUS_MARKS = {"under_resolved": ("o", "tab:orange"), "out_of_law_range": ("D", "tab:purple"),
                "not_converged": ("^", "tab:red"), "failed": ("X", "k"), "pending": ("s", "0.5")}
"""Marker and colour of a point whose status is not ok, in every design map (ok points are unmarked)."""
LINESTYLES = ("-", "--", ":", "-.")
MARKERS = ("o", "s", "^", "D", "v", "P")


def axis_words(name: str) -> str:
    """A study axis in words: 'contact.pitch' → 'pitch', 'contact.E_star' → 'E*', 'var.aspect' → 'aspect'."""
    word = name.split(".", 1)[-1]
    return "E*" if word == "E_star" else word.replace("_", " ")


def axis_scale(values):
    """(label unit, tick texts, numbers or None) of an axis's values: quantities of one dimension are shown in
    one engineering-prefixed unit ('µm': '1.2', '2'); anything else as given."""
    from tengsim.units import parse_quantity, quantity_dim, si_prefix, si_unit

    texts = [str(v) for v in values]
    try:
        dims = {quantity_dim(v) for v in values}
    except (TengsimError, TypeError, ValueError, AttributeError):
        return "", texts, None
    if len(dims) != 1 or None in dims:
        return "", texts, None
    (dim,) = dims
    si = np.array([parse_quantity(v) for v in values], float)
    f, unit = si_prefix(float(np.max(np.abs(si))), si_unit(dim))
    return unit, [f"{x / f:.4g}" for x in si], si / f


def axis_label(ds, dim) -> str:
    """An axis label in words with its unit ('pitch (µm)')."""
    from tengsim.study.dataset import key_of

    unit = axis_scale(ds[dim].values)[0]
    return axis_words(key_of(ds, dim)) + (f" ({unit})" if unit else "")


def _ticks(ds, dim):
    return axis_scale(ds[dim].values)[1]


def _mark_status(ax, status, xx, yy, seen):
    """Mark the points whose status is not ok (``status`` an array over the map, xx/yy their positions)."""
    for word, (m, c) in STATUS_MARKS.items():
        hit = status == word
        if hit.any():
            ax.plot(xx[hit], yy[hit], m, mfc="none", mec=c, ms=11, mew=1.6, label=word.replace("_", " "))
            seen.add(word)


def _axis_values(ds, dim):
    from tengsim.study.spec import numeric

    v = ds[dim].values
    x = np.array([numeric(a) for a in v], float)
    return (x, True) if np.all(np.isfinite(x)) else (np.arange(len(v), dtype=float), False)


def _data(ds, var):
    d = ds[var].values.astype(float)
    return d / 1e3 if var in _KPA else d


def plot_study(root, out, vars=MAP_VARS) -> list:
    """Draw the design maps of study directory ``root`` to ``out`` (and ``<out stem>_voc<suffix>`` for the
    V_OC(P) curves).  Returns the files written."""
    from tengsim.plots import pyplot

    plt = pyplot()

    root, out = Path(root), Path(out)
    from tengsim.study.layout import StudyDir

    nc = StudyDir(root).dataset_nc
    if not nc.exists():
        raise TengsimError(f"{root} holds no study.nc (run tengsim sweep first)")
    from tengsim.study.dataset import key_of

    ds = read_dataset(nc)
    dims = [d for d in ds["pull_off_F"].dims]
    have = lambda v: v in ds and np.isfinite(ds[v].values.astype(float)).any()  # noqa: E731
    vars = [("pull_off_F" if v == "pull_off_Pa" and not have(v) else v) for v in vars]  # dimensionless: F
    vars = [v for v in vars if have(v)] or ["pull_off_F"]
    n = len(vars)
    cols = min(3, n)
    rows = math.ceil(n / cols)
    fig, axs = plt.subplots(rows, cols, figsize=(4.2 * cols, 3.4 * rows), squeeze=False)
    if dims == ["point"]:  # sampled: scatter over the first two parameters
        params = [c for c in ds.coords if ds[c].dims == ("point",) and c != "point"]
        if not params:
            raise TengsimError(f"{nc}: no axis to plot against")
        px, xnum = _axis_values(ds, params[0])
        py = _axis_values(ds, params[1])[0] if len(params) > 1 else np.zeros_like(px)
        for ax, v in zip(axs.flat, vars):
            sc = ax.scatter(px, py, c=_data(ds, v), cmap="viridis", s=30)
            fig.colorbar(sc, ax=ax, label=_LABEL.get(v, v))
            ax.set_xlabel(axis_words(key_of(ds, params[0])))
            if len(params) > 1:
                ax.set_ylabel(axis_words(key_of(ds, params[1])))
            if xnum and np.all(px > 0) and px.max() / px.min() > 20:
                ax.set_xscale("log")
    else:
        sel = {d: 0 for d in dims[2:]}
        sub = ds.isel(sel) if sel else ds
        xd = dims[0]
        x, xnum = _axis_values(sub, xd)
        status = sub["status"].values.astype(str) if "status" in sub else None
        seen = set()
        for ax, v in zip(axs.flat, vars):
            if len(dims) == 1:
                ax.plot(x, _data(sub, v), "o-")
                ax.set_ylabel(_LABEL.get(v, v))
                if status is not None:
                    _mark_status(ax, status, x, _data(sub, v), seen)
            else:
                yd = dims[1]
                y, ynum = _axis_values(sub, yd)
                z = _data(sub[[v]].transpose(yd, xd), v)
                m = ax.pcolormesh(np.arange(len(x)), np.arange(len(y)), z, shading="nearest", cmap="viridis")
                fig.colorbar(m, ax=ax, label=_LABEL.get(v, v))
                ax.set_yticks(np.arange(len(y)), _ticks(sub, yd))
                ax.set_xticks(np.arange(len(x)), _ticks(sub, xd), rotation=45)
                ax.set_ylabel(axis_label(sub, yd))
                if "adhesive_full_contact" in sub:
                    full = sub["adhesive_full_contact"].transpose(yd, xd).values
                    yy, xx = np.nonzero(full == 1)
                    ax.plot(xx, yy, "wx", ms=6, label="full contact at zero load")
                    if len(xx):
                        seen.add("full")
                if status is not None:
                    st = sub["status"].transpose(yd, xd).values.astype(str)
                    yy, xx = np.indices(st.shape)
                    _mark_status(ax, st.ravel(), xx.ravel(), yy.ravel(), seen)
            ax.set_xlabel(axis_label(sub, xd))
            if len(dims) == 1 and xnum and np.all(x > 0) and x.max() / x.min() > 20:
                ax.set_xscale("log")
        if sel:
            fig.suptitle(", ".join(f"{axis_words(key_of(ds, d))} = {_ticks(ds, d)[0]} {axis_scale(ds[d].values)[0]}".rstrip()
                                   for d in sel), fontsize=9)
        if seen:  # one legend for the status marks of every map
            from matplotlib.lines import Line2D

            marks = sorted(seen - {"full"})
            handles = [Line2D([], [], ls="", marker=STATUS_MARKS[w][0], mfc="none", mec=STATUS_MARKS[w][1], ms=9,
                              mew=1.6) for w in marks]
            labels = [f"status {w.replace('_', ' ')}" for w in marks]
            if "full" in seen:
                handles.append(Line2D([], [], ls="", marker="x", color="0.3", ms=7))
                labels.append("full contact at zero load")
            fig.legend(handles, labels, loc="lower center", ncol=len(labels), fontsize=8, frameon=False)
    for ax in list(axs.flat)[n:]:
        ax.set_visible(False)
    fig.tight_layout(rect=(0, 0.04, 1, 1))
    from tengsim.plots import save

    written = []
    save(fig, out)
    written.append(out)
    if np.isfinite(ds["V_OC"].values).any():
        voc = out.with_name(out.stem + "_voc" + out.suffix)
        _plot_voc(plt, ds, dims, voc)
        written.append(voc)
    return written


def _plot_voc(plt, ds, dims, path):
    """V_OC(P) of every point: colour by the first axis (categorical: one colour per shape), line style by the
    second, marker by the third; a point whose status is not ok has its status marker at the curve's end."""
    from matplotlib.lines import Line2D

    from tengsim.plots import save
    from tengsim.study.dataset import key_of

    pdim = "applied_pressure" if "applied_pressure" in ds.dims else "pressure"  # study.nc before CF: 'pressure'
    P = ds[pdim].values / 1e3
    fig, ax = plt.subplots(figsize=(7.5, 4.6))
    axes = [d for d in dims if d != "point"]
    order = sorted(axes, key=lambda d: key_of(ds, d) != "contact.shape")  # the shape, if an axis, gets the colours
    styles = dict(zip(order, ("color", "ls", "marker")))
    colours = plt.get_cmap("tab10").colors
    pick = {"color": colours, "ls": LINESTYLES, "marker": MARKERS}
    seen = set()
    flat = ds["V_OC"].stack(_p=dims) if len(dims) > 1 else ds["V_OC"].rename({dims[0]: "_p"})
    for k in range(flat.sizes["_p"]):
        row = flat.isel(_p=k)
        kw = {"color": "k", "ls": "-", "marker": None}
        for d, what in styles.items():
            vals = list(ds[d].values)
            kw[what] = pick[what][vals.index(row[d].values) % len(pick[what])]
        y = row.transpose(..., pdim).values
        ax.plot(P, y, lw=1.2, markevery=max(1, len(P) // 8), ms=4, **kw)
        st = str(ds["status"].stack(_p=dims).isel(_p=k).values) if len(dims) > 1 and "status" in ds else (
            str(ds["status"].values[k]) if "status" in ds else "ok")
        if st in STATUS_MARKS and np.isfinite(y).any():
            i = int(np.flatnonzero(np.isfinite(y))[-1])
            m, c = STATUS_MARKS[st]
            ax.plot(P[i], y[i], m, mfc="none", mec=c, ms=10, mew=1.6)
            seen.add(st)
    handles, labels = [], []
    for d, what in styles.items():
        unit, ticks, _ = axis_scale(ds[d].values)
        for j, t in enumerate(ticks):
            kw = {"color": "k", "ls": "-", "marker": None, what: pick[what][j % len(pick[what])]}
            handles.append(Line2D([], [], lw=1.2, **kw))
            labels.append(f"{axis_words(key_of(ds, d))} {t}{' ' + unit if unit else ''}")
    for w in sorted(seen):
        handles.append(Line2D([], [], ls="", marker=STATUS_MARKS[w][0], mfc="none", mec=STATUS_MARKS[w][1], ms=9))
        labels.append(f"status {w.replace('_', ' ')}")
    ax.legend(handles, labels, fontsize=8, loc="center left", bbox_to_anchor=(1.01, 0.5), frameon=False)
    ax.set_xlabel("nominal pressure (kPa)")
    ax.set_ylabel("open-circuit voltage V_OC (V), Eq. 12")
    ax.grid(alpha=0.3)
    fig.tight_layout()
    save(fig, path)
