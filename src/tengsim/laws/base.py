"""Surface interaction laws: pressure P(g) and energy per area Φ(g) of the gap g = H + 1 = h/ε.

Positive P is repulsive and P = −dΦ/dg.  Units: P in W/ε, Φ in W (paper Eq. 7).

A law is a pure formula: ``evaluate`` gives its own Φ and P at every gap.  ``g_safe`` declares how far
down the formula is used in a solve: the solvers evaluate the law through the wrapper
:class:`tengsim.laws.safe.SafeLaw`, which continues P linearly below g_safe (a solver's line search may
try g <= 0); physical equilibria never reach g_safe.  States are always judged by the residual of Eq. (9).

Every law also declares its own numbers (:class:`Law`, "declared numbers"): its maximum tension, the
gaps of that peak and of zero load, its work of adhesion, its cohesive range and its steepest
softening.  The built-in laws give them in closed form; the base class finds them numerically, once
per law, for a law that does not.
"""
from __future__ import annotations

import dataclasses
from functools import cached_property

import numpy as np

from tengsim.errors import TengsimError, positive
from tengsim.registry import LAWS


class Law:
    """Base class: subclasses give the raw law for g >= g_safe via ``_raw(g) -> (Φ, P, dP/dg)``.

    A law's fields (its dataclass fields, or constructor arguments) are ``[contact]`` keys of a run
    with that law (:func:`tengsim.run.keys.law_fields`), except the numerical guards named in
    ``internal_fields``; ``field_help`` gives a key its help text (with its unit: W and ε).

    Declared numbers (units W and ε; what :mod:`tengsim.status` reads): ``max_tension`` σ0 = −min P
    (W/ε), ``g_peak`` (the smallest gap where P = −σ0), ``g_zero`` g0 (P(g0) = 0, the last zero below
    g_peak: the contact gap), ``work`` W = −Φ(g0) (W), ``cohesive_range`` h0 = W/σ0 (ε),
    ``max_softening`` max dP/dg over g_peak <= g <= g0 + 2 h0 (W/ε², the stiffest softening beyond the
    peak) and ``g_safe`` (below it a solve uses the safe extension, :class:`tengsim.laws.safe.SafeLaw`).  A law without tension has ``max_tension`` =
    ``work`` = ``max_softening`` = 0 and ``g_peak`` = ``g_zero`` = ``cohesive_range`` = None.  A
    subclass overrides them with closed forms where it knows them; otherwise the base class finds them
    numerically from ``evaluate`` and ``_raw``'s dP/dg, once per law (:func:`numeric_window`,
    :func:`numeric_softening`).
    """

    g_safe: float
    internal_fields = ("g_safe",)
    field_help = {}

    def _raw(self, g, need_dp=True, xp=np):  # pragma: no cover - abstract
        """(Φ, P, dP/dg) at g >= g_safe; ``xp`` the array namespace (numpy, or jax.numpy when traced by
        the JAX solver, tengsim.solvers.jax_fast: a law whose ``_raw`` takes ``xp`` runs there too)."""
        raise NotImplementedError

    def evaluate(self, g: np.ndarray):
        """Return (Φ, P) at gaps g (arrays of g's shape): the law's formula, at any gap."""
        phi, p, _ = self._raw(np.asarray(g, dtype=float), need_dp=False)
        return phi, p

    def evaluate_xp(self, g, xp):
        """(Φ, P) at gaps g in the array namespace ``xp`` (jax.numpy inside a jit-compiled solver)."""
        phi, p, _ = self._raw(g, need_dp=False, xp=xp)
        return phi, p

    def energy_pressure(self, g: np.ndarray, out: np.ndarray, work):
        """ΣΦ(g), writing P(g) into ``out``: the solvers' hot path (``work``: two scratch arrays).  The sum
        is a backend scalar, left on the device (the solver brings a sweep's sums to the host at once)."""
        phi, p = self.evaluate(g)
        out[...] = p
        return phi.sum()

    def pressure(self, g):
        return self.evaluate(g)[1]

    def energy(self, g):
        return self.evaluate(g)[0]

    def stiffness(self, g):
        """−dP/dg = Φ''(g), the local interaction stiffness."""
        return -self._raw(np.asarray(g, dtype=float))[2]

    # ---- declared numbers: closed forms in the built-in laws, a cached numerical search here ----------

    @cached_property
    def _numeric_window(self):
        return numeric_window(self)

    @cached_property
    def _numeric_softening(self) -> float:
        if not self.max_tension > 0:
            return 0.0
        return numeric_softening(self, self.g_peak, self.g_zero + 2.0 * self.cohesive_range)

    @property
    def max_tension(self) -> float:
        """σ0 = −min P, the most tensile pressure (W/ε); 0 for a law without tension."""
        w = self._numeric_window
        return 0.0 if w is None else w[1]

    @property
    def g_peak(self) -> float | None:
        """The smallest gap where P = −σ0 (the tensile peak; a plateau's start); None without tension."""
        w = self._numeric_window
        return None if w is None else w[0]

    @property
    def g_zero(self) -> float | None:
        """The contact gap g0: P(g0) = 0, the last zero of P below ``g_peak``; None without tension."""
        w = self._numeric_window
        return None if w is None else w[2]

    @property
    def work(self) -> float:
        """The work of adhesion −Φ(g0) (W; 1 for the built-in laws); 0 for a law without tension."""
        w = self._numeric_window
        return 0.0 if w is None else w[3]

    @property
    def cohesive_range(self) -> float | None:
        """The Dugdale range h0 = W/σ0 of the law (ε); None without tension.  (Not the ``range`` field of
        :class:`~tengsim.laws.Exponential` or the property of :class:`~tengsim.laws.MaugisDugdale`.)"""
        s0 = self.max_tension
        return self.work / s0 if s0 > 0 else None

    @property
    def max_softening(self) -> float:
        """The stiffest softening beyond the tensile peak, max dP/dg over g_peak <= g <= g0 + 2 h0 (W/ε²);
        0 for a law without tension."""
        return self._numeric_softening

    @property
    def peak_separation(self) -> float:
        """The gap (ε) that bounds the charged contact area (:func:`tengsim.analysis.charged_area`): the
        separation of the law's peak tension ``g_peak`` (Greenwood's contact edge; for an axisymmetric
        contact the tensile-peak radius; a plateau's start: Maugis' contact radius a); for a law without
        tension, the gap 1 where its wall sets in (the paper's contact gap, P(1) = the wall's scale)."""
        g = self.g_peak
        return 1.0 if g is None else float(g)

    #: How the gap opens just outside the charged area's edge, g − g_peak ∝ s^edge_opening (s the distance
    #: from the edge): 1 where the gap crosses ``peak_separation`` with a slope (the peak lies beyond the
    #: contact gap: LJ 9-3, a wall without tension); 1.5 where the peak tension starts at the wall's edge
    #: (Maugis–Dugdale, exponential: the edge of a cohesive zone).  It locates the edge within a pixel.
    edge_opening = 1.0

    def hard_wall(self):
        """The law's hard-wall limit (:class:`tengsim.laws.cohesive.CohesiveLimit`: its traction, energy and
        curvature beyond a rigid wall at g = 1, and which constrained solver it prefers), or None for a law without
        one (the constrained solvers 'pk' and 'ram' and the design ask this, never the class)."""
        return None

    def params(self) -> dict:
        """The law's parameters (its dataclass fields; public attributes otherwise) and its class name."""
        if dataclasses.is_dataclass(self):
            d = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        else:
            d = {k: v for k, v in vars(self).items() if not k.startswith("_")}
        d["law"] = type(self).__name__
        return d


