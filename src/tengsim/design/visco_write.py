"""The files of a design's viscoelastic cycles: OUT/visco.csv (every cycle's rows), OUT/visco_table.csv (the
frequency table), OUT/visco.png (A/S(t) and V_OC(t) over the square cycle at each frequency, and the V_OC(P)
loops), a section appended to OUT/report.md, and the cycles recorded in OUT/design.nc (:func:`record_in_design`),
so that the design result carries its material's history: ``tengsim device design`` drives the device with it
(:func:`tengsim.device.areas.area_cycle_from_design`)."""
from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np

COLS = ("frequency_Hz", "sensitivity_V_per_Pa", "linear_range_Pa", "voc_hysteresis_fraction", "response_s",
        "recovery_s", "area_max", "area_max_steady")


def _fmt(v, scale=1.0, digits=3) -> str:
    return "n/a" if v is None or not math.isfinite(v) else f"{v * scale:.{digits}g}"


def report_section(vd) -> str:
    m = vd.material
    lines = ["", "## Viscoelastic cycles (`--relaxation`)", "",
             f"Material: E∞ = {m.E_inf / 1e6:.4g} MPa, E0 = {m.E0 / 1e6:.4g} MPa, "
             + ", ".join(f"{e / 1e6:.3g} MPa at τ = {t:g} s" for e, t in zip(m.E, m.tau))
             + (f" ({m.source})" if m.source else "") + ".",
             f"Each frequency: a triangle cycle 0 → p_max → 0 in one period (sensitivity, linear range, hysteresis of "
             f"V_OC(P)) and a square cycle (press in 5 % of the period, hold, release; response and recovery time to "
             f"90 % of V_OC's change), load-controlled, on one coarse grid {vd.grid}: rate effects, not converged "
             f"numbers (the static design above is). 0 Hz: the relaxed elastic solid (E∞).", "",
             "| f (Hz) | sensitivity (V/kPa) | linear range (kPa) | hysteresis | response (ms) | recovery (ms) | max A/S "
             "| max A/S, steady |",
             "|---|---|---|---|---|---|---|---|"]
    for r in vd.table:
        lines.append(f"| {_fmt(r['frequency_Hz'])} | {_fmt(r['sensitivity_V_per_Pa'], 1e3)} | "
                     f"{_fmt(r['linear_range_Pa'], 1e-3)} | {_fmt(r['voc_hysteresis_fraction'], 100)} % | "
                     f"{_fmt(r['response_s'], 1e3)} | {_fmt(r['recovery_s'], 1e3)} | {_fmt(r['area_max'], 1, 4)} | "
                     f"{_fmt(r.get('area_max_steady', math.nan), 1, 4)} |")
    if vd.steady:
        lines += ["", "The device's presses repeated with the material's memory carried from one period to the next "
                  "(max A/S, steady: the square press's periodic steady state; the first press starts from rest): "
                  + "; ".join(f"{s['cycle']} at {s['frequency_Hz']:g} Hz "
                              f"{'repeats' if s['converged'] else 'does NOT repeat'} to "
                              f"{_fmt(s['change'], 100, 2)} % after {s['evaluations']} periods" for s in vd.steady)
                  + "."]
    lines += ["", "![viscoelastic cycles](visco.png)", ""]
    return "\n".join(lines)


def figure(vd, path: Path) -> None:
    from tengsim.plots import pyplot, save

    plt = pyplot()

    fig, axes = plt.subplots(1, 3, figsize=(13, 4.0), constrained_layout=True)
    colors = plt.cm.viridis(np.linspace(0, 0.85, max(1, len(vd.table))))
    for c, row in zip(colors, vd.table):
        f = row["frequency_Hz"]
        label = f"{f:g} Hz" if f else "elastic (E∞)"
        for cyc in vd.cycles:
            if cyc.frequency != f:
                continue
            period = 1 / f if f else 1.0
            ls = "--" if not f else "-" if cyc.press == 1 else ":"
            if cyc.press not in (0, 1):
                continue
            if cyc.kind == "square":
                which = label if not f else f"{label}, {'first press' if cyc.press == 1 else 'steady state'}"
                axes[0].plot(cyc.t / period, cyc.area, ls, color=c, label=which)
                axes[1].plot(cyc.t / period, cyc.voc, ls, color=c, label=which)
            elif cyc.kind == "triangle":
                axes[2].plot(cyc.pressure_Pa / 1e3, cyc.voc, ls, color=c, label=label)
    axes[0].set(xlabel="t / period (square cycle; dotted: its periodic steady state)", ylabel="A/S")
    axes[1].set(xlabel="t / period (square cycle; dotted: its periodic steady state)", ylabel="V_OC (V, Eq. 12)")
    axes[2].set(xlabel="nominal pressure (kPa, triangle cycle)", ylabel="V_OC (V, Eq. 12)")
    for ax in axes:
        ax.grid(alpha=0.3)
    axes[0].legend(frameon=False, fontsize=8)
    save(fig, path)  # atomic, as every figure


