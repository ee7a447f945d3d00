"""The fit on the model (:mod:`tengsim.calibrate.surrogate`): σ in closed form, the rest on a grid, profiles.

**Noise model.**  With a ``voc_err_V`` column the errors are taken as known: deviance = χ² = Σ r², r = (V − V_model)/err.
Otherwise one scale s is estimated for all curves: relative (default; r = (V − V_model)/max(V, 5 % of the largest V
of its curve)) or absolute (r = V − V_model, volts); deviance = n log Σ r² (the likelihood with s profiled out).

**σ.**  V_model = σ g(θ) (g: V_OC per unit σ, from A/S), so for each θ the best σ is Σ V g/w² / Σ g²/w², clipped to
its bounds: exact, no search.

**Intervals: profile likelihood.**  Few parameters (≤ 4) and a likelihood that is far from Gaussian (a bound that
is reached, a ridge along which W and ε trade off) make a profile the honest interval: each parameter's 95 % interval
is where its profile deviance rises by less than χ²₁(0.95) = 3.84 (known errors) or n log(1 + F₁,ₙ₋ₚ(0.95)/(n − p))
(estimated scale: the exact threshold for a linear model).  An interval that reaches a bound is said to be open
there: the data do not determine that side.

**Grid.**  The deviance is evaluated on a grid over the box that holds the region that fits (81² for two contact
parameters, 31³ for three), the best point polished by Nelder–Mead on the model; a profile is the minimum over the
other axes; σ's profile minimises the quadratic in σ at each grid point.  The correlation matrix is that of the log
parameters weighted by the likelihood on the grid (flat in log within the bounds), σ's conditional spread included.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tengsim.calibrate.problem import label, text

RELATIVE_FLOOR = 0.05
GRID = {1: 401, 2: 81, 3: 31}


@dataclass
class Model:
    """The problem and its surrogates, as one function of the log contact parameters."""

    prob: object
    surrogates: dict  # geometry key -> Surrogate
    geo: tuple  # geometry key of each curve

    def __post_init__(self):
        p = self.prob
        self.V = np.concatenate([c.voc for c in p.curves])
        self.P = [c.pressure for c in p.curves]
        if p.known_errors:
            self.w = np.concatenate([c.err for c in p.curves])
        elif p.noise == "relative":
            self.w = np.concatenate([np.maximum(c.voc, RELATIVE_FLOOR * c.voc.max()) for c in p.curves])
        else:
            self.w = np.ones(p.n_points)
        self.a = float(np.sum((self.V / self.w) ** 2))

    def physical(self, theta) -> dict:
        """{name: SI array} of log contact parameters ``theta`` (K, d), the fixed ones broadcast."""
        theta = np.atleast_2d(theta)
        out = {}
        for name in ("W", "eps", "E_star"):
            if name in self.prob.contact_free:
                out[name] = np.exp(theta[:, self.prob.contact_free.index(name)])
            else:
                out[name] = np.full(len(theta), self.prob.fixed[name])
        return out

    def g(self, theta, pressures=None, branches=None) -> list:
        """Per curve: V_OC per unit σ (K, n_i) at its data pressures (or ``pressures``/``branches`` lists)."""
        ph = self.physical(theta)
        u = np.log(ph["W"]) + math.log(self.prob.E_ref) - np.log(ph["E_star"])
        v = np.log(ph["eps"])
        lam = ph["E_star"] / self.prob.E_ref
        out = []
        for i, c in enumerate(self.prob.curves):
            P = c.pressure if pressures is None else pressures[i]
            B = c.branch if branches is None else branches[i]
            out.append(self.prob.factor(i) * self.surrogates[self.geo[i]].area(u, v, lam, P, B))
        return out

    def sums(self, theta):
        G = np.concatenate(self.g(theta), axis=1)
        b = (G * (self.V / self.w ** 2)).sum(axis=1)
        c = ((G / self.w) ** 2).sum(axis=1)
        return b, c

    def sigma_hat(self, b, c):
        p = self.prob
        s = np.where(c > 0, b / np.maximum(c, 1e-300), p.bounds["sigma"][0] if "sigma" in p.free else 0)
        if "sigma" in p.free:
            return np.clip(s, *p.bounds["sigma"])
        return np.full_like(b, p.fixed["sigma"])

    def dev_from_rss(self, rss):
        rss = np.maximum(rss, 1e-300)
        return rss if self.prob.known_errors else self.prob.n_points * np.log(rss)

    def rss_from_dev(self, dev):
        # capped below float overflow: a threshold widened for a large interpolation error can exceed it
        return dev if self.prob.known_errors else np.exp(np.minimum(dev / self.prob.n_points, 700.0))

    def deviance(self, theta):
        """(deviance (K,), σ̂ (K,)) at log parameters ``theta``."""
        b, c = self.sums(theta)
        s = self.sigma_hat(b, c)
        return self.dev_from_rss(self.a - 2 * s * b + s * s * c), s


def inflation(n: int, model_error: float, scale: float) -> float:
    """The factor on the interval threshold that makes room for the model's own error e (the interpolation's
    leave-one-out error, which includes each node's discretisation error): an error common to all n points moves the
    best fit as much as noise of e √n per point would, so the threshold (a deviance, ∝ 1/s²) grows by 1 + n e²/s²."""
    if not (model_error > 0 and math.isfinite(model_error)):
        return 1.0
    return 1.0 + n * (model_error / scale) ** 2


def threshold(prob) -> float:
    """The profile deviance rise of a 95 % interval (module doc)."""
    from scipy import stats

    if prob.known_errors:
        return float(stats.chi2.ppf(0.95, 1))
    n, p = prob.n_points, len(prob.free)
    dof = max(n - p, 1)
    return float(n * math.log1p(stats.f.ppf(0.95, 1, dof) / dof))


@dataclass(frozen=True)
class Fit:
    """A fit's numbers (SI): ``best`` {name: value}, ``interval`` {name: (lo, hi, open_lo, open_hi)},
    ``profile`` {name: (values, deviance rise)}, ``names``/``corr`` (the correlation matrix of the log parameters),
    ``threshold``, ``dev_min``, ``scale`` (the noise: relative fraction, volts, or 1 with known errors),
    ``words`` (identifiability in plain words), ``region`` (log contact parameters of the grid points that fit
    jointly), ``box`` the grid's box."""

    best: dict
    interval: dict
    profile: dict
    names: tuple
    corr: np.ndarray
    threshold: float
    dev_min: float
    scale: float
    words: tuple
    region: np.ndarray
    box: np.ndarray
    theta: np.ndarray
    grid_theta: np.ndarray
    grid_dev: np.ndarray
    grid_sigma: np.ndarray


