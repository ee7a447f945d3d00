"""A calibration's files: fit.nc (CF-1.10, SI), fit.csv, report.md, fit.png, residuals.png, profiles.png and
material.toml (what ``tengsim design --material`` reads).

fit.nc: dimension ``observation`` (every measured point, curves one after another: ``curve`` index,
``measured_pressure`` Pa, ``voc_measured``, ``voc_fitted``, ``voc_lower``/``voc_upper`` (V, the 95 % band),
``residual`` (in the noise model's units)); dimension ``curve_point`` (the drawn curves: ``curve_of_point``,
``curve_pressure``, ``voc_best``, ``voc_band_lower``, ``voc_band_upper``); dimension ``parameter`` (``best``,
``lower_95``, ``upper_95`` SI, ``parameter_units``), ``correlation`` (parameter, parameter2); per parameter its
profile (``profile_NAME_value``, ``profile_NAME_deviance``); global attributes: noise model, scale, threshold,
interval method, surrogate error, the identifiability sentences.
"""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from tengsim.calibrate.problem import UNITS, label, text

SI_UNITS = {"sigma": "C m-2", "W": "J m-2", "eps": "m", "E_star": "Pa"}


def _obs(cal):
    prob, model, f = cal.problem, cal.model, cal.fit
    G = model.g(f.theta[None, :])
    fitted = [f.best["sigma"] * g[0] for g in G]
    lo_hi = _band_at_data(cal)
    rows = {"curve": [], "P": [], "V": [], "Vf": [], "lo": [], "hi": [], "r": []}
    off = 0
    for i, c in enumerate(prob.curves):
        w = model.w[off:off + c.n]
        off += c.n
        rows["curve"] += [i] * c.n
        rows["P"] += list(c.pressure)
        rows["V"] += list(c.voc)
        rows["Vf"] += list(fitted[i])
        rows["lo"] += list(lo_hi[i][1])
        rows["hi"] += list(lo_hi[i][2])
        rows["r"] += list((c.voc - fitted[i]) / w)
    return {k: np.asarray(v) for k, v in rows.items()}


def _band_at_data(cal):
    from tengsim.calibrate.fit import band

    return band(cal.model, cal.fit, [c.pressure for c in cal.problem.curves], [c.branch for c in cal.problem.curves])


def noise_text(cal) -> str:
    prob, f = cal.problem, cal.fit
    if prob.known_errors:
        return "known errors (the voc_err_V column): χ² with each point's own uncertainty"
    if prob.noise == "relative":
        return (f"relative, one scale estimated from the residuals: {100 * f.scale:.3g} % of V_OC (points below 5 % "
                "of a curve's largest voltage weighted as at 5 %)")
    return f"absolute, one scale estimated from the residuals: {f.scale:.4g} V"