#: Peak tension of the LJ93 law, 16/(9√3) W/ε (at g = 3^{1/6}): the default stress of the other laws,
#: so that the Tabor parameter μ means the same for every built-in law.
LJ_PEAK_TENSION = 16.0 / (9.0 * 3.0**0.5)


def check_g_safe(law):
    """g_safe in (0, 1): the safe extension starts below the contact gap."""
    if not 0 < law.g_safe < 1:
        raise TengsimError(f"g_safe must lie in (0, 1), got {law.g_safe!r}")


def _check_common(law):
    positive("wall_stiffness", law.wall_stiffness)
    check_g_safe(law)


def _sqrt(x):
    """√x of a law parameter: a float here, a traced scalar in the JAX solver (no NumPy ufunc there)."""
    return np.sqrt(x) if isinstance(x, (int, float, np.number)) else x ** 0.5


def _wall(g, sigma, k, phi1, xp=np):
    """Linear wall for g < 1: P = −σ + k(1 − g), Φ = Φ(1) − σ(1 − g) + k(1 − g)²/2, dP/dg = −k.

    Continuous with a tension σ at g = 1; zero load at g = 1 − σ/k, where Φ = Φ(1) − σ²/(2k).
    """
    t = 1.0 - g
    return phi1 - sigma * t + 0.5 * k * t * t, -sigma + k * t, xp.zeros_like(g) - k


