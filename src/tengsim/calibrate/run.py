"""A calibration, start to finish: the problem checked, the nodes solved (kept in DIR), the fit, zoomed in.

:func:`plan_calibration` checks everything before anything is solved or written (the designs, the curves, the free
parameters and bounds, that the voltage can be reached).  :func:`calibrate` then

1. lays an n × n grid of nodes (default 4 × 4) over the bounds of (W_eff, ε) (the axes that are free), prints how
   many designs the whole run is expected to solve (:func:`tengsim.calibrate.checks.expected_designs`; after the
   first, their time at the time per design measured), and solves each (kept in ``DIR/designs``);
2. fits (:func:`tengsim.calibrate.fit.fit`) and measures the interpolation's error
   (:func:`tengsim.calibrate.checks.interpolation_error`: designs at the best fit, at both ends of each free contact
   parameter's interval and half-way beyond each end), the largest; if it is above half the data's noise, lays a
   new n × n grid over the box of that region (15 % margin, at least half the previous box) and fits again, at
   most ``zooms`` times;
3. if the error is still above half the noise, makes the checks nodes and checks anew, at most :data:`REFINE`
   times; the intervals make room for the last error measured (:func:`tengsim.calibrate.fit.inflation`);
4. warns in words (:func:`warnings`, among the fit's words) when the fitted noise is much larger than the stated or
   expected one, or the interpolation's error exceeds the noise;
5. returns a frozen :class:`Calibration` (the fit, its bands, the surrogate's error, the nodes' account).
"""
from __future__ import annotations

import dataclasses
import importlib
import math
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from tengsim.errors import SolverUnavailable, TengsimError

LOO_PER_NOISE = 0.5
"""Zooming stops when the interpolation's leave-one-out error (rms over the nodes of the fitted region, in the
residual's units) is at most this fraction of the data's noise; whatever it is, the intervals make room for it
(:func:`tengsim.calibrate.fit.inflation`).  It includes each node's own discretisation error (a design converged to
its tol), which no interpolation removes: give the designs a tol below the data's relative noise."""
MARGIN = 0.15
REFINE = 3
"""Rounds after the zooms in which the checks (converged designs at the best fit and the interval ends) become
nodes and are checked anew, while the interpolation's error is above :data:`LOO_PER_NOISE` of the noise."""


@dataclass(frozen=True)
class Calibration:
    problem: object
    fit: object
    model: object = field(repr=False)
    bands: tuple = field(repr=False)
    plot_pressures: tuple = field(repr=False)
    surrogate_error: float = math.nan
    surrogate_ok: bool = False
    nodes_solved: int = 0
    nodes_cached: int = 0
    nodes_failed: tuple = ()
    seconds: float = 0.0
    zooms: int = 0
    refinements: int = 0
    warnings: tuple = ()


def _say(progress, text):
    if progress is not None:
        progress(text)