def to_dataset(cal):
    import xarray as xr

    from tengsim.io import cf_conventions

    prob, f = cal.problem, cal.fit
    o = _obs(cal)
    ds = xr.Dataset()
    ds["curve"] = ("observation", o["curve"].astype(np.int32), {"long_name": "index of the measured curve", "units": "1"})
    ds["measured_pressure"] = ("observation", o["P"], {"units": "Pa", "long_name": "nominal pressure of the measurement"})
    for k, long in (("V", "measured open-circuit voltage"), ("Vf", "fitted open-circuit voltage"),
                    ("lo", "lower end of the 95 % band of the fitted voltage"),
                    ("hi", "upper end of the 95 % band of the fitted voltage")):
        name = {"V": "voc_measured", "Vf": "voc_fitted", "lo": "voc_lower", "hi": "voc_upper"}[k]
        ds[name] = ("observation", o[k], {"units": "V", "long_name": long})
    ds["residual"] = ("observation", o["r"], {"units": "1" if prob.noise == "relative" or prob.known_errors else "V",
                                              "long_name": "residual in the noise model's units"})
    cp, cv, bl, bh, bb = [], [], [], [], []
    for i, (P, (best, lo, hi)) in enumerate(zip(cal.plot_pressures, cal.bands)):
        cp += [i] * len(P)
        cv += list(P)
        bb += list(best)
        bl += list(lo)
        bh += list(hi)
    ds["curve_of_point"] = ("curve_point", np.asarray(cp, np.int32), {"long_name": "index of the curve", "units": "1"})
    ds["curve_pressure"] = ("curve_point", np.asarray(cv), {"units": "Pa", "long_name": "nominal pressure"})
    ds["voc_best"] = ("curve_point", np.asarray(bb), {"units": "V", "long_name": "fitted open-circuit voltage"})
    ds["voc_band_lower"] = ("curve_point", np.asarray(bl), {"units": "V", "long_name": "lower end of the 95 % band"})
    ds["voc_band_upper"] = ("curve_point", np.asarray(bh), {"units": "V", "long_name": "upper end of the 95 % band"})
    names = list(prob.free)
    ds["best"] = ("parameter", [f.best[k] for k in names], {"long_name": "best value (SI; units in parameter_units)"})
    ds["lower_95"] = ("parameter", [f.interval[k][0] for k in names], {"long_name": "lower end of the 95 % profile-likelihood interval (SI)"})
    ds["upper_95"] = ("parameter", [f.interval[k][1] for k in names], {"long_name": "upper end of the 95 % profile-likelihood interval (SI)"})
    ds["open_at_bound"] = ("parameter", np.array([int(f.interval[k][2]) + 2 * int(f.interval[k][3]) for k in names],
                                                   np.int32),
                           {"long_name": "interval open at a bound: 0 none, 1 lower, 2 upper, 3 both", "units": "1"})
    ds["parameter_name"] = ("parameter", np.array(names, dtype=object), {"long_name": "parameter"})
    ds["parameter_units"] = ("parameter", np.array([SI_UNITS[k] for k in names], dtype=object),
                             {"long_name": "SI unit of the parameter"})
    if len(f.names):
        ds["correlation"] = (("parameter_corr", "parameter_corr2"), np.asarray(f.corr, float),
                             {"units": "1", "long_name": "correlation of the log parameters ("
                              + ", ".join(f.names) + ")"})
    for k, (vals, d) in f.profile.items():
        ds[f"profile_{k}_value"] = (f"profile_{k}", np.asarray(vals, float), {"units": SI_UNITS[k],
                                                                            "long_name": f"{k} along its profile"})
        ds[f"profile_{k}_deviance"] = (f"profile_{k}", np.asarray(d, float),
                                       {"units": "1", "long_name": f"profile deviance rise of {k}"})
    for v in ("parameter_name", "parameter_units"):
        ds[v].encoding["dtype"] = "S1"
    ds.attrs = {"noise_model": noise_text(cal), "voc_model": prob.voc, "interval_method":
                "profile likelihood (threshold %.4g)" % f.threshold, "noise_scale": float(f.scale),
                "surrogate_error_at_best": float(cal.surrogate_error) if math.isfinite(cal.surrogate_error) else "n/a",
                "surrogate_within_noise": int(cal.surrogate_ok), "identifiability": " ".join(f.words),
                "free": ",".join(prob.free), "fixed": json.dumps(prob.fixed, sort_keys=True),
                "designs": json.dumps(list(prob.names)), "data": json.dumps([c.source for c in prob.curves])}
    return cf_conventions(ds, "tengsim calibrate: " + ", ".join(prob.free) + " fitted to measured V_OC(P)")


def material_text(cal) -> str:
    """material.toml: [design] the material (best values, with units) that ``tengsim design`` reads; [uncertainty]
    the 95 % intervals and the parameter points whose designs give a prediction's band."""
    from tengsim.calibrate.material import band_points

    f, prob = cal.fit, cal.problem
    vals = {**{k: v for k, v in prob.fixed.items()}, **f.best}
    lines = ["# tengsim calibrate: the material fitted to " + ", ".join(c.source for c in prob.curves),
             "# read by: tengsim design DESIGN.toml --material material.toml --out DIR (the [design] keys below replace",
             "# the design's own; a prediction then runs the [[uncertainty.point]] designs too and writes bands)",
             "[design]"]
    for k in ("E_star", "W", "eps", "sigma"):
        if k in vals:
            lines.append(f'{k} = "{vals[k] / UNITS[k][1]:.8g}{UNITS[k][2]}"')
    lines += ["", "[uncertainty]", 'method = "profile likelihood, 95 %"', f"free = {json.dumps(list(prob.free))}"]
    for k in prob.free:
        lo, hi, olo, ohi = f.interval[k]
        lines.append(f'{k}_95 = ["{lo / UNITS[k][1]:.6g}{UNITS[k][2]}", "{hi / UNITS[k][1]:.6g}{UNITS[k][2]}"]'
                     + ("  # open at a bound: not determined" if olo or ohi else ""))
    for pt in band_points(cal):
        lines += ["", "[[uncertainty.point]]"]
        for k, v in pt.items():
            lines.append(f'{k} = "{v / UNITS[k][1]:.8g}{UNITS[k][2]}"')
    return "\n".join(lines) + "\n"


