"""Finite-thickness elastic film on a rigid substrate: the surface compliance of a layer.

A layer of thickness t (Poisson ratio ν, E* = E/(1 − ν²) as for the half-space) on a rigid substrate,
loaded by a normal surface pressure p̂(q), has the surface normal displacement

    ŵ(q) = (2 / (E* |q|)) · C(|q| t) · p̂(q),        C → 1 as |q| t → ∞ (the half-space, Eq. 9),

in tengsim's dimensionless form ŵ = (2κ/|q|) C(|q| T) P̂ (κ = μ^{3/2}, T = t in X units).  With
s = |q| t and κ_ν = 3 − 4ν (derived from the plane-strain Navier equations in the direction of q,
checked against the limits below):

* bonded (no slip at the substrate):
  C = [κ_ν sinh 2s − 2s] / [κ_ν cosh 2s + 2s² + (1 + κ_ν²)/2]
  (the classic layer result, e.g. Carbone & Mangialardi, J. Mech. Phys. Solids 56, 684 (2008));
  s → 0: C ≈ s (1 − 2ν) / (2 (1 − ν)²), i.e. ŵ/p̂ → t (1 + ν)(1 − 2ν) / (E (1 − ν)), the
  uniaxial-strain (oedometric) compliance t/M of the layer.
* frictionless substrate (no shear at the substrate): C = (cosh 2s − 1) / (sinh 2s + 2s), free of ν;
  s → 0: C ≈ s/2, i.e. ŵ/p̂ → t/E* (a thin layer that may slide spreads in plane strain).

The mean (q = 0) mode of a periodic film is uniform compression with zero mean in-plane strain
(the displacements are periodic), for either substrate: compliance t/M = t (1 + ν)(1 − 2ν)/(E (1 − ν)),
dimensionless κ T (1 − 2ν)/(1 − ν)².  It vanishes for an incompressible film (ν = 1/2).
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np

from tengsim.errors import TengsimError, positive
from tengsim.kernels.base import pixel_influence

SUBSTRATES = ("bonded", "frictionless")
_SERIES_S = 0.02  # below this s the closed forms lose digits to cancellation: Taylor series instead


def check_film(thickness, substrate: str = "bonded", poisson: float = 0.5):
    """Validated (thickness, substrate, poisson): thickness > 0, substrate bonded|frictionless, −1 < ν ≤ 1/2."""
    t = positive("thickness", thickness)
    if not isinstance(substrate, str) or substrate.strip().lower() not in SUBSTRATES:
        raise TengsimError(f"substrate must be one of {', '.join(SUBSTRATES)}, got {substrate!r}")
    try:
        nu = float(poisson)
    except (TypeError, ValueError):
        raise TengsimError(f"poisson must be a number, got {poisson!r}") from None
    if not (-1.0 < nu <= 0.5):
        raise TengsimError(f"poisson must be in (-1, 0.5], got {poisson!r}")
    return t, substrate.strip().lower(), nu


def _bonded_series(s, k):
    c1 = 4 * (k - 1) / (k + 1) ** 2
    c3 = 8 * (k - 3) * (k - 2) / (3 * (k + 1) ** 3)
    c5 = 8 * (k**3 - 28 * k**2 + 111 * k - 120) / (15 * (k + 1) ** 4)
    c7 = 16 * (k**4 - 123 * k**3 + 1529 * k**2 - 5067 * k + 5040) / (315 * (k + 1) ** 5)
    s2 = s * s
    return s * (c1 + s2 * (c3 + s2 * (c5 + s2 * c7)))


def compliance_factor(s, poisson: float = 0.5, substrate: str = "bonded") -> np.ndarray:
    """C(s), s = |q| t: the layer's surface compliance over the half-space's (module docstring)."""
    s = np.asarray(s, dtype=float)
    out = np.empty_like(s)
    small = s < _SERIES_S
    big = ~small
    sb = s[big]
    e = np.exp(-2 * sb)  # written in e^{-2s}: no overflow at large s
    if substrate == "bonded":
        k = 3 - 4 * poisson
        num = -k * np.expm1(-4 * sb) - 4 * sb * e
        den = k * (1 + e * e) + (4 * sb * sb + 1 + k * k) * e
        out[big] = num / den
        out[small] = _bonded_series(s[small], k)
    elif substrate == "frictionless":
        # (cosh 2s − 1)/(sinh 2s + 2s) = (1 − e)² / (1 − e² + 4 s e)
        out[big] = np.expm1(-2 * sb) ** 2 / (-np.expm1(-4 * sb) + 4 * sb * e)
        ss = s[small]
        out[small] = ss / 2 - ss**5 / 90
    else:
        raise TengsimError(f"substrate must be one of {', '.join(SUBSTRATES)}, got {substrate!r}")
    return out


def small_s_slope(poisson: float, substrate: str) -> float:
    """c₁ = lim C(s)/s as s → 0: (1 − 2ν)/(2(1 − ν)²) bonded, 1/2 frictionless."""
    return (1 - 2 * poisson) / (2 * (1 - poisson) ** 2) if substrate == "bonded" else 0.5


def mean_compliance(thickness: float, poisson: float, coupling: float = 1.0) -> float:
    """Compliance of the uniform (q = 0) mode of a periodic film, κ T (1 − 2ν)/(1 − ν)² (= t/M in SI
    with coupling 1/E*): uniaxial strain, for a bonded or a frictionless substrate alike."""
    return coupling * thickness * (1 - 2 * poisson) / (1 - poisson) ** 2


def oedometric_compliance_si(thickness_m: float, E_star_Pa: float, poisson: float) -> float:
    """t (1 + ν)(1 − 2ν)/(E (1 − ν)) with E = E*(1 − ν²): the uniaxial-strain compliance in m/Pa."""
    E = E_star_Pa * (1 - poisson**2)
    return thickness_m * (1 + poisson) * (1 - 2 * poisson) / (E * (1 - poisson))


# --- real-space correction of the free (isolated) kernel -------------------------------------------
# ΔK(r) = (κ/π)(1/T) h(r/T),  h(ρ) = ∫₀^∞ (C(s) − 1) J₀(sρ) ds  (the inverse Hankel transform of the
# layer-minus-half-space multiplier (2κ/q)(C − 1)).  With c₁ = C'(0) the non-smooth part is split off
# in closed form, C − 1 = −e^{−s} + (c₁ − 1) s e^{−s} + g(s), g = O(s²):
#     h(ρ) = −1/√(1 + ρ²) + (c₁ − 1)/(1 + ρ²)^{3/2} + ∫ g(s) J₀(sρ) ds,
# the last integral tabulated on ρ ≤ RHO_FAR by Gauss–Legendre panels (cubic spline in between).
# C is odd in s, so C − 1 is −1 plus odd powers of s, which have no algebraic tail in 2-D
# (∫ sⁿ J₀(sρ) ds ∝ Pₙ(0) = 0 for odd n): h(ρ) = −1/ρ up to terms that decay exponentially
# (|h + 1/ρ| < 1e-9 at ρ = 25 for 0.3 ≤ ν ≤ 0.5, measured), so beyond RHO_FAR h = −1/ρ exactly
# cancels the half-space: the layer's influence vanishes farther than 40 thicknesses.
RHO_FAR = 40.0
_DRHO = 0.02
_S_MAX = 45.0


@lru_cache(maxsize=16)
def _spline(poisson: float, substrate: str):
    from scipy.interpolate import CubicSpline
    from scipy.special import j0

    c1 = small_s_slope(poisson, substrate)
    panels, order = 320, 12
    xg, wg = np.polynomial.legendre.leggauss(order)
    edges = np.linspace(0.0, _S_MAX, panels + 1)
    half = 0.5 * np.diff(edges)
    s = (edges[:-1, None] + half[:, None] * (xg[None, :] + 1)).ravel()
    w = (half[:, None] * wg[None, :]).ravel()
    es = np.exp(-s)
    gw = (compliance_factor(s, poisson, substrate) - 1 + es - (c1 - 1) * s * es) * w
    rho = np.arange(0.0, RHO_FAR + 3 * _DRHO, _DRHO)
    vals = np.empty_like(rho)
    for i0 in range(0, rho.size, 256):
        vals[i0:i0 + 256] = j0(rho[i0:i0 + 256, None] * s[None, :]) @ gw
    return CubicSpline(rho, vals)


def correction_profile(rho, poisson: float = 0.5, substrate: str = "bonded") -> np.ndarray:
    """h(ρ) = ∫₀^∞ (C(s) − 1) J₀(sρ) ds (see above): the layer's real-space correction per unit 1/T."""
    rho = np.abs(np.asarray(rho, dtype=float))
    c1 = small_s_slope(float(poisson), substrate)
    out = np.empty_like(rho)
    near = rho <= RHO_FAR
    r = rho[near]
    x2 = 1 + r * r
    out[near] = -1 / np.sqrt(x2) + (c1 - 1) / (x2 * np.sqrt(x2)) + _spline(float(poisson), substrate)(r)
    out[~near] = -1 / rho[~near]
    return out