def plan_calibration(designs, data, free=None, bounds=None, noise="relative", voc="eq12", solver=None):
    """The checked :class:`tengsim.calibrate.problem.Problem`.  ``designs``: one per curve (or one for all), each a
    design's table, a (label, table) pair (the CLI's: the file read at the edge, named by its path) or a design TOML
    path; every table taken by the one reading of a design's tables (:func:`tengsim.design.design_table`);
    ``data``: CSV paths or :class:`Curve` s; ``solver``: the designs' solver (a design's ``solver`` key; None: as
    the design files say)."""
    from tengsim.calibrate.data import Curve, read_curve
    from tengsim.calibrate.problem import (DEFAULT_BOUNDS, NOISES, PARAMS, VOC_MODELS, Problem, check_reachable,
                                           count_check, parse_bounds, parse_free, text)
    from tengsim.design import plan_design, read_design
    from tengsim.run.refine import check_solver

    designs, data = list(designs), list(data)
    if not data:
        raise TengsimError("--data: give at least one measured curve (CSV)")
    if len(designs) == 1 and len(data) > 1:
        designs = designs * len(data)
    if len(designs) != len(data):
        raise TengsimError(f"{len(designs)} designs for {len(data)} measured curves: give one design per curve "
                           "(or one for all)")
    if noise not in NOISES:
        raise TengsimError(f"--noise {noise!r}: relative or absolute")
    if voc not in VOC_MODELS:
        raise TengsimError(f"--voc {voc!r}: eq12 or eq17")
    free = parse_free(free)
    user = parse_bounds(bounds, free)
    bnds = {k: user.get(k, DEFAULT_BOUNDS[k]) for k in PARAMS}
    from tengsim.design import design_table

    tables, names = [], []
    for d in designs:
        if isinstance(d, tuple) and len(d) == 2 and isinstance(d[1], dict):
            name, t = str(d[0]), design_table(d[1], str(d[0]))
        elif isinstance(d, dict):
            t = design_table(d)
            name = t.get("name", t.get("shape"))
        else:
            name, t = str(d), read_design(d)
        if solver is not None:
            t["solver"] = solver
        tables.append(t)
        names.append(name)
    # the material: fixed values from the designs (one material), starting values for the free ones
    fixed = {}
    for k in PARAMS:
        vals = set()
        for where, t in zip(names, tables):
            if t.get(k) not in (None, ""):
                from tengsim.calibrate.problem import KINDS
                from tengsim.units import parse_quantity

                try:
                    vals.add(round(parse_quantity(t[k], KINDS[k], k), 15))
                except TengsimError as exc:
                    raise TengsimError(f"{where}: {exc}") from None
        if k in free:
            continue
        if k == "sigma" and not vals:
            from tengsim.design import PAPER_DEVICE

            vals = {PAPER_DEVICE["sigma"]}
        if not vals:
            raise TengsimError(f"{k} is neither free nor given in the designs: give it in the design files or add "
                               f"it to --free")
        if len(vals) > 1:
            raise TengsimError(f"the designs give different {k} ({', '.join(text(k, v) for v in sorted(vals))}): one "
                               f"material is fitted; give one value or free it")
        fixed[k] = vals.pop()
    E_ref = fixed.get("E_star", math.sqrt(bnds["E_star"][0] * bnds["E_star"][1]))
    mid = {k: math.sqrt(bnds[k][0] * bnds[k][1]) for k in ("W", "eps")}
    plans = []
    for where, t in zip(names, tables):
        probe = {**t, "W": fixed.get("W", mid["W"]), "eps": fixed.get("eps", mid["eps"]), "E_star": E_ref}
        if "p_max" not in probe:
            probe["p_max"] = 1e3
        try:
            plan = plan_design(probe, f"{where}: ")
        except SolverUnavailable:  # a solver this machine lacks is not the design's fault: said as it is
            raise
        except TengsimError as exc:
            raise TengsimError(f"{exc} (not a design tengsim design accepts)") from None
        check_solver(plan.contact_plan)  # as tengsim design does: a solver missing here refused before any node
        plans.append(plan)
    curves = [c if isinstance(c, Curve) else read_curve(c) for c in data]
    prob = Problem(tuple(plans), tuple(tables), tuple(curves), free, bnds, fixed, noise, voc, E_ref, tuple(names))
    count_check(prob)
    check_reachable(prob)
    return prob


def _node_ranges(prob):
    """(u range, v range, dims): log W_eff and log ε over the bounds (a fixed axis: its value)."""
    lw = [math.log(x) for x in (prob.bounds["W"] if "W" in prob.free else (prob.fixed["W"],) * 2)]
    le = [math.log(x) for x in (prob.bounds["E_star"] if "E_star" in prob.free else (prob.fixed["E_star"],) * 2)]
    lr = math.log(prob.E_ref)
    u = (lw[0] + lr - le[1], lw[1] + lr - le[0])
    v = tuple(math.log(x) for x in (prob.bounds["eps"] if "eps" in prob.free else (prob.fixed["eps"],) * 2))
    dims = tuple(k for k, r in enumerate((u, v)) if r[1] > r[0] + 1e-12)
    return u, v, dims


def _p_max(prob, key, geo):
    from tengsim.calibrate.surrogate import nice_up

    top = max(float(c.pressure.max()) for c, g in zip(prob.curves, geo) if g == key)
    if "E_star" not in prob.free:  # λ = 1: the nodes' pressures can be the data's own (a step of p_max/20)
        return nice_up(top)
    return nice_up(1.05 * top * prob.E_ref / prob.bounds["E_star"][0])


def calibrate(prob, out_dir, n_nodes: int = 4, zooms: int = 2, progress=None, refine: int = REFINE,
              expected_noise=None) -> Calibration:
    """Run the calibration of the checked problem ``prob`` (module doc); nodes kept in ``out_dir/designs``, which
    the run holds locked (:func:`tengsim.outfolder.folder_lock`): two calibrations never share their designs.
    ``expected_noise``: the data's noise as known beforehand, in the noise model's unit (a fraction of V_OC for
    the relative model, volts for the absolute), for the warning when the fit's is much larger."""
    from tengsim.outfolder import folder_lock

    with folder_lock(Path(out_dir) / "designs", what="the designs folder", holder="tengsim calibrate"):
        return _calibrate(prob, out_dir, n_nodes, zooms, progress, refine, expected_noise)