RECORD = {  # design.nc variable (along VISCO_DIM): (units, long_name)
    "visco_frequency": ("Hz", "frequency of the cycle the row belongs to (0: the relaxed elastic solid, E_inf, "
                              "period 1 s)"),
    "visco_time": ("s", "time from the start of the cycle"),
    "visco_pressure": ("Pa", "nominal pressure (load control)"),
    "visco_charged_area_fraction": ("1", "charged contact area over cell area (A/S) on the cycles' coarse grid"),
    "visco_press": ("1", "which press of the repeated cycle (1, 2, ... from rest; 0: its periodic steady state)"),
}
VISCO_DIM = "visco_row"


def record_in_design(vd, folder) -> Path | None:
    """Add the cycles to ``folder``/design.nc (none there: None): the variables :data:`RECORD` and ``visco_cycle``
    (triangle or square) along :data:`VISCO_DIM`, one row per time of each cycle as in visco.csv, and the
    attributes ``relaxation`` (JSON: E_inf_Pa, E_Pa, tau_s, source), ``visco_frequencies_Hz``, ``visco_p_max_Pa``
    (every cycle presses to it), ``visco_rise`` (the square cycle's ramps, a fraction of its period; pressed for
    half the period), ``visco_grid``, ``visco_steady`` (JSON: per frequency and press, how its periodic steady state
    converged).  A square or sine press has rows for its presses 1, 2, … from rest and for its steady state
    (``visco_press`` 0).  Rewritten whole (atomically): the design's own variables unchanged."""
    import json

    from tengsim.design.visco import RISE
    from tengsim.io import read_dataset, write_dataset

    path = Path(folder) / "design.nc"
    if not path.is_file():
        return None
    ds = read_dataset(path)
    cols = {"visco_frequency": [], "visco_time": [], "visco_pressure": [], "visco_charged_area_fraction": [],
            "visco_press": []}
    kinds = []
    for c in vd.cycles:
        cols["visco_frequency"].append(np.full(c.t.size, float(c.frequency)))
        cols["visco_time"].append(np.asarray(c.t, float))
        cols["visco_pressure"].append(np.asarray(c.pressure_Pa, float))
        cols["visco_charged_area_fraction"].append(np.asarray(c.area, float))
        cols["visco_press"].append(np.full(c.t.size, int(c.press)))
        kinds += [c.kind] * c.t.size
    for name, parts in cols.items():
        units, long_name = RECORD[name]
        ds[name] = ((VISCO_DIM,), np.concatenate(parts), {"units": units, "long_name": long_name})
    ds["visco_cycle"] = ((VISCO_DIM,), np.array(kinds, dtype=object),
                         {"long_name": "triangle, square or sine cycle"})
    m = vd.material
    ds.attrs["relaxation"] = json.dumps({"E_inf_Pa": m.E_inf, "E_Pa": list(m.E), "tau_s": list(m.tau),
                                         "source": m.source})
    ds.attrs["visco_frequencies_Hz"] = np.array(sorted({float(r["frequency_Hz"]) for r in vd.table} - {0.0}))
    ds.attrs["visco_p_max_Pa"] = float(vd.p_max_Pa)
    ds.attrs["visco_rise"] = float(RISE)
    ds.attrs["visco_grid"] = str(vd.grid)
    ds.attrs["visco_steady"] = json.dumps([{k: (bool(v) if isinstance(v, (bool, np.bool_)) else v)
                                            for k, v in s.items()} for s in vd.steady])
    write_dataset(ds, path)
    return path


def write_visco(vd, folder) -> list:
    """Write the files (module doc); returns their paths."""
    folder = Path(folder)
    rows = folder / "visco.csv"
    with rows.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["frequency_Hz", "cycle", "press", "time_s", "pressure_Pa", "area_fraction", "voc_V", "force_N"])
        for c in vd.cycles:
            for i in range(c.t.size):
                w.writerow([c.frequency, c.kind, c.press, c.t[i], c.pressure_Pa[i], c.area[i], c.voc[i],
                            c.force_N[i]])
    table = folder / "visco_table.csv"
    with table.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(COLS)
        for r in vd.table:
            w.writerow([r[k] for k in COLS])
    png = folder / "visco.png"
    figure(vd, png)
    report = folder / "report.md"
    with report.open("a") as fh:
        fh.write(report_section(vd))
    record_in_design(vd, folder)
    return [rows, table, png]
