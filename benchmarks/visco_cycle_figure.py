"""docs/data/visco_cycle.png: A/S over one pressing cycle at two frequencies (docs/model.md, "When viscoelasticity
matters"), from the visco.csv a design writes:

    tengsim design examples/own_design/pyramid.toml --relaxation examples/relaxation/pdms.toml --out v/
    PYTHONPATH=src python benchmarks/visco_cycle_figure.py v/visco.csv docs/data/visco_cycle.png
"""
from __future__ import annotations

import csv
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def main(src, dst, freqs=(0.5, 10.0)):
    data = defaultdict(list)
    with open(src) as fh:
        for r in csv.DictReader(fh):
            if r["cycle"] == "square":
                data[float(r["frequency_Hz"])].append((float(r["time_s"]), float(r["area_fraction"]),
                                                       float(r["pressure_Pa"])))
    fig, ax = plt.subplots(figsize=(4.6, 3.2), constrained_layout=True)
    styles = {0.0: ("0.55", "--", "relaxed elastic (E∞)")}
    colors = ["#1b6ca8", "#d1495b"]
    for c, f in zip(colors, freqs):
        styles[f] = (c, "-", f"{f:g} Hz")
    for f, (c, ls, label) in styles.items():
        rows = np.array(data[f])
        period = 1.0 / f if f else 1.0
        ax.plot(rows[:, 0] / period, rows[:, 1], ls, color=c, lw=1.6, label=label)
    p = np.array(data[0.0])
    ax2 = ax.twinx()
    ax2.fill_between(p[:, 0], p[:, 2] / 1e3, color="0.9", zorder=0, step=None)
    ax2.set_ylabel("nominal pressure (kPa)", color="0.5")
    ax2.tick_params(axis="y", colors="0.5")
    ax.set_zorder(ax2.get_zorder() + 1)
    ax.patch.set_visible(False)
    ax.set_xlabel("t / period")
    ax.set_ylabel("charged area A/S")
    ax.set_xlim(0, 1)
    ax.legend(frameon=False, loc="center right")
    fig.savefig(dst, dpi=200)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