def _calibrate(prob, out_dir, n_nodes, zooms, progress, refine, expected_noise) -> Calibration:
    from tengsim.calibrate.checks import expected_designs, interpolation_error
    from tengsim.calibrate.fit import Model, band, fit, residual_text
    from tengsim.calibrate.surrogate import (POINTS_PER_CURVE, Surrogate, geometry_key, grid_points, node_table,
                                             solve_node)
    from tengsim.units import time_text
    importlib.import_module("tengsim.design.write")  # its imports (xarray) before the first design is timed

    t0 = time.perf_counter()
    folder = Path(out_dir) / "designs"
    geo = tuple(geometry_key(t) for t in prob.tables)
    keys = list(dict.fromkeys(geo))
    base = {k: _branches(prob.tables[geo.index(k)],
                         any("retraction" in c.branch for c, g in zip(prob.curves, geo) if g == k)) for k in keys}
    pmax = {k: _p_max(prob, k, geo) for k in keys}
    (u0, u1), (v0, v1), dims = _node_ranges(prob)
    span = (max(u1 - u0, 1e-12), max(v1 - v0, 1e-12))
    surr = {k: Surrogate(np.linspace(0, pmax[k], POINTS_PER_CURVE), [], span, dims) for k in keys}
    count = {"solved": 0, "cached": 0, "seconds": 0.0, "batch": 0}
    failed = []
    batches, most = expected_designs(prob, n_nodes, zooms, refine, len(dims), len(keys))
    _say(progress, f"the calibration: about {sum(batches)} designs (at most {most}: every zoom and refinement); its "
                   "time is said after the first design, measured on this machine as loaded now")

    def whole(extra: int) -> str:
        """The rest of the whole calibration at the time per design measured so far (this machine's load)."""
        per = count["seconds"] / count["solved"]
        rest = extra + sum(batches[count["batch"]:])
        return (f"the whole calibration: about {time_text(per * rest)} more ({rest} designs expected at "
                f"{time_text(per)} each, measured; at most {time_text(per * max(most - count['solved'], rest))})")

    def solve(todo, title):
        from tengsim.calibrate.surrogate import node_key

        new = [x for x in todo if not (folder / f"{node_key(x[3])}.nc").is_file()
               and not (folder / f"{node_key(x[3])}.failed.txt").is_file()]
        count["batch"] += 1
        if new:
            _say(progress, f"{title}: {len(todo)} designs ({len(todo) - len(new)} kept in {folder}), {len(new)} to "
                           "solve" + (f"; {whole(len(new))}" if count["solved"] else ""))
        done_t, n_done, out = 0.0, 0, []
        for m, (k, u, v, table) in enumerate(todo):
            node = solve_node(table, folder, u, v)
            out.append(node)
            if node.cached:
                count["cached"] += 1
            else:
                count["solved"] += 1
                count["seconds"] += node.seconds
                n_done += 1
                done_t += node.seconds
                left = done_t / n_done * (len(new) - n_done)
                _say(progress, f"design {m + 1}/{len(todo)} (W {math.exp(u) * 1e3:.4g} mJ/m², ε "
                               f"{math.exp(v) * 1e9:.4g} nm): {'ok' if node.ok else node.message} in "
                               f"{node.seconds:.0f} s; about {time_text(max(left, 0))} left of these"
                               + (f"; {whole(len(new) - n_done)}" if count["solved"] == 1 else ""))
            if not node.ok:
                failed.append(f"W {math.exp(u) * 1e3:.4g} mJ/m², ε {math.exp(v) * 1e9:.4g} nm: {node.message}")
        return out

    def grid(box, n=n_nodes):
        """Solve the n × n grid over ``box`` (nodes near one solved left out); the number of designs it added."""
        us = grid_points(*box[0], n if 0 in dims else 1)
        vs = grid_points(*box[1], n if 1 in dims else 1)
        du = (us[1] - us[0]) / span[0] if len(us) > 1 else 1.0
        dv = (vs[1] - vs[0]) / span[1] if len(vs) > 1 else 1.0
        todo = []
        for k in keys:
            have = [(n.u, n.v) for n in surr[k].nodes]
            for u in us:
                for v in vs:  # a node closer than a third of the new spacing to one solved: not solved again (two
                    # designs that close differ by their discretisation errors, which a spline would chase)
                    if not any(abs(u - a) / span[0] < du / 3 + 1e-12 and abs(v - b) / span[1] < dv / 3 + 1e-12
                               for a, b in have):
                        todo.append((k, u, v, node_table(base[k], math.exp(u), math.exp(v), prob.E_ref, pmax[k])))
        for (k, *_), node in zip(todo, solve(todo, "the (W, ε) grid")):
            surr[k].nodes.append(node)
            surr[k]._rbf.clear()
        return len(todo)

    box_uv = ((u0, u1), (v0, v1))
    grid(box_uv)
    model = Model(prob, surr, geo)
    result = _fit_in_box(model, fit)
    err, zoom, rounds = 0.0, 0, 0
    for zoom in range(zooms + 1):
        if not dims:
            break
        err, checks = interpolation_error(model, result, solve, base, pmax)
        if math.isfinite(err) and err <= LOO_PER_NOISE * result.scale or zoom == zooms:
            break
        box_uv = _region_box(model, result, ((u0, u1), (v0, v1)), box_uv)
        _say(progress, f"interpolation error {residual_text(err, prob)} (noise {residual_text(result.scale, prob)}):"
                       " zooming on the region that fits")
        n = n_nodes
        while not grid(box_uv, n) and n < 4 * n_nodes:  # the region is the box already solved (a fit too poor
            n = 2 * n - 1  # to narrow it): its grid at half the spacing, else the zoom would repeat the same fit
        model = Model(prob, surr, geo)
        result = _fit_in_box(model, fit)
    while dims and rounds < refine and not (math.isfinite(err) and err <= LOO_PER_NOISE * result.scale):
        rounds += 1  # the checks, converged designs where the fit lands, become nodes; checked anew
        _say(progress, f"interpolation error {residual_text(err, prob)} (noise {residual_text(result.scale, prob)}) "
                       f"after the zooms: the checks made nodes (refinement {rounds}/{refine})")
        for k, node in checks:
            sk = surr[k]
            if node.ok and not any(all(abs((n.u, n.v)[d] - (node.u, node.v)[d]) <= 1e-3 * sk.span[d]
                                       for d in sk.dims) for n in sk.nodes):
                sk.nodes.append(node)
                sk._rbf.clear()
        model = Model(prob, surr, geo)
        result = _fit_in_box(model, fit)
        err, checks = interpolation_error(model, result, solve, base, pmax)
    if math.isfinite(err) and err > 0:  # the intervals with room for the model's own error
        result = _fit_in_box(model, lambda m, box=None: fit(m, box, model_error=err))
    loo = err
    ok = bool(math.isfinite(loo) and loo <= LOO_PER_NOISE * result.scale)
    warn = warnings(prob, result, loo, expected_noise)
    result = dataclasses.replace(result, words=result.words + warn)
    solved, cached = count["solved"], count["cached"]
    P_plot = [np.linspace(0.0, float(c.pressure.max()), 61) for c in prob.curves]
    B_plot = [np.full(61, "approach" if "approach" in c.branch else c.branch[0]) for c in prob.curves]
    bands = band(model, result, P_plot, B_plot)
    return Calibration(prob, result, model, tuple(bands), tuple(P_plot), loo, ok, solved, cached,
                       tuple(dict.fromkeys(failed)), time.perf_counter() - t0, zoom, rounds, warn)