def breakdown_warning(cal) -> list:
    """One warning line when the fitted σ is above the air-breakdown cap of a curve's device (issue 51;
    tengsim.design.breakdown: open circuit, 4 cm² electrode, gaps up to d0): no device holds that charge."""
    from tengsim.design.breakdown import design_breakdown

    prob = cal.problem
    sigma = {**prob.fixed, **cal.fit.best}.get("sigma")
    if sigma is None:
        return []
    caps = [design_breakdown(sigma, p.eps_r, p.T, p.gap, 1.0)["sigma_breakdown_C_m2"] for p in prob.plans]
    cap = min(caps)
    if sigma <= cap:
        return []
    return ["", f"**Warning: the fitted σ = {sigma * 1e6:.4g} µC/m² is above the air-breakdown cap "
                f"{cap * 1e6:.3g} µC/m² of the curves' device (Paschen, open circuit, 4 cm², gaps up to d0): the "
                "gap would discharge; no device holds that charge (docs/device.md).**"]


def report_text(cal, figures) -> str:
    from tengsim.calibrate.fit import inflation, residual_text

    f, prob = cal.fit, cal.problem
    out = ["# Calibration", "", f"Fitted: {', '.join(label(k) for k in prob.free)} to {prob.n_points} points of "
           f"{len(prob.curves)} measured curve(s), jointly (one material); V_OC by {prob.voc.replace('eq', 'Eq. ')}.", "",
           "| parameter | best | 95 % interval | note |", "|---|---|---|---|"]
    for k in prob.free:
        lo, hi, olo, ohi = f.interval[k]
        note = "open at the lower bound" if olo and not ohi else "open at the upper bound" if ohi and not olo else \
            "not determined (both bounds)" if olo and ohi else ""
        out.append(f"| {label(k)} | {text(k, f.best[k])} | {text(k, lo)} – {text(k, hi)} | {note} |")
    for k, v in prob.fixed.items():
        out.append(f"| {label(k)} | {text(k, v)} (fixed) | | |")
    out += breakdown_warning(cal)
    out += ["", "## What the data determine", ""] + [f"* {w}" for w in f.words]
    if len(f.names):
        out += ["", "## Correlation (log parameters)", "", "| | " + " | ".join(label(n) for n in f.names) + " |",
                "|---|" + "---|" * len(f.names)]
        for i, n in enumerate(f.names):
            out.append(f"| {label(n)} | " + " | ".join(f"{f.corr[i, j]:+.2f}" for j in range(len(f.names))) + " |")
    out += ["", "## Method", "",
            f"* Noise model: {noise_text(cal)}.",
            f"* Intervals: profile likelihood (few parameters; a likelihood that is not Gaussian: bounds reached, "
            f"ridges), each where its profile deviance rises by less than {f.threshold:.3g}.",
            "* σ is profiled out in closed form (V_OC is linear in σ); W, ε (and E*) from converged designs on a grid in "
            "(log W, log ε), interpolated along each curve (the pressure at fixed levels of A/S) by a thin-plate "
            "spline (E* as a pressure scale: no solve of its own).",
            f"* Designs: {cal.nodes_solved} solved, {cal.nodes_cached} taken back from designs/ "
            f"({len(cal.nodes_failed)} not converged and left out), {cal.zooms} zoom(s), {cal.refinements} "
            f"refinement(s) (the checks made designs); {cal.seconds:.0f} s.",
            f"* Interpolation error (designs solved at the best fit and at both ends of each interval against the "
            f"interpolation there, the largest rms over the data points): {residual_text(cal.surrogate_error, prob)} "
            f"against the noise {residual_text(f.scale, prob)}: "
            + ("within half the noise." if cal.surrogate_ok else "**above half the noise: the intervals are widened "
               "for it; narrow --bounds, add --nodes or --zooms for tighter ones**.")
            + f" The intervals make room for it (threshold × {inflation(prob.n_points, cal.surrogate_error, f.scale):.3g})."]
    if cal.nodes_failed:
        out += ["", "Nodes left out:", ""] + [f"* {x}" for x in cal.nodes_failed]
    out += ["", "## Files", "", "fit.nc (CF-1.10, SI), fit.csv, material.toml (`tengsim design --material`), "
            + ", ".join(figures) + "."]
    out += [""] + [f"![{x}]({x})" for x in figures]
    return "\n".join(out) + "\n"


