"""Design maps and ranked tables of examples/design/question.toml (docs/design.md, "The design question").

    python -m tengsim.cli.main sweep examples/design/question.toml --out question --workers 2
    python docs/data/design/question.py question docs/data/design
    python docs/data/design/question.py question_periodic docs/data/design question_periodic   # the array study

Writes question_maps.png, question_voc.png, question.csv (a copy of study.csv) and question_tables.md.
"""
import math
import shutil
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import xarray as xr  # noqa: E402

DIMS = ("contact.shape", "contact.pitch", "var.aspect", "contact.E_star")


def _at(v, label):
    """V_OC_at at a named pressure: study.nc labels them with the auxiliary coordinate pressure_label (CF);
    files from before it have a string coordinate pressure_named."""
    if "pressure_label" in v.coords:
        return v.swap_dims(pressure_named="pressure_label").sel(pressure_label=label)
    return v.sel(pressure_named=label)


def flat(ds):
    """One row per point (dict), in grid order."""
    rows = []
    st = ds.stack(_p=list(DIMS))
    for k in range(st.sizes["_p"]):
        r = st.isel(_p=k)
        rows.append({**{d: r[d].item() for d in DIMS},
                     **{v: r[v].item() for v in ("status", "run_status", "S_V_per_kPa", "linear_range_Pa", "V_sat",
                                                 "P_sat_Pa", "area_fraction_0", "adhesive_full_contact",
                                                 "pull_off_Pa", "seconds", "message")},
                     "V10": float(_at(r["V_OC_at"], "10kPa"))})
    return rows


def fmt(x, f="{:.3g}"):
    return "–" if x is None or (isinstance(x, float) and not math.isfinite(x)) else f.format(x)


def table(rows, key, n=10):
    out = ["| rank | pattern | pitch | aspect | E* | S 0–10 kPa (V/kPa) | linear range (kPa) | V_OC 10 kPa (V) | "
           "P_sat (kPa) | A/S at 0 | grid status |", "|---|---|---|---|---|---|---|---|---|---|---|"]
    for i, r in enumerate(rows[:n]):
        out.append(f"| {i + 1} | {r['contact.shape']} | {r['contact.pitch']} | {r['var.aspect']:g} | "
                   f"{r['contact.E_star']} | {fmt(r['S_V_per_kPa'])} | {fmt(r['linear_range_Pa'] / 1e3)} | "
                   f"{fmt(r['V10'])} | {fmt(r['P_sat_Pa'] / 1e3)} | {fmt(r['area_fraction_0'])} | "
                   f"{r['run_status'] or r['status']} |")
    return "\n".join(out)


