"""Design maps of a study directory: lines over one axis, heat maps over two, V_OC(P) coloured by an axis."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from tengsim.errors import TengsimError
from tengsim.io import read_dataset

MAP_VARS = ("S_V_per_kPa", "linear_range_Pa", "P_sat_Pa", "pull_off_F", "area_fraction_0", "V_sat")
_LABEL = {"S_V_per_kPa": "sensitivity S (V/kPa)", "linear_range_Pa": "linear range (kPa)",
          "P_sat_Pa": "P at 90 % of V_sat (kPa)", "pull_off_F": "pull-off F (Eq. 10)",
          "area_fraction_0": "A/S at zero load", "V_sat": "V_sat (V)"}
_KPA = ("linear_range_Pa", "P_sat_Pa")


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
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    root, out = Path(root), Path(out)
    from tengsim.study.layout import StudyDir

    nc = StudyDir(root).dataset_nc
    if not nc.exists():
        raise TengsimError(f"{root} holds no study.nc (run tengsim sweep first)")
    from tengsim.study.dataset import key_of

    ds = read_dataset(nc)
    dims = [d for d in ds["pull_off_F"].dims]
    vars = [v for v in vars if v in ds and np.isfinite(ds[v].values.astype(float)).any()] or ["pull_off_F"]
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
            ax.set_xlabel(key_of(ds, params[0]))
            if len(params) > 1:
                ax.set_ylabel(key_of(ds, params[1]))
            if xnum and np.all(px > 0) and px.max() / px.min() > 20:
                ax.set_xscale("log")
    else:
        sel = {d: 0 for d in dims[2:]}
        sub = ds.isel(sel) if sel else ds
        xd = dims[0]
        x, xnum = _axis_values(sub, xd)
        for ax, v in zip(axs.flat, vars):
            if len(dims) == 1:
                ax.plot(x, _data(sub, v), "o-")
                ax.set_ylabel(_LABEL.get(v, v))
            else:
                yd = dims[1]
                y, ynum = _axis_values(sub, yd)
                z = _data(sub[[v]].transpose(yd, xd), v)
                m = ax.pcolormesh(np.arange(len(x)), np.arange(len(y)), z, shading="nearest", cmap="viridis")
                fig.colorbar(m, ax=ax, label=_LABEL.get(v, v))
                ax.set_yticks(np.arange(len(y)), [str(a) for a in sub[yd].values])
                ax.set_xticks(np.arange(len(x)), [str(a) for a in sub[xd].values], rotation=45)
                ax.set_ylabel(key_of(ds, yd))
                if "adhesive_full_contact" in sub:
                    full = sub["adhesive_full_contact"].transpose(yd, xd).values
                    yy, xx = np.nonzero(full == 1)
                    ax.plot(xx, yy, "wx", ms=6, label="full contact at zero load")
            ax.set_xlabel(key_of(ds, xd))
            if len(dims) == 1 and xnum and np.all(x > 0) and x.max() / x.min() > 20:
                ax.set_xscale("log")
        if sel:
            fig.suptitle(", ".join(f"{key_of(ds, d)} = {ds[d].values[0]}" for d in sel), fontsize=9)
    for ax in list(axs.flat)[n:]:
        ax.set_visible(False)
    fig.tight_layout()
    from tengsim.plots import save

    written = []
    save(fig, out)
    written.append(out)
    if np.isfinite(ds["V_OC"].values).any():
        voc = out.with_name(out.stem + "_voc" + out.suffix)
        fig, ax = plt.subplots(figsize=(5.5, 4))
        by = dims[0]
        flat = ds["V_OC"].stack(_p=[d for d in dims]) if len(dims) > 1 else ds["V_OC"].rename({dims[0]: "_p"})
        cval, cnum = _axis_values(ds, by) if by != "point" else (np.arange(ds.sizes["point"]), True)
        cmap = plt.get_cmap("viridis")
        pdim = "applied_pressure" if "applied_pressure" in ds.dims else "pressure"  # study.nc before CF: 'pressure'
        P = ds[pdim].values / 1e3
        for k in range(flat.sizes["_p"]):
            row = flat.isel(_p=k)
            idx = list(ds[by].values).index(row[by].values) if by != "point" else k
            c = cmap(idx / max(1, len(cval) - 1))
            ax.plot(P, row.transpose(..., pdim).values, color=c, lw=1)
        sm = plt.cm.ScalarMappable(cmap=cmap, norm=plt.Normalize(0, max(1, len(cval) - 1)))
        cb = fig.colorbar(sm, ax=ax, label=key_of(ds, by))
        cb.set_ticks(np.arange(len(cval)), labels=[str(a) for a in ds[by].values]) if by != "point" else None
        ax.set_xlabel("pressure (kPa)")
        ax.set_ylabel("V_OC (V), Eq. (12)")
        fig.tight_layout()
        save(fig, voc)
        written.append(voc)
    return written