def numeric_window(law):
    """(g_peak, σ0, g0, W) of a law found numerically from ``law.evaluate`` and ``law.g_safe`` (None for a
    law without tension): the fallback for a law that declares no closed forms.  The most tensile of
    4001 geometric samples of [g_safe, 100] refined by a bounded search (on a plateau: a point near its
    start), the last sign change of P below it by root finding, W = −Φ(g0)."""
    from scipy.optimize import brentq, minimize_scalar

    def P(x):
        return float(law.evaluate(np.array([x]))[1][0])

    g = np.geomspace(max(float(law.g_safe), 1e-3), 100.0, 4001)
    p = np.asarray(law.evaluate(g)[1], dtype=float)
    i = int(np.argmin(p))
    if not p[i] < 0 or i == 0 or i == len(g) - 1:
        return None
    r = minimize_scalar(P, bounds=(g[i - 1], g[i + 1]), method="bounded", options={"xatol": 1e-12})
    g_peak, sigma0 = float(r.x), -float(r.fun)
    pos = np.flatnonzero(p[:i] > 0)
    if len(pos) == 0:
        return None
    j = int(pos[-1])
    g0 = float(brentq(P, g[j], g[j + 1], xtol=1e-14))
    work = -float(law.evaluate(np.array([g0]))[0][0])
    if not work > 0:
        return None
    return g_peak, sigma0, g0, work


def numeric_softening(law, g_lo: float, g_hi: float) -> float:
    """max dP/dg over [g_lo, g_hi], >= 0, found numerically: the fallback for a law that declares no
    closed form.  dP/dg is the law's own (−``law.stiffness``, from ``_raw``) where it has one, else a
    central difference of ``evaluate``; 20001 samples, the largest refined by a bounded search."""
    from scipy.optimize import minimize_scalar

    stiffness = getattr(law, "stiffness", None)
    if stiffness is None:
        def stiffness(x, h=1e-7):
            x = np.asarray(x, dtype=float)
            return -(law.evaluate(x + h)[1] - law.evaluate(x - h)[1]) / (2.0 * h)

    g = np.linspace(g_lo, g_hi, 20001)
    d = -np.asarray(stiffness(g), dtype=float)
    i = int(np.argmax(d))
    lo, hi = g[max(i - 1, 0)], g[min(i + 1, len(g) - 1)]
    r = minimize_scalar(lambda x: float(np.asarray(stiffness(np.array([x])))[0]), bounds=(lo, hi),
                        method="bounded", options={"xatol": 1e-12})
    return float(max(d[i], -float(r.fun), 0.0))


class WallLaw(Law):
    """A law whose linear wall (:func:`_wall`, stiffness ``wall_stiffness``) starts at g = 1 with its peak
    tension ``tension`` there (Maugis–Dugdale, exponential): the declared numbers these laws share.  The peak
    starts at the wall's edge g = 1, where a contact's gap opens as (r − a)^{3/2} (``edge_opening``)."""

    edge_opening = 1.5

    @property
    def max_tension(self) -> float:
        return self.tension

    @property
    def g_peak(self) -> float:
        return 1.0

    @property
    def g_zero(self) -> float:
        """Zero load on the wall: g0 = 1 − σ0/k."""
        return 1.0 - self.tension / self.wall_stiffness


def make_law(name: str, **params) -> Law:
    """Law by registered name or alias (see ``tengsim.registry.LAWS``): 'lj93' (the paper's), 'repulsive',
    'md' (Maugis–Dugdale) or 'exp' (exponential)."""
    return LAWS.get(name)(**params)

