"""Axisymmetric reference: a sphere (paraboloid) on a flat with any interaction law, solved on rings.

Written apart from the 2-D engine (no grid, kernel, solver or path code is shared) to check it.
Dimensionless units as in the engine (paper Eq. 7–10, sphere with ℓ = sqrt(Rε), so R = 1 and the
coupling is κ = μ^{3/2}):  g = H + 1,  U0 = r²/2,

    H(r) = −D + U0(r) + (κ/π) ∬ P(g(r'))/|x − x'| dA'                               (Eq. 9)

The pressure is piecewise constant on annuli b_{j−1} < r < b_j and Eq. (9) is collocated at the ring
mid-radii r_i.  The influence of a uniformly loaded disc of radius a at radius r is closed form
(Johnson 1985 §3.4, Eq. 3.41; complete elliptic integrals of modulus k, parameter m = k²):

    ∬_disc 1/|x − x'| dA' = 4a E(r/a)                              (r <= a)
                          = 4r [E(a/r) − (1 − a²/r²) K(a/r)]         (r > a)

and a ring is the difference of two discs.  The nodal gaps and D are solved by Newton's method on
the dense system, continued by pseudo-arclength in (nodal gaps, D), so the solution curve
is followed through its turning points in D (Greenwood 1997 traces the same S-shaped curves).  The
displacement-controlled approach and retraction, their jumps and the pull-off follow from the curve
(:func:`walk`).  Force: ∬P dA (= 3π F of Eq. 10; the sphere's pull-off ∬P = −π P̄ in units of πWR).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.special import ellipe, ellipk

from tengsim.errors import TengsimError, positive
from tengsim.laws.safe import safe


def disc_integral(r, a):
    """∬ over the disc of radius a of 1/|x − x'| dA', at radius r (Johnson 1985 Eq. 3.41)."""
    r = np.asarray(r, dtype=float)
    a = np.asarray(a, dtype=float)
    r, a = np.broadcast_arrays(r, a)
    out = np.empty(r.shape)
    inside = r <= a
    with np.errstate(divide="ignore", invalid="ignore"):
        ki = np.where(inside & (a > 0), r / np.where(a > 0, a, 1.0), 0.0)
        out[inside] = 4.0 * a[inside] * ellipe(ki[inside] ** 2)
        ko = np.where(~inside, a / np.where(r > 0, r, 1.0), 0.0)
        m = ko[~inside] ** 2
        out[~inside] = 4.0 * r[~inside] * (ellipe(m) - (1.0 - m) * ellipk(m))
    return out


def radial_mesh(dr: float, r_fine: float = 4.0, r_max: float = 30.0, growth: float = 1.03) -> np.ndarray:
    """Ring edges b_0 = 0 < b_1 < …: uniform ``dr`` up to ``r_fine``, then growing geometrically by
    ``growth`` per ring up to ``r_max`` (the far field only carries the law's weak tail)."""
    positive("dr", dr)
    if not (0 < r_fine <= r_max and growth >= 1.0):
        raise TengsimError("need 0 < r_fine <= r_max and growth >= 1")
    n = int(round(r_fine / dr))
    edges = list(np.arange(n + 1) * (r_fine / n))
    step = r_fine / n
    while edges[-1] < r_max:
        step *= growth
        edges.append(edges[-1] + step)
    return np.asarray(edges)


def ring_matrix(edges: np.ndarray, coupling: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(C, r, area): displacement at the ring mid-radii r_i per unit pressure on ring j,
    C_ij = (κ/π)[I(r_i, b_j) − I(r_i, b_{j−1})] with I = :func:`disc_integral`; ring areas π(b_j² − b_{j−1}²)."""
    b = np.asarray(edges, dtype=float)
    r = 0.5 * (b[1:] + b[:-1])
    Ib = disc_integral(r[:, None], b[None, :])
    C = (coupling / np.pi) * (Ib[:, 1:] - Ib[:, :-1])
    return C, r, np.pi * (b[1:] ** 2 - b[:-1] ** 2)


@dataclass
class Curve:
    """The solution curve in arclength order: D, force ∬P dA, central gap, contact radius (edge of
    g <= ``contact_gap``, linear between nodes; 0 if the centre is open) and the gap fields."""

    D: np.ndarray
    force: np.ndarray
    center_gap: np.ndarray
    contact_radius: np.ndarray
    gaps: np.ndarray
    r: np.ndarray
    mu: float


@dataclass
class Walk:
    """Displacement-controlled approach and retraction on a :class:`Curve`.

    ``jump_in``/``jump_out``: D of the first turning point met on approach / retraction (NaN if the
    branch has none); ``pull_off``: min ∬P dA on the retraction path; ``pull_off_load``: min over the
    whole curve (load control).  ``hysteresis``: whether the two paths differ."""

    jump_in: float
    jump_out: float
    pull_off: float
    pull_off_load: float
    hysteresis: bool


class AxisymSphere:
    """Sphere U0 = r²/2 against a flat, Tabor parameter ``mu``, law ``law`` (a tengsim law), on rings."""

    def __init__(self, mu: float, law, dr: float = 0.02, r_fine: float = 4.0, r_max: float = 30.0,
                 growth: float = 1.03, contact_gap: float = 1.0):
        self.mu = positive("mu", mu)
        self.law = safe(law)  # Newton's trial gaps may fall below g_safe
        self.edges = radial_mesh(dr, r_fine, r_max, growth)
        self.C, self.r, self.area = ring_matrix(self.edges, self.mu ** 1.5)
        self.U0 = 0.5 * self.r ** 2
        self.contact_gap = contact_gap

    def _p_dp(self, g):
        """P(g) and dP/dg (= −``law.stiffness``) at the nodal gaps."""
        P = self.law.pressure(g)
        dP = -self.law.stiffness(g)
        return P, dP

    def residual(self, H, D):
        """Residual of Eq. (9) at the ring mid-radii, units of ε."""
        P, _ = self._p_dp(H + 1.0)
        return H + D - self.U0 - self.C @ P

    def force(self, H) -> float:
        """∬P dA."""
        return float(self.area @ self.law.pressure(H + 1.0))

    def solve_at(self, D: float, H=None, tol: float = 1e-10, max_iter: int = 60):
        """Equilibrium at fixed D by damped Newton from H (default the rigid gap U0 − D)."""
        H = self.U0 - D if H is None else H.copy()
        n = H.size
        for _ in range(max_iter):
            P, dP = self._p_dp(H + 1.0)
            res = H + D - self.U0 - self.C @ P
            if np.max(np.abs(res)) < tol:
                return H
            J = np.eye(n) - self.C * dP[None, :]
            dH = np.linalg.solve(J, -res)
            H += dH * min(1.0, 0.2 / max(np.max(np.abs(dH)), 1e-300))
        raise TengsimError(f"axisym Newton did not converge at D = {D}")

    def _newton_arc(self, H, D, H0, D0, tH, tD, ds, tol, max_iter):
        """Newton on Eq. (9) plus the arclength condition ⟨t, x − x0⟩ = ds, x = (H, D), with the
        metric ⟨x, y⟩ = mean(H_x H_y) + D_x D_y."""
        n = H.size
        J = np.empty((n + 1, n + 1))
        res = np.empty(n + 1)
        for it in range(max_iter):
            P, dP = self._p_dp(H + 1.0)
            res[:n] = H + D - self.U0 - self.C @ P
            res[n] = float(tH @ (H - H0)) / n + tD * (D - D0) - ds
            if np.max(np.abs(res)) < tol:
                return H, D, it
            J[:n, :n] = -self.C * dP[None, :]
            J[np.arange(n), np.arange(n)] += 1.0
            J[:n, n] = 1.0
            J[n, :n] = tH / n
            J[n, n] = tD
            try:
                dx = np.linalg.solve(J, -res)
            except np.linalg.LinAlgError:
                return None
            step = np.max(np.abs(dx))
            if not np.isfinite(step) or step > 5.0:
                return None
            H = H + dx[:n]
            D = D + dx[n]
        return None

    def trace(self, d_start: float | None = None, d_end: float = 0.5, ds: float = 0.01, ds_max: float = 0.02,
              dh_max: float = 0.05, tol: float = 1e-9, max_steps: int = 20000) -> Curve:
        """Follow the equilibrium curve from D = ``d_start`` (apart; default −(1.5 + 1.5μ)) until D >= ``d_end``.

        Pseudo-arclength in x = (nodal gaps, D) with the metric mean(ΔH²) + ΔD², secant predictor; a
        step is halved when Newton fails or when any nodal gap moves by more than ``dh_max`` (so the
        curve is resolved where the contact edge runs), and grows again after easy steps, up to
        ``ds_max``.  The curve passes turning points in D, where D alone could not parametrise it.
        """
        if d_start is None:
            d_start = -(1.5 + 1.5 * self.mu)           # apart, beyond the jump-out (≈ −1.74 at μ = 1, −3.38 at μ = 2)
        H = self.solve_at(d_start)
        D = d_start
        n = H.size
        tH, tD = -np.ones(n), 1.0                      # approaching: every gap closes as D grows
        out = [(D, H)]
        ds_min = 1e-8
        for _ in range(max_steps):
            if D >= d_end:
                break
            if len(out) >= 2:
                Dp, Hp = out[-2]
                vH, vD = H - Hp, D - Dp
                nv = np.sqrt(float(vH @ vH) / n + vD * vD)
                if nv > 0:
                    tH, tD = vH / nv, vD / nv
            nt = np.sqrt(float(tH @ tH) / n + tD * tD)
            tH, tD = tH / nt, tD / nt
            while True:
                got = self._newton_arc(H + ds * tH, D + ds * tD, H, D, tH, tD, ds, tol, 25)
                if got is not None:
                    Hn, Dn, its = got
                    if np.max(np.abs(Hn - H)) <= dh_max or ds <= ds_min:
                        break
                ds *= 0.5
                if ds < ds_min:
                    raise TengsimError(f"axisym continuation stalled at D = {D:.6g}")
            H, D = Hn, Dn
            out.append((D, H))
            if its <= 4:
                ds = min(ds * 1.5, ds_max)
        else:
            raise TengsimError("axisym continuation: too many steps")
        Ds = np.array([d for d, _ in out])
        Hs = np.array([h for _, h in out])
        F = np.array([self.force(h) for h in Hs])
        return Curve(Ds, F, Hs[:, 0] + 1.0, np.array([self.contact_radius(h) for h in Hs]), Hs, self.r, self.mu)

    def contact_radius(self, H) -> float:
        """Outer edge of the zone g <= contact_gap that contains the centre (linear between nodes)."""
        g = H + 1.0
        c = self.contact_gap
        if g[0] > c:
            return 0.0
        i = int(np.argmax(g > c)) if np.any(g > c) else g.size - 1
        if i == 0 or g[i] <= c:
            return float(self.r[-1])
        f = (c - g[i - 1]) / (g[i] - g[i - 1])
        return float(self.r[i - 1] + f * (self.r[i] - self.r[i - 1]))


def _turning(D, i):
    """D at the extremum near sample i, from the parabola through samples i−1, i, i+1 (arclength order)."""
    if i <= 0 or i >= len(D) - 1:
        return float(D[i])
    y0, y1, y2 = D[i - 1], D[i], D[i + 1]
    den = y0 - 2 * y1 + y2
    if den == 0:
        return float(y1)
    # vertex of the parabola through equally weighted index positions (samples are closely spaced)
    return float(y1 - (y0 - y2) ** 2 / (8 * den))


def pull_off_state(curve: Curve) -> tuple[float, float, float]:
    """(∬P dA, D, contact radius) at the force minimum of the curve: vertex of the parabola through the
    minimal sample and its neighbours (in arclength index), D and radius interpolated to it."""
    F = curve.force
    i = int(np.argmin(F))
    if i == 0 or i == len(F) - 1:
        return float(F[i]), float(curve.D[i]), float(curve.contact_radius[i])
    f0, f1, f2 = F[i - 1], F[i], F[i + 1]
    den = f0 - 2 * f1 + f2
    u = 0.5 * (f0 - f2) / den if den > 0 else 0.0       # vertex offset in samples, |u| <= 1/2
    fmin = f1 - 0.25 * (f0 - f2) * u
    j = i + (1 if u > 0 else -1)
    lerp = lambda y: float(y[i] + abs(u) * (y[j] - y[i]))
    return float(fmin), lerp(curve.D), lerp(curve.contact_radius)


def walk(curve: Curve) -> Walk:
    """Displacement-controlled approach (D up) and retraction (D down) along ``curve``.

    On approach the state follows the curve while D increases; at a turning point (D maximum) it
    jumps, at that D, to the next part of the curve where D increases again.  Retraction is the mirror
    image, starting from the curve's end.
    """
    D, F = curve.D, curve.force
    n = len(D)

    def run(order):
        idx = list(order)
        sign = 1 if idx[0] < idx[-1] else -1           # +1: approach (D up), −1: retraction (D down)
        visited = [idx[0]]
        first_jump = np.nan
        k = 0
        while k < len(idx) - 1:
            a, b = idx[k], idx[k + 1]
            if sign * (D[b] - D[a]) >= 0:
                visited.append(b)
                k += 1
                continue
            Dj = D[a]                                   # turning point: jump at this D
            if np.isnan(first_jump):
                first_jump = _turning(D, a)
            # land where the curve next passes Dj moving in the driving direction
            land = None
            for m in range(k + 1, len(idx) - 1):
                c, d = idx[m], idx[m + 1]
                if sign * (D[d] - D[c]) > 0 and (D[c] - Dj) * (D[d] - Dj) <= 0:
                    land = m + 1
                    break
            if land is None:
                break
            visited.append(idx[land])
            k = land
        return visited, first_jump

    app, jin = run(range(n))
    ret, jout = run(range(n - 1, -1, -1))
    return Walk(float(jin), float(jout), float(F[ret].min()), float(F.min()),
                bool(not np.isnan(jin) or not np.isnan(jout)))


@dataclass(frozen=True)
class MaugisSphere:
    """Maugis–Dugdale theory in this module's (and the engine's) sphere units: pull-off ∬P/π (= |F|/(πWR)),
    contact radii in ℓ = sqrt(Rε) at pull-off and at zero load, approach D (ε) at pull-off."""

    lam: float
    pull_off: float
    a_pull_off: float
    a_zero_load: float
    D_pull_off: float


def maugis_sphere(mu: float, sigma0: float | None = None) -> MaugisSphere:
    """Maugis' theory (tengsim.references) for the dimensionless sphere R = ε = W = 1, E* = μ^{−3/2}.

    With these values the references' SI-like formulas return the engine's units directly: forces in
    W R (so P̄ = |F|/(πWR) = −∬P/π), lengths in ℓ = sqrt(Rε) = 1, indentation in ε.  λ from the
    Dugdale stress ``sigma0`` (default the LJ93 peak 16/(9√3), giving λ = 1.157 μ)."""
    from tengsim import references as ref  # the package's closed forms (this module sits above them)
    from tengsim.laws import LJ_PEAK_TENSION

    R, E_star, W = 1.0, positive("mu", mu) ** -1.5, 1.0
    lam = ref.md_lambda(R, E_star, W, LJ_PEAK_TENSION if sigma0 is None else sigma0)
    sc = ref.md_scales(R, E_star, W)
    pt = ref.maugis_dugdale_pulloff_point(lam)
    c = ref.maugis_dugdale_curve(lam, A_max=4.0, n=4000, A_min=1e-3)
    i = int(np.argmin(c.P))
    a0 = float(np.interp(0.0, c.P[i:], c.A[i:]))          # P increases with A past the minimum
    return MaugisSphere(lam, -pt.P, pt.A * sc.length, a0 * sc.length, pt.D * sc.indentation)
