"""Where a calibration measures its interpolation's error: check designs solved at the best fit, at each interval's
ends and half-way beyond them, compared with the interpolation there (:func:`interpolation_error`, used by
:func:`tengsim.calibrate.run.calibrate`)."""
from __future__ import annotations

import math

import numpy as np


def expected_designs(prob, n_nodes: int, zooms: int, refine: int, dims: int, geometries: int) -> tuple:
    """([designs of each batch expected], at most): the first grid (``n_nodes`` per varying axis, per geometry) and
    its checks (:func:`check_points`: the best fit and, per free contact parameter, both interval ends and half-way
    beyond each), a grid and its checks per zoom, and the checks of half the refinement rounds (rounded up: the
    README's calibration made 2 of 3, 34 designs); at most, every refinement's.  A zoom's grid leaves out nodes near
    solved ones, and the zooms stop once the interpolation is within half the noise: the expected count is the
    usual run's, not a bound."""
    if not dims:
        return [geometries], geometries
    grid = n_nodes ** dims * geometries
    checks = (1 + 4 * len(prob.contact_free)) * geometries
    batches = [grid, checks] * (1 + zooms) + [checks] * ((refine + 1) // 2)
    return batches, sum(batches) + checks * (refine - (refine + 1) // 2)


def check_points(f, prob) -> list:
    """Log contact parameters where the interpolation is checked: the best fit and, for each free contact
    parameter, both ends of its 95 % interval (the others at their profile optimum there): a check at the best fit
    alone can sit on a design, where the interpolation is exact however wrong it is between designs (a curve that
    turns from partial to full contact between two of them)."""
    pts = [f.theta]
    for j, name in enumerate(prob.contact_free):
        axis = f.grid_theta[:, j]
        for end in f.interval[name][:2]:
            t = math.log(end)
            near = np.flatnonzero(np.abs(axis - t) <= np.min(np.abs(axis - t)) + 1e-12)
            p = f.grid_theta[near[np.argmin(f.grid_dev[near])]]
            if all(np.max(np.abs(p - q)) > 1e-6 for q in pts):
                pts.append(p)
    return pts


def interpolation_error(model, f, solve, base, pmax):
    """The interpolation's error, measured: at each of :func:`check_points` each geometry's design is solved (a
    check, not a node: kept in designs/ but not interpolated), its A/S at the data pressures against the
    interpolation's, as residuals (σ̂ × factor × ΔA / weight); (the largest over the points of the rms over the
    data points, [(geometry key, check design)])."""
    from tengsim.calibrate.surrogate import node_table

    keys = list(dict.fromkeys(model.geo))
    pts = check_points(f, model.prob)
    todo, where = [], []
    first = model.surrogates[keys[0]]
    best = None
    for theta in pts:
        ph = model.physical(theta[None, :])
        u = float(np.log(ph["W"][0]) + math.log(model.prob.E_ref) - np.log(ph["E_star"][0]))
        v, lam = float(np.log(ph["eps"][0])), float(ph["E_star"][0] / model.prob.E_ref)
        if best is None:
            best = (u, v)
            spots = [(u, v)]
        else:
            spots = _outward(first, (u, v), best)
        for u, v in spots:
            where.append((u, v, lam))
            todo += [(k, u, v, node_table(base[k], math.exp(u), math.exp(v), model.prob.E_ref, pmax[k]))
                     for k in keys]
    nodes = solve(todo, f"checks at the best fit, the interval ends and beyond them ({len(where)} points)")
    worst = 0.0
    for m, (u, v, lam) in enumerate(where):
        got = dict(zip(keys, nodes[m * len(keys):(m + 1) * len(keys)]))
        errs, off = [], 0
        for i, c in enumerate(model.prob.curves):
            node = got[model.geo[i]]
            w = model.w[off:off + c.n]
            off += c.n
            if not node.ok:
                continue
            sur = _without_node_at(model.surrogates[model.geo[i]], u, v).area(u, v, lam, c.pressure, c.branch)[0]
            own = np.array([node.area_at(b, [p / lam])[0] for p, b in zip(c.pressure, c.branch)])
            errs.append(f.best["sigma"] * model.prob.factor(i) * (sur - own) / w)
        if errs:
            worst = max(worst, float(np.sqrt(np.mean(np.concatenate(errs) ** 2))))
    checks = [(k, node) for m in range(len(where)) for k, node in zip(keys, nodes[m * len(keys):(m + 1) * len(keys)])]
    return worst, checks


def _outward(s, uv, best) -> list:
    """Where to check the interpolation at an interval's end ``uv`` (log W_eff, log ε): there (unless a node is
    there already: its value is exact) and half-way from it to the nearest node beyond it, away from the ``best``
    fit (none beyond: an end at a bound).  The interval's end is where the model starts to miss the data, often at the
    edge of the nodes, and its error there comes from the gap beyond: checking only at the end, which then becomes a
    node, moves the end a little further each round and never closes the gap; the half-way check does."""
    if not s.dims:
        return [uv]
    at_node = any(all(abs((n.u, n.v)[k] - uv[k]) <= 1e-6 * s.span[k] for k in s.dims) for n in s.good())
    out = [] if at_node else [uv]
    d = np.array([(uv[k] - best[k]) / s.span[k] for k in s.dims])
    if not np.any(d):
        return out or [uv]
    d /= np.linalg.norm(d)
    beyond = []
    for n in s.good():
        step = np.array([((n.u, n.v)[k] - uv[k]) / s.span[k] for k in s.dims])
        if step @ d > 1e-6:
            beyond.append((float(np.linalg.norm(step)), n))
    if beyond:
        n = min(beyond, key=lambda x: x[0])[1]
        out.append(tuple(0.5 * (uv[k] + (n.u, n.v)[k]) if k in s.dims else uv[k] for k in (0, 1)))
    return out


def _without_node_at(s, u, v):
    """The surrogate ``s`` less its nodes at (u, v) (a check where a node already is is measured from the others,
    else it would be exact there however wrong the interpolation is between nodes)."""
    from tengsim.calibrate.surrogate import Surrogate

    near = [n for n in s.nodes if all(abs((n.u, n.v)[d] - (u, v)[d]) <= 1e-6 * s.span[d] for d in s.dims)]
    if not near or len(near) == len(s.good()):
        return s
    return Surrogate(s.pressures, [n for n in s.nodes if not any(n is x for x in near)], s.span, s.dims, s.interp)