def _grid(box, n):
    axes = [np.linspace(lo, hi, n) for lo, hi in box]
    mesh = np.meshgrid(*axes, indexing="ij")
    return axes, np.stack([m.ravel() for m in mesh], axis=1)


def _crossing(vals, prof, thr, k_best):
    """(lo, hi, open_lo, open_hi) of {prof <= thr} around index k_best, linear between grid points."""
    inside = prof <= thr
    i = k_best
    while i > 0 and inside[i - 1]:
        i -= 1
    j = k_best
    while j < len(vals) - 1 and inside[j + 1]:
        j += 1

    def cut(a, b):  # a inside, b outside
        fa, fb = prof[a] - thr, prof[b] - thr
        return vals[a] + (vals[b] - vals[a]) * (fa / (fa - fb)) if fb != fa else vals[a]

    lo = vals[0] if i == 0 and inside[0] else cut(i, i - 1)
    hi = vals[-1] if j == len(vals) - 1 and inside[-1] else cut(j, j + 1)
    return lo, hi, bool(i == 0 and inside[0]), bool(j == len(vals) - 1 and inside[-1])


def fit(model: Model, box=None, polish: bool = True, model_error: float = 0.0) -> Fit:
    """The fit (module doc) on the box (d, 2) of log contact parameters (default: their bounds).  ``model_error``:
    the model's own error (rms, residual units), taken as an error common to every point
    (:func:`inflation`)."""
    from scipy.optimize import minimize

    from tengsim.calibrate.problem import log_bounds

    prob = model.prob
    names = prob.contact_free
    d = len(names)
    thr = threshold(prob)
    lb = log_bounds(prob)
    box = lb.copy() if box is None else np.asarray(box, float)
    if d:
        axes, pts = _grid(box, GRID[d])
    else:
        axes, pts = [], np.zeros((1, 0))
    dev, sig = model.deviance(pts)
    k = int(np.argmin(dev))
    theta, dmin = pts[k], float(dev[k])
    if polish and d:
        f = lambda t: float(model.deviance(np.clip(t, lb[:, 0], lb[:, 1])[None, :])[0][0])  # noqa: E731
        r = minimize(f, theta, method="Nelder-Mead", options={"xatol": 1e-5, "fatol": 1e-9, "maxiter": 400})
        if r.fun < dmin:
            theta, dmin = np.clip(r.x, lb[:, 0], lb[:, 1]), float(r.fun)
    best_dev, best_sig = model.deviance(theta[None, :])
    best = {"sigma": float(best_sig[0]), **{n: float(v[0]) for n, v in model.physical(theta[None, :]).items()}}
    n, p = prob.n_points, len(prob.free)
    rss_min = float(model.rss_from_dev(dmin))
    scale = 1.0 if prob.known_errors else math.sqrt(rss_min / max(n - p, 1))
    thr *= inflation(n, model_error, scale)
    # profiles of the contact parameters: min over the other axes
    profile, interval = {}, {}
    shape = tuple(len(a) for a in axes)
    D = dev.reshape(shape) if d else dev
    for j, name in enumerate(names):
        other = tuple(a for a in range(d) if a != j)
        prof = (D.min(axis=other) if other else D) - dmin
        kb = int(np.argmin(prof))
        lo, hi, olo, ohi = _crossing(axes[j], prof, thr, kb)
        olo = olo and box[j, 0] <= lb[j, 0] + 1e-9
        ohi = ohi and box[j, 1] >= lb[j, 1] - 1e-9
        profile[name] = (np.exp(axes[j]), np.maximum(prof, 0.0))
        interval[name] = (math.exp(lo), math.exp(hi), olo, ohi)
    # sigma: RSS(s, θ) = a - 2 s b + s² c, minimised over the grid at each s
    b, c = model.sums(pts)
    if "sigma" in prob.free:
        s0 = best["sigma"]
        slo, shi = prob.bounds["sigma"]
        svals = np.exp(np.linspace(math.log(max(slo, s0 / 3)), math.log(min(shi, s0 * 3)), 401))
        prof = np.array([float(np.min(model.dev_from_rss(model.a - 2 * s * b + s * s * c))) for s in svals]) - dmin
        lo, hi, olo, ohi = _crossing(np.log(svals), prof, thr, int(np.argmin(prof)))
        profile["sigma"] = (svals, np.maximum(prof, 0.0))
        interval["sigma"] = (math.exp(lo), math.exp(hi), olo and svals[0] <= slo * (1 + 1e-9),
                             ohi and svals[-1] >= shi * (1 - 1e-9))
    extended = []
    for name, (lo, hi, olo, ohi) in list(interval.items()):  # the best value always inside its own interval
        v = best[name]
        if not lo <= v <= hi:
            extended.append(name)
            interval[name] = (min(lo, v), max(hi, v), olo, ohi)
    region = pts[dev <= dmin + thr] if d else pts
    cnames, corr = _correlation(model, pts, dev, dmin, b, c, scale)
    fitres = Fit(best, interval, profile, cnames, corr, thr, dmin, scale, (), region, box, theta, pts, dev, sig)
    words = tuple(identifiability(fitres, prob))
    grow = inflation(n, model_error, scale)
    if grow > 1.5:
        words += (f"These intervals are widened ×{math.sqrt(grow):.2g} for the interpolation's own error "
                  f"({residual_text(model_error, prob)} against the noise {residual_text(scale, prob)}): "
                  "with more designs (--nodes, --zooms, tighter "
                  "--bounds) they narrow to what the data alone allow.",)
    if extended:
        words += (f"The best fit lay outside the grid's profile interval of {', '.join(extended)}: the interval "
                  "was extended to hold it. The interpolation between designs is not smooth enough here to trust "
                  "these intervals: give more designs (--nodes, --zooms) or tighter --bounds.",)
    return Fit(best, interval, profile, cnames, corr, thr, dmin, scale, words, region, box, theta, pts, dev, sig)


