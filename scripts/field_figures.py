"""Figures of docs/device.md's field section: V_OC(x) under both field models, and Paschen's curve with the
device's gap voltage. Writes docs/data/field_voc.png and docs/data/field_paschen.png (about a minute).

    PYTHONPATH=src python scripts/field_figures.py
"""
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from tengsim.device import EPS0, DeviceParams
from tengsim.device.breakdown import gap_voltage_per_sigma, sigma_breakdown
from tengsim.device.field import gap_coefficients
from tengsim.device.paschen import breakdown_voltage

OUT = Path(__file__).resolve().parents[1] / "docs" / "data"
SIGMA, T, ER = 10e-6, 50e-6, 2.1  # assumed: 10 uC/m2 on a 50 um FEP-like layer


def voc_figure():
    x = np.geomspace(1e-5, 2e-2, 24)
    fig, ax = plt.subplots(figsize=(5.2, 3.6), constrained_layout=True)
    ax.plot(x * 1e3, SIGMA * x / EPS0 / 1e3, "k-", label="parallel (Eq. 17)")
    for size, style in ((0.01, "C0--"), (0.02, "C1-."), (0.05, "C2:")):
        v = gap_coefficients("square", size, T, ER, x)[1] * SIGMA * size * size
        ax.plot(x * 1e3, v / 1e3, style, lw=2, label=f"finite, square {size * 100:.0f} cm")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("gap x (mm)")
    ax.set_ylabel("open-circuit voltage $V_{OC}$ (kV)")
    ax.set_title(f"σ = {SIGMA * 1e6:.0f} µC/m², T = {T * 1e6:.0f} µm, ε_r = {ER}")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.savefig(OUT / "field_voc.png", dpi=130)


def paschen_figure():
    p = DeviceParams(mass_kg=0.01, stiffness_N_per_m=5e3, area_m2=0.02 ** 2, thickness_m=T, gap_m=1e-3, eps_r=ER,
                     sigma_C_per_m2=SIGMA, field="finite", electrode_shape="square")
    x = np.geomspace(2e-6, 2e-2, 300)
    fig, ax = plt.subplots(figsize=(5.2, 3.6), constrained_layout=True)
    ax.plot(x * 1e3, breakdown_voltage(x), "k-", lw=2, label="Paschen, air, 1 atm (min 327 V at 7.5 µm)")
    cap = sigma_breakdown(p, x_max_m=2e-2)
    for sig, style in ((SIGMA, "C0"), (cap.sigma_breakdown_C_m2, "C3")):
        for cond, ls in (("open", "-"), ("short", "--")):
            v = sig * gap_voltage_per_sigma(p, x, cond)
            ax.plot(x * 1e3, v, color=style, ls=ls,
                    label=f"gap, {cond} circuit, σ = {sig * 1e6:.1f} µC/m²")
    ax.plot([cap.gap_at_limit_m * 1e3], [breakdown_voltage(cap.gap_at_limit_m)], "o", color="C3", mfc="none", ms=9)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_ylim(10, 3e5)
    ax.set_xlabel("gap x (mm)")
    ax.set_ylabel("voltage (V)")
    ax.set_title("2 cm square electrode, finite field, T = 50 µm")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, loc="upper left")
    fig.savefig(OUT / "field_paschen.png", dpi=130)


if __name__ == "__main__":
    voc_figure()
    paschen_figure()