def _branches(table: dict, retraction: bool) -> dict:
    """The nodes' design table: the retraction solved only where a curve of the geometry was measured on it (the
    approach alone costs half)."""
    t = {k: v for k, v in table.items() if k != "retraction"}
    return t if retraction else {**t, "retraction": False}


NOISE_LARGE = 0.10
"""A fitted relative noise above this (10 % of V_OC) is warned of when no expected noise is given: larger than a
TENG bench measurement's usual few per cent, it says the model misses the data's shape."""
NOISE_RATIO = 2.0
"""A fitted noise more than this times the expected (or the stated errors') is warned of."""


def warnings(prob, f, err, expected=None) -> tuple:
    """Plain-word warnings: the fitted noise much larger than the data's stated or expected noise, the
    interpolation's error above the fitted noise."""
    from tengsim.calibrate.fit import residual_text

    out = []
    n, p = prob.n_points, len(prob.free)
    if prob.known_errors:
        s = math.sqrt(max(f.dev_min, 0.0) / max(n - p, 1))
        if s > NOISE_RATIO:
            out.append(f"Warning: the residuals are {s:.2g} × the stated errors (voc_err_V): the model does not "
                       "fit these data within their errors; the intervals assume it does.")
    elif expected is not None and f.scale > NOISE_RATIO * expected:
        out.append(f"Warning: the fitted noise {residual_text(f.scale, prob)} is {f.scale / expected:.2g} × the "
                   f"expected {residual_text(expected, prob)}: the model misses the data's shape by more than their "
                   "noise; the best values and intervals are those of a poor fit.")
    elif expected is None and prob.noise == "relative" and f.scale > NOISE_LARGE:
        out.append(f"Warning: the fitted noise {residual_text(f.scale, prob)} is large for a V_OC measurement: the "
                   "model may miss the data's shape; the best values and intervals are those of a poor fit.")
    if not math.isfinite(err) or err > f.scale:
        out.append(f"Warning: the interpolation's own error ({residual_text(err, prob)}, measured against designs "
                   f"solved where the fit lands) exceeds the fitted noise ({residual_text(f.scale, prob)}): the "
                   "model between designs, not the data, limits this fit; give more designs (--nodes, --zooms) or "
                   "tighter --bounds." + _tol_hint(prob, f.scale))
    return tuple(out)