def _gauss3():
    x, w = np.polynomial.legendre.leggauss(3)
    return 0.5 * x, 0.5 * w  # nodes and weights on [−1/2, 1/2]


MAX_PIXEL_PER_THICKNESS = 64
"""The largest pixel a film's correction is integrated on, in film thicknesses: the correction splits a pixel
into ⌈dx/T⌉² sub-pixels (9 Gauss points each), so a film of 1e-15 m under a 10 nm pixel asked for 10¹⁶ of them
(a run past any budget; 1e-30 m: an allocation that could not succeed)."""


def check_film_pixels(thickness: float, dx: float, lateral: float | None = None) -> None:
    """Refuse, before any kernel is built, a pixel more than :data:`MAX_PIXEL_PER_THICKNESS` film thicknesses
    wide (``lateral``: metres per unit, for a message in metres)."""
    if not dx <= MAX_PIXEL_PER_THICKNESS * thickness:
        from tengsim.errors import TengsimError
        from tengsim.units import format_si

        def say(v):
            return format_si(v * lateral, "m") if lateral else f"{v:g}"

        raise TengsimError(f"film thickness {say(thickness)} is below 1/{MAX_PIXEL_PER_THICKNESS} of the pixel "
                           f"(dx {say(dx)}): give a film at least {say(dx / MAX_PIXEL_PER_THICKNESS)} thick, a "
                           "finer grid, or no film (a half-space)")