def _correlation(model, pts, dev, dmin, b, c, scale):
    """Correlation of the log parameters under the likelihood on the grid (module doc)."""
    prob = model.prob
    wts = np.exp(-0.5 * (dev - dmin))
    wts = wts / wts.sum()
    cols, names = [], []
    extra_var = None
    if "sigma" in prob.free:
        s = np.maximum(model.sigma_hat(b, c), 1e-300)
        cols.append(np.log(s))
        with np.errstate(over="ignore", divide="ignore", invalid="ignore"):  # c = 0: no charged area, no σ
            extra_var = (scale ** 2 / np.maximum(c, 1e-300)) / s ** 2
        names.append("sigma")
    for j, name in enumerate(prob.contact_free):
        cols.append(pts[:, j])
        names.append(name)
    if not cols:
        return (), np.zeros((0, 0))
    X = np.stack(cols, axis=1)
    mean = wts @ X
    Xc = X - mean
    cov = (Xc * wts[:, None]).T @ Xc
    if extra_var is not None:
        live = wts > 0  # points of no weight add nothing (an infinite variance at one of them included)
        cov[0, 0] += float(wts[live] @ extra_var[live])
    sd = np.sqrt(np.maximum(np.diag(cov), 1e-300))
    with np.errstate(invalid="ignore"):
        corr = cov / np.outer(sd, sd)
    corr[~np.isfinite(corr)] = 0.0  # an unbounded variance: no linear trade-off to report
    np.fill_diagonal(corr, 1.0)
    return tuple(names), corr


