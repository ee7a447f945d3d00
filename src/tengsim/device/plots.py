"""Figures for the device model (Agg backend; PNG or PDF by extension, written atomically)."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from tengsim.errors import require


def _figure(nrows, ncols, size):
    from tengsim.plots import pyplot

    plt = pyplot()

    return plt, *plt.subplots(nrows, ncols, figsize=size, squeeze=False)


def _save(plt, fig, path):
    from tengsim.plots import save

    fmt = Path(path).suffix.lower().lstrip(".")
    require(fmt in ("png", "pdf", "svg"), f"plot path must end in .png, .pdf or .svg, got {str(path)!r}")
    fig.tight_layout()
    save(fig, path)


def plot_fig7(result, path) -> None:
    """Nine panels as in Fig. 7: P_a S, y, ydot, Q, I, V, I_SC, V_OC, power against t."""
    plt, fig, ax = _figure(3, 3, (12, 9))
    t = result.t * 1e3
    S = result.params.area_m2
    panels = [("applied force (N)", result.P_a * S), ("displacement y (mm)", result.y * 1e3),
              ("velocity (m/s)", result.ydot), ("charge Q (nC)", result.Q * 1e9), ("current I (µA)", result.I * 1e6),
              ("voltage V (V)", result.V), ("short-circuit current I_SC (µA)", result.I_sc * 1e6),
              ("open-circuit voltage V_OC (V)", result.V_oc), ("power into the load (µW)", result.power * 1e6)]
    settled = result.t >= result.waveform.period  # the first period holds the Q(0) = 0 start spike
    for a, (label, y) in zip(ax.ravel(), panels):
        a.plot(t, y, lw=0.8)
        a.set_xlabel("t (ms)")
        a.set_ylabel(label)
        a.grid(alpha=0.3)
        if settled.any() and np.ptp(y[settled]) > 0:
            lo, hi = float(np.min(y[settled])), float(np.max(y[settled]))
            pad = 0.08 * (hi - lo)
            if np.min(y) < lo - pad or np.max(y) > hi + pad:  # keep the start spike from hiding the cycle
                a.set_ylim(lo - pad, hi + pad)
                a.axvspan(t[0], result.waveform.period * 1e3, color="0.9", zorder=0)
    fig.suptitle("Fig. 7 device (grey: first period, start transient of Q(0) = 0, clipped)", fontsize=10)
    _save(plt, fig, path)


def plot_fig8(result, path, table=None) -> None:
    """Staircase run as Fig. 8: (a) A/S against pressure over the staircase's range, (b) V_OC(t) with
    the per-step V_OC. The pressure axis spans 0 to 1.1 x the largest step (not the area table's range)."""
    from tengsim.device.analysis import staircase_summary

    plt, fig, ax = _figure(1, 2, (12, 4.5))
    area = result.params.area
    s = staircase_summary(result)
    steps = np.asarray(s["pressure_steps_Pa"])
    p_hi = 1.1 * float(np.max(steps))
    p = np.linspace(0.0, p_hi, 200)
    tab = np.asarray(getattr(area, "pressure_Pa", []), dtype=float)
    p = np.union1d(p, tab[(tab >= 0) & (tab <= p_hi)])  # keep the table's own points inside the range
    ax[0, 0].plot(p / 1e3, area(p), "-", label="A(P) model")
    ax[0, 0].plot(steps / 1e3, s["area_fraction_steps"], "o", ms=3, label="staircase steps")
    ax[0, 0].set_xlim(0.0, p_hi / 1e3)
    ax[0, 0].set_ylim(0.0, max(1.1 * float(np.max(area(p))), 1e-3))  # a fraction: from 0, not zoomed
    ax[0, 0].set_xlabel("applied pressure (kPa)")
    ax[0, 0].set_ylabel("charged area A/S")
    ax[0, 0].legend()
    ax[0, 1].plot(result.t, result.V_oc, lw=0.8, label="V_OC(t), Eq. 17")
    per = result.waveform.period
    v = np.array([np.nan if x is None else x for x in s["voc_steps_V"]], dtype=float)
    tk = (np.arange(v.size) + 0.75) * per
    ax[0, 1].plot(tk, v, "o", ms=3, label="per step")
    ax[0, 1].set_xlabel("t (s)")
    ax[0, 1].set_ylabel("V_OC (V)")
    ax[0, 1].legend()
    _save(plt, fig, path)


def plot_vq_cycle(result, path, cycle: int = -1) -> None:
    """V-Q loop of one settled cycle with the cycle for maximised energy output (Zi et al. 2015)."""
    from tengsim.device.analysis import vq_cycle

    vq = vq_cycle(result, cycle)
    plt, fig, ax = _figure(1, 1, (6, 5))
    a = ax[0, 0]
    a.plot(vq.charge_C * 1e9, vq.voltage_V, label=f"run, E = {vq.energy_J:.3g} J")
    a.plot(vq.cmeo.charge_C * 1e9, vq.cmeo.voltage_V, "--", label=f"CMEO, E_m = {vq.cmeo.energy_J:.3g} J")
    a.set_xlabel("Q (nC)")
    a.set_ylabel("V (V)")
    a.legend()
    _save(plt, fig, path)


def plot_resistance_sweep(sweep, path) -> None:
    """Mean power and energy per cycle against load R, optimum marked."""
    from tengsim.units import si_prefix

    plt, fig, ax = _figure(1, 2, (11, 4.5))
    fp, pu = si_prefix(float(np.nanmax(sweep.average_power_W)), "W")
    ax[0, 0].loglog(sweep.load_ohm, sweep.average_power_W / fp, "o-", label="mean")
    peak = getattr(sweep, "peak_power_W", None)
    if peak is not None:
        ax[0, 0].loglog(sweep.load_ohm, peak / fp, "s--", ms=4, label="peak")
    ax[0, 0].axvline(sweep.optimum_ohm, color="k", ls=":",
                     label="largest in range (at its edge)" if getattr(sweep, "optimum_at_edge", False)
                     else "optimum")
    ax[0, 0].legend()
    ax[0, 0].set_xlabel("load R (Ω)")
    ax[0, 0].set_ylabel(f"power into the load ({pu})")
    ax[0, 1].loglog(sweep.load_ohm, sweep.peak_voltage_V, "o-", label="peak voltage (V)")
    ax[0, 1].loglog(sweep.load_ohm, sweep.peak_current_A * 1e6, "s-", label="peak current (µA)")
    ax[0, 1].set_xlabel("load R (Ω)")
    ax[0, 1].legend()
    _save(plt, fig, path)