def film_pixel_correction(X, Y, dx: float, dy: float, thickness: float, poisson: float,
                          substrate: str) -> np.ndarray:
    """∬ over the pixel at offsets (X, Y) of (1/T) h(|r|/T): the layer-minus-half-space influence per κ/π.

    A pixel wholly beyond ``RHO_FAR`` thicknesses gets −pixel_influence exactly (there h = −1/ρ:
    the layer's influence vanishes); a nearer one is split into k × k sub-pixels, k = ⌈max(dx, dy)/T⌉,
    with 3 × 3 Gauss points each (h is smooth on the scale T, so a film thinner than a pixel still
    has its correction resolved)."""
    check_film_pixels(thickness, max(dx, dy))
    X, Y = np.broadcast_arrays(np.asarray(X, float), np.asarray(Y, float))
    out = -pixel_influence(X, Y, dx, dy)
    gap = np.hypot(np.maximum(np.abs(X) - dx / 2, 0.0), np.maximum(np.abs(Y) - dy / 2, 0.0))
    near = gap < RHO_FAR * thickness
    if not near.any():
        return out
    Xn, Yn = X[near], Y[near]
    k = int(np.ceil(max(dx, dy) / thickness))
    xg, wg = _gauss3()
    sub = (np.arange(k) + 0.5) / k - 0.5  # sub-pixel centres on [−1/2, 1/2]
    nodes = [(c + x / k, w / k) for c in sub for x, w in zip(xg, wg)]
    acc = np.zeros(Xn.shape)
    for xi, wi in nodes:
        for yj, wj in nodes:
            r = np.hypot(Xn + xi * dx, Yn + yj * dy)
            acc += (wi * wj) * correction_profile(r / thickness, poisson, substrate)
    out[near] = acc * (dx * dy / thickness)
    return out


class _Film:
    """The elastic body every kernel shares: the coupling and the optional film fields (validated; the film's all
    None for the half-space)."""

    def _init_body(self) -> float:
        """The body validated in one place, before anything is built from it: the coupling (finite and > 0; returned
        as a float) and the film's fields (:meth:`_init_film`)."""
        coupling = positive("coupling", self.coupling)
        self._init_film()
        return coupling

    def _init_film(self):
        if self.thickness is None:
            self.film = False
            return
        self.thickness, self.substrate, self.poisson = check_film(self.thickness, self.substrate,
                                                                       self.poisson)
        self.film = True

    def film_params(self) -> dict:
        """thickness, substrate, poisson of the film ({} for the half-space): rebuilds the same body."""
        if not self.film:
            return {}
        return {"thickness": self.thickness, "substrate": self.substrate, "poisson": self.poisson}