def identifiability(f: Fit, prob) -> list:
    """Plain words: what each parameter is, the range that fits, and the trade-offs (|correlation| > 0.9)."""
    out = []
    for name in prob.free:
        lo, hi, olo, ohi = f.interval[name]
        L = label(name)
        if olo and ohi:
            out.append(f"{L} is not determined by these data: every {L} within the bounds {text(name, lo)} to "
                       f"{text(name, hi)} fits within the noise.")
        elif olo:
            out.append(f"{L} is not determined from below by these data: every {L} below {text(name, hi)} fits "
                       f"within the noise (down to the bound {text(name, lo)}).")
        elif ohi:
            out.append(f"{L} is not determined from above by these data: every {L} above {text(name, lo)} fits "
                       f"within the noise (up to the bound {text(name, hi)}).")
        else:
            best = f.best[name]
            out.append(f"{L} is determined: {text(name, best)}, 95 % {text(name, lo)} to {text(name, hi)} "
                       f"({100 * (hi - lo) / 2 / best:.2g} % half-width).")
    names = list(f.names)
    for i in range(len(names)):
        for j in range(i + 1, len(names)):
            r = float(f.corr[i, j])
            if abs(r) > 0.9:
                k = _slope(f, prob, names[i], names[j])
                a, b = label(names[i]), label(names[j])
                if k is not None and math.isfinite(k):
                    expo = f"{b}^{-k:.2g}" if abs(k) > 1e-3 else b
                    out.append(f"{a} and {b} trade off along {a}·{expo} ≈ const (correlation {r:+.2f}): the data fix "
                               f"that combination better than either alone.")
                else:
                    out.append(f"{a} and {b} trade off (correlation {r:+.2f}).")
    return out


def _slope(f: Fit, prob, x, y):
    """d log x / d log y along the region that fits (least squares over its grid points)."""
    def col(name):
        if name == "sigma":
            return None
        return f.region[:, prob.contact_free.index(name)]

    if "sigma" in (x, y):
        mask = f.grid_dev <= f.dev_min + f.threshold
        cx = np.log(f.grid_sigma[mask]) if x == "sigma" else f.grid_theta[mask][:, prob.contact_free.index(x)]
        cy = np.log(f.grid_sigma[mask]) if y == "sigma" else f.grid_theta[mask][:, prob.contact_free.index(y)]
    else:
        cx, cy = col(x), col(y)
    if cx is None or len(cx) < 3 or np.ptp(cy) == 0:
        return None
    return float(np.polyfit(cy, cx, 1)[0])


def band(model: Model, f: Fit, pressures, branches, level_threshold=None) -> tuple:
    """Per curve (best, lower, upper) V_OC at ``pressures`` (list per curve): the envelope over the grid points and σ
    inside the 95 % profile region (deviance within the threshold of the minimum)."""
    thr = f.threshold if level_threshold is None else level_threshold
    mask = f.grid_dev <= f.dev_min + thr
    pts = f.grid_theta[mask] if f.grid_theta.shape[1] else f.grid_theta
    if not len(pts):  # a region narrower than the grid: the best point
        pts = f.theta[None, :]
    if len(pts) > 4000:
        pts = pts[np.random.default_rng(0).choice(len(pts), 4000, replace=False)]
    b, c = model.sums(pts)
    R = float(model.rss_from_dev(f.dev_min + thr))
    # σ range at each θ: a - 2 s b + s² c <= R
    disc = np.maximum(b * b - c * (model.a - R), 0.0)
    s_lo, s_hi = (b - np.sqrt(disc)) / np.maximum(c, 1e-300), (b + np.sqrt(disc)) / np.maximum(c, 1e-300)
    if "sigma" not in model.prob.free:
        s_lo = s_hi = np.full(len(pts), model.prob.fixed["sigma"])
    else:
        s_lo, s_hi = (np.clip(s, *model.prob.bounds["sigma"]) for s in (s_lo, s_hi))
    G = model.g(pts, pressures, branches)
    Gb = model.g(f.theta[None, :], pressures, branches)
    out = []
    for gi, gb in zip(G, Gb):
        out.append((f.best["sigma"] * gb[0], np.min(s_lo[:, None] * gi, axis=0), np.max(s_hi[:, None] * gi, axis=0)))
    return out


def residual_text(x: float, prob) -> str:
    """A size in the residual's units, said in the user's: % of V_OC (relative noise), volts (absolute), or
    multiples of the data's own voc_err_V (known errors)."""
    if prob.known_errors:
        return f"{x:.3g} × voc_err_V"
    if prob.noise == "relative":
        return f"{100 * x:.3g} % of V_OC"
    return f"{x:.3g} V"