def _tol_hint(prob, scale) -> str:
    """Where the designs' tol (their A/S to about that fraction) exceeds a relative noise: neighbouring designs then
    differ by their discretisation more than the data do, which no number of designs removes."""
    tols = [float(getattr(pl, "rel_tol", 0.0) or 0.0) for pl in getattr(prob, "plans", ())]
    tol = max(tols) if tols else 0.0
    if prob.known_errors or prob.noise != "relative" or not tol > scale:
        return ""
    return (f" The designs' tol {tol:g} (A/S to about {100 * tol:.3g} %) exceeds that noise: give the designs a tol "
            f"below it (e.g. tol = {_below(scale):g}).")


def _below(x: float) -> float:
    """A round number below x (1, 2 or 5 × a power of ten)."""
    e = 10 ** math.floor(math.log10(x))
    return max(m * e for m in (1, 2, 5) if m * e < x) if x > e else e / 2


def _fit_in_box(model, fit):
    """The fit on the bounds, then on the box of the region that fits (a finer grid there), grown while that
    region touches a side of the box that is not a bound."""
    from tengsim.calibrate.problem import log_bounds

    f = fit(model)
    lb = log_bounds(model.prob)
    if not len(lb):
        return f
    for _ in range(4):
        reg = f.grid_theta[f.grid_dev <= f.dev_min + 2 * f.threshold]
        if not len(reg):  # a region narrower than the grid (data the model fits exactly): its best point
            reg = f.theta[None, :]
        lo, hi = reg.min(axis=0), reg.max(axis=0)
        pad = np.maximum(MARGIN * (hi - lo), (f.box[:, 1] - f.box[:, 0]) / 40)
        box = np.stack([np.maximum(lo - pad, lb[:, 0]), np.minimum(hi + pad, lb[:, 1])], axis=1)
        g = fit(model, box)
        reg2 = g.grid_theta[g.grid_dev <= g.dev_min + g.threshold]
        step = (box[:, 1] - box[:, 0]) / 80
        touch = ((reg2.min(axis=0) <= box[:, 0] + step) & (box[:, 0] > lb[:, 0] + 1e-9)) | \
                ((reg2.max(axis=0) >= box[:, 1] - step) & (box[:, 1] < lb[:, 1] - 1e-9))
        f = g
        if not touch.any():
            break
    return f


def _uv(model, theta):
    ph = model.physical(theta)
    return np.log(ph["W"]) + math.log(model.prob.E_ref) - np.log(ph["E_star"]), np.log(ph["eps"])


def _region_box(model, f, full, prev):
    """The next grid's box in (log W_eff, log ε): the region that fits (deviance within twice the threshold,
    :data:`MARGIN` more on each side), at least half the previous box on each axis (an interpolation that is not
    yet within the noise may place the region wrongly; halving keeps the zoom from outrunning it), within the
    bounds."""
    reg = f.grid_theta[f.grid_dev <= f.dev_min + 2 * f.threshold]
    if not len(reg):
        reg = f.theta[None, :]
    u, v = _uv(model, reg)
    bu, bv = _uv(model, f.theta[None, :])
    out = []
    for vals, best, (lo, hi), (plo, phi) in zip((u, v), (bu[0], bv[0]), full, prev):
        a, b = float(vals.min()), float(vals.max())
        pad = max(MARGIN * (b - a), 0.02 * (hi - lo))
        a, b = a - pad, b + pad
        half = 0.5 * (phi - plo)
        if b - a < half:
            c = best
            a, b = c - 0.5 * half, c + 0.5 * half
        if a < lo:
            a, b = lo, min(hi, b + (lo - a))
        if b > hi:
            a, b = max(lo, a - (b - hi)), hi
        out.append((a, b))
    return tuple(out)


def say_to_stderr(quiet=False):
    return None if quiet else (lambda text: print(f"tengsim: {text}", file=sys.stderr, flush=True))
