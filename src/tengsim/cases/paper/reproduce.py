"""Reproduce the paper end to end: Figs. 3, 4, 5 (contact) and 7, 8 (device), data and summary.

Everything is written into a staging folder first and moved into place only when the whole run
has succeeded, so an interrupted or failed run leaves no partial output behind. summary.json is
strict JSON: a value that could not be measured is null, never NaN.
"""
from __future__ import annotations

import os
import shutil
import tempfile
import time
from pathlib import Path

import numpy as np

from tengsim import io
from tengsim._version import __version__
from tengsim.cases.paper.contact import (FIG3_D, GROUPS, PAPER_TRANSITION_D, RunSettings,
                                         area_table_from_load_result, area_table_from_result, compare_area_tables,
                                         contact_summary, run_group, run_group_load)
from tengsim.cases.paper.device import fig7_summary, fig8_summary, run_fig7, run_fig8

# Section 4 (Fig. 5) constants: σ = 5.84 µC/m², ε_r = 2.40, T = 400 µm.
FIG5_SIGMA = 5.84e-6
FIG5_EPS_R = 2.40
FIG5_T = 400e-6


def reproduce(out_dir, quick: bool = False, progress_factory=None, log=None,
              groups=GROUPS, cycles: int | None = None) -> dict:
    """Run everything; write figures (PNG+PDF), data (CSV+NetCDF) and summary.json to ``out_dir``.

    ``progress_factory(label)`` returns a progress callable for one long stage (or None).
    Returns the summary dict.
    """
    from tengsim.device import plots as dplots
    from tengsim.device.formulas import voc_polymer
    from tengsim.cases.paper.figures import plot_fig3, plot_fig4, plot_fig5

    out_dir = Path(out_dir)
    io.check_writable(out_dir)  # the staging folder goes beside it
    stage = Path(tempfile.mkdtemp(prefix=f".{out_dir.name}.", suffix=".part", dir=out_dir.parent))
    say = log or (lambda msg: None)
    t0 = time.perf_counter()
    try:
        settings = RunSettings.preset(quick)
        results, summary = {}, {"tengsim_version": __version__, "quick": quick,
                                "settings": settings.__dict__, "contact": {}}
        for g in groups:
            say(f"contact: group {g} (dx={settings.dx}, D {settings.d_min}..{settings.d_max} step {settings.d_step})")
            prog = progress_factory(f"group {g}") if progress_factory else None
            res = run_group(g, settings, progress=prog)
            if prog is not None and hasattr(prog, "close"):
                prog.close()
            results[g] = res
            res.save(stage / f"contact_{g}.nc")
            res.save(stage / f"contact_{g}.csv")
            summary["contact"][g] = contact_summary(res, g)
        plot_fig3(results, stage / "fig3.png", FIG3_D)
        plot_fig3(results, stage / "fig3.pdf", FIG3_D)
        plot_fig4(results, stage / "fig4.png", PAPER_TRANSITION_D)
        plot_fig4(results, stage / "fig4.pdf", PAPER_TRANSITION_D)
        # Fig. 5: V_OC(pressure) by Eq. (12) from the load-controlled A(P) of each group: a
        # LoadPathSpec approach from F = 0 to the largest F the D path reached; the table picked from the
        # D path is kept beside it for comparison (fig5.csv, summary 'area_table_vs_D_picked')
        curves, cols = {}, {}
        tables = {}
        picked = {}
        for g, res in results.items():
            f_max = float(np.max(res.branch("approach")["F"]))
            say(f"contact: group {g} under load control (F 0..{f_max:.4g}, steps <= {settings.p_step_Pa:g} Pa)")
            prog = progress_factory(f"group {g} load") if progress_factory else None
            lres = run_group_load(g, f_max, settings, progress=prog)
            if prog is not None and hasattr(prog, "close"):
                prog.close()
            lres.save(stage / f"contact_{g}_load.csv")
            tab = area_table_from_load_result(lres, g)
            tables[g] = tab
            picked[g] = area_table_from_result(res, g)
            v = voc_polymer(tab.area_fraction, FIG5_SIGMA, FIG5_EPS_R, FIG5_T)
            curves[g] = (tab.pressure_Pa, v)
            c = summary["contact"][g]
            c["area_table"] = "load-controlled"
            c["area_table_vs_D_picked"] = compare_area_tables(tab, picked[g], g, settings.dx)
            c["voc_saturation_V"] = float(v[-1])  # at the highest pressure reached (D = d_max)
            c["voc_saturation_pressure_Pa"] = float(tab.pressure_Pa[-1])
            c["area_fraction_final"] = float(tab.area_fraction[-1])
            for kpa in (10, 150):  # V_OC at the pressures of the paper's Fig. 8 range
                P = kpa * 1e3
                c[f"voc_at_{kpa}kPa_V"] = float(np.interp(P, tab.pressure_Pa, v)) \
                    if tab.pressure_Pa[0] <= P <= tab.pressure_Pa[-1] else None  # outside the table
        n = max(max(len(c[0]) for c in curves.values()), max(len(t.pressure_Pa) for t in picked.values()))

        def pad(x):
            return np.pad(np.asarray(x, float), (0, n - len(x)), constant_values=np.nan)
        for g, (p, v) in curves.items():
            cols[f"pressure_Pa_{g}"] = pad(p)
            cols[f"area_fraction_{g}"] = pad(tables[g].area_fraction)
            cols[f"voc_V_{g}"] = pad(v)
        for g, t in picked.items():  # the D-picked table, for comparison
            cols[f"pressure_Pa_Dpicked_{g}"] = pad(t.pressure_Pa)
            cols[f"area_fraction_Dpicked_{g}"] = pad(t.area_fraction)
            cols[f"voc_V_Dpicked_{g}"] = pad(voc_polymer(t.area_fraction, FIG5_SIGMA, FIG5_EPS_R, FIG5_T))
        io.write_csv(stage / "fig5.csv", cols, header={"model": "Eq. (12)", "area_table": "load-controlled "
                                                       "(columns *_Dpicked_*: picked from the D path)",
                                                       "sigma_C_m2": FIG5_SIGMA,
                                                       "eps_r": FIG5_EPS_R, "T_m": FIG5_T})
        plot_fig5(curves, stage / "fig5.png")
        plot_fig5(curves, stage / "fig5.pdf")
        # Fig. 7: flat device, 10 N square wave at 5 Hz
        say("device: Fig. 7 (flat device, 10 N square wave at 5 Hz)")
        r7 = run_fig7(cycles=cycles or (4 if quick else 8))
        r7.write_csv(stage / "fig7.csv")
        io.write_dataset(r7.to_dataset(), stage / "fig7.nc")
        dplots.plot_fig7(r7, stage / "fig7.png")
        dplots.plot_fig7(r7, stage / "fig7.pdf")
        summary["fig7"] = fig7_summary(r7)
        # Fig. 8: group A device under the 10 -> 150 kPa staircase, A(P) from the engine
        if "A" in tables:
            say("device: Fig. 8 (group A, 10 -> 150 kPa staircase at 2 Hz)")
            r8 = run_fig8(area_table=tables["A"])
            r8.write_csv(stage / "fig8.csv")
            io.write_dataset(r8.to_dataset(), stage / "fig8.nc")
            dplots.plot_fig8(r8, stage / "fig8.png")
            dplots.plot_fig8(r8, stage / "fig8.pdf")
            summary["fig8"] = fig8_summary(r8)
        summary["seconds"] = time.perf_counter() - t0
        summary = io.jsonable(summary)
        io.write_json(stage / "summary.json", summary)
        out_dir.mkdir(parents=True, exist_ok=True)
        for f in sorted(stage.iterdir()):
            os.replace(f, out_dir / f.name)
        return summary
    finally:
        shutil.rmtree(stage, ignore_errors=True)


def _num(x, fmt: str = ".4g") -> str:
    return "n/a" if x is None else format(x, fmt)


def summary_text(summary: dict) -> list:
    """One line per contact group (transition D, pull-off F, saturated V_OC); missing values read 'n/a'."""
    return [f"group {g}: transition D = {_num(s.get('transition_D'), '.3g')} (paper {s.get('transition_D_paper')}), "
            f"pull-off F = {_num(s.get('pull_off_F'))}, V_OC sat = {_num(s.get('voc_saturation_V'))} V"
            for g, s in summary.get("contact", {}).items()]