def main(study_dir, out, name="question"):
    study_dir, out = Path(study_dir), Path(out)
    ds = xr.load_dataset(study_dir / "study.nc", engine="h5netcdf")
    # study.nc names its axes CF-style (contact_shape) with the [axes] key in 'tengsim_key': back to the keys
    ds = ds.rename({v: ds[v].attrs["tengsim_key"] for v in ds.variables if "tengsim_key" in ds[v].attrs})
    rows = flat(ds)
    # distinct computations only (the hemisphere ignores the aspect ratio)
    seen, uniq = set(), []
    for r in rows:
        key = (r["contact.shape"], r["contact.pitch"], r["contact.E_star"],
               None if r["contact.shape"] == "hemisphere" else r["var.aspect"])
        if key not in seen:
            seen.add(key)
            uniq.append(r)
    sensor = [r for r in uniq if r["status"] != "failed" and r["adhesive_full_contact"] != 1
              and math.isfinite(r["S_V_per_kPa"])]
    by_s = sorted(sensor, key=lambda r: -r["S_V_per_kPa"])
    lin = [dict(r, linear_range_Pa=min(r["linear_range_Pa"], 150e3)) for r in sensor
           if math.isfinite(r["linear_range_Pa"]) and r["S_V_per_kPa"] > 0]
    by_lin = sorted(lin, key=lambda r: (-r["linear_range_Pa"], -r["S_V_per_kPa"]))
    full = [r for r in uniq if r["adhesive_full_contact"] == 1]
    counts = {}
    for r in uniq:
        counts[r["run_status"] or r["status"]] = counts.get(r["run_status"] or r["status"], 0) + 1
    md = ["### Highest sensitivity below 10 kPa (not in full contact at zero load)", "", table(by_s, "S"), "",
          "### Widest linear range up to 150 kPa (S > 0, not in full contact at zero load; capped at 150 kPa)", "",
          table(by_lin, "lin"), "",
          f"### Full contact under adhesion alone ({len(full)} of {len(uniq)} distinct points)", "",
          "| pattern | points in full contact at zero load (pitch, aspect, E*) |", "|---|---|"]
    for shape in ds["contact.shape"].values:
        f = [r for r in full if r["contact.shape"] == shape]
        md.append(f"| {shape} | " + ("; ".join(f"{r['contact.pitch']}, {r['var.aspect']:g}, {r['contact.E_star']}"
                                              for r in f) or "none") + " |")
    md += ["", "Points by status: " + ", ".join(f"{k}: {v}" for k, v in sorted(counts.items())) + ".",
           "", "Failed points: " + ("; ".join(f"{r['contact.shape']} {r['contact.pitch']} {r['var.aspect']:g} "
                                              f"{r['contact.E_star']}: {r['message'][:120]}"
                                              for r in uniq if r["status"] == "failed") or "none") + ".",
           "", f"Compute: {sum(r['seconds'] for r in uniq if math.isfinite(r['seconds'])):.0f} s summed over points."]
    (out / f"{name}_tables.md").write_text("\n".join(md) + "\n")
    shutil.copy(study_dir / "study.csv", out / f"{name}.csv")

    # maps: rows = pattern; columns = S and linear range at each aspect; pitch × E* heat maps
    shapes = list(ds["contact.shape"].values)
    aspects = list(ds["var.aspect"].values)
    pitches, Es = list(ds["contact.pitch"].values), list(ds["contact.E_star"].values)
    panels = [("S_V_per_kPa", a) for a in aspects] + [("linear_range_Pa", a) for a in aspects]
    fig, axs = plt.subplots(len(shapes), len(panels), figsize=(3.0 * len(panels), 2.3 * len(shapes)),
                            squeeze=False)
    lims = {"S_V_per_kPa": (0, np.nanpercentile(np.clip(ds["S_V_per_kPa"].values, 0, None), 98)),
            "linear_range_Pa": (0, 150)}
    for i, s in enumerate(shapes):
        for j, (v, a) in enumerate(panels):
            ax = axs[i, j]
            sub = ds.sel({"contact.shape": s, "var.aspect": a}).transpose("contact.E_star", "contact.pitch", ...)
            z = sub[v].values.astype(float)
            if v == "linear_range_Pa":
                z = np.minimum(z / 1e3, 150)
                z = np.where(sub["S_V_per_kPa"].values > 0, z, np.nan)
            m = ax.pcolormesh(np.arange(len(pitches)), np.arange(len(Es)), z, shading="nearest", cmap="viridis",
                              vmin=lims[v][0], vmax=lims[v][1])
            full_ = sub["adhesive_full_contact"].values == 1
            rs = sub["run_status"].values
            for yy in range(len(Es)):
                for xx in range(len(pitches)):
                    txt = "F" if full_[yy, xx] else fmt(z[yy, xx], "{:.2g}")
                    if rs[yy, xx] not in ("ok", ""):
                        txt += "*"
                    if sub["status"].values[yy, xx] == "failed":
                        txt = "failed"
                    ax.text(xx, yy, txt, ha="center", va="center", fontsize=7, color="w")
            ax.set_xticks(np.arange(len(pitches)), pitches, fontsize=7)
            ax.set_yticks(np.arange(len(Es)), Es, fontsize=7)
            if i == 0:
                ax.set_title(("S (V/kPa)" if v == "S_V_per_kPa" else "linear range (kPa)") + f", aspect {a:g}",
                             fontsize=8)
            if j == 0:
                ax.set_ylabel(f"{s}\nE*", fontsize=8)
            if i == len(shapes) - 1:
                ax.set_xlabel("pitch", fontsize=8)
            if i == 0 and j in (0, len(aspects)):
                fig.colorbar(m, ax=axs[:, j:j + len(aspects)].ravel().tolist(), shrink=0.5, location="bottom")
    fig.suptitle("F: full contact under adhesion alone; *: under-resolved (grid status); "
                 "linear range blank where S ≤ 0", fontsize=8)
    fig.savefig(out / f"{name}_maps.png", dpi=110, bbox_inches="tight")
    plt.close(fig)

    fig, axs = plt.subplots(1, len(shapes), figsize=(3.2 * len(shapes), 3.0), sharey=True, squeeze=False)
    P = ds["applied_pressure" if "applied_pressure" in ds.dims else "pressure"].values / 1e3
    cmap = plt.get_cmap("viridis")
    for i, s in enumerate(shapes):
        ax = axs[0, i]
        for k, e in enumerate(Es):
            sub = ds["V_OC"].sel({"contact.shape": s, "contact.E_star": e})
            for pt in pitches:
                for a in aspects:
                    ax.plot(P, sub.sel({"contact.pitch": pt, "var.aspect": a}).values,
                            color=cmap(k / max(1, len(Es) - 1)), lw=0.8)
        ax.set_title(s, fontsize=9)
        ax.set_xlabel("pressure (kPa)")
    axs[0, 0].set_ylabel("V_OC (V), Eq. (12)")
    sm = plt.cm.ScalarMappable(cmap=cmap, norm=plt.Normalize(0, len(Es) - 1))
    cb = fig.colorbar(sm, ax=axs[0, -1])
    cb.set_ticks(np.arange(len(Es)), labels=Es)
    cb.set_label("E*")
    fig.tight_layout()
    fig.savefig(out / f"{name}_voc.png", dpi=110)
    plt.close(fig)
    print("\n".join(md))


if __name__ == "__main__":
    main(*sys.argv[1:4])