def figures(cal, out: Path) -> list:
    from tengsim.plots import pyplot, save

    plt = pyplot()
    f, prob = cal.fit, cal.problem
    o = _obs(cal)
    paths = []
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    for i, c in enumerate(prob.curves):
        col = f"C{i}"
        best, lo, hi = cal.bands[i]
        P = cal.plot_pressures[i] / 1e3
        # ``where`` given: matplotlib 3.6.0 with numpy 1.24 (the floors) fails on its default
        ax.fill_between(P, lo, hi, where=np.ones(np.shape(P), bool), color=col, alpha=0.25, lw=0)
        data, design = Path(str(c.source)).stem, Path(str(prob.names[i])).stem
        ax.plot(P, best, color=col, label=data if data == design else f"{data} ({design})")
        ax.errorbar(c.pressure / 1e3, c.voc, yerr=c.err, fmt="o", ms=4, color=col, mfc="none")
    ax.set_xlabel("nominal pressure (kPa)")
    ax.set_ylabel("V_OC (V)")
    ax.set_title("measured (o), fitted (line) and its 95 % band")
    ax.legend(fontsize=8, title="curve (design)" if len(prob.curves) > 1 else None, title_fontsize=8)
    save(fig, out / "fit.png")
    paths.append(out / "fit.png")
    fig, ax = plt.subplots(figsize=(6.4, 3.4))
    for i in range(len(prob.curves)):
        m = o["curve"] == i
        ax.plot(o["P"][m] / 1e3, o["r"][m] * (100 if prob.noise == "relative" and not prob.known_errors else 1),
                "o", color=f"C{i}")
    ax.axhline(0, color="k", lw=0.8)
    ax.set_xlabel("nominal pressure (kPa)")
    ax.set_ylabel("residual (%)" if prob.noise == "relative" and not prob.known_errors else
                  "residual (σ units)" if prob.known_errors else "residual (V)")
    save(fig, out / "residuals.png")
    paths.append(out / "residuals.png")
    ks = list(f.profile)
    from matplotlib.ticker import MaxNLocator, NullFormatter, ScalarFormatter

    fig, axes = plt.subplots(1, len(ks), figsize=(3.2 * len(ks), 3.0), squeeze=False)
    top = max(3 * f.threshold, 1)
    for ax, k in zip(axes[0], ks):
        vals, d = f.profile[k]
        x = vals / UNITS[k][1]
        ax.plot(x, d, color="k")
        ax.axhline(f.threshold, color="r", ls="--", lw=0.8, label="95 % threshold")
        ax.set_xscale("log")
        seen = x[d <= top]  # the x range where the profile is drawn inside the axes, a little wider
        if len(seen) and seen.max() > seen.min():
            pad = (seen.max() / seen.min()) ** 0.08
            ax.set_xlim(max(x.min(), seen.min() / pad), min(x.max(), seen.max() * pad))
        ax.xaxis.set_major_locator(MaxNLocator(4))  # plain numbers in the axis unit, several even on a narrow range
        ax.xaxis.set_major_formatter(ScalarFormatter())
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.set_xlabel(f"{label(k)} ({UNITS[k][0]}, log scale)")
        ax.set_ylim(0, top)
    axes[0][0].set_ylabel("profile deviance rise")
    axes[0][0].legend(fontsize=7, loc="upper left")
    save(fig, out / "profiles.png")
    paths.append(out / "profiles.png")
    return paths


def write_calibration(cal, out_dir, figures_too: bool = True) -> list:
    from tengsim.io import csv_text, write_dataset, write_text

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    write_dataset(to_dataset(cal), out / "fit.nc")
    o = _obs(cal)
    write_text(out / "fit.csv", csv_text({"curve": o["curve"], "pressure_kPa": o["P"] / 1e3, "voc_V": o["V"],
                                          "voc_fitted_V": o["Vf"], "voc_lower_V": o["lo"], "voc_upper_V": o["hi"],
                                          "residual": o["r"]}))
    write_text(out / "material.toml", material_text(cal))
    figs = figures(cal, out) if figures_too else []
    write_text(out / "report.md", report_text(cal, [p.name for p in figs]))
    return [out / "fit.nc", out / "fit.csv", out / "material.toml", *figs, out / "report.md"]
