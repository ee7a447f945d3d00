"""Boundary-element (method of moments) electrostatics of a finite contact-separation TENG.

Geometry (lengths in units of the electrode size L: the square's side or the disk's diameter): the back
electrode at z = 0, the tribo-charged dielectric surface a uniform fixed charge sheet of the electrode's
size at z = t_e, the moving electrode at z = t_e + x. The dielectric layer (thickness T, eps_r) enters as
its equivalent air thickness t_e = T / (eps_r L): exact for the normal field under the electrodes (the
displacement D is continuous, so its potential drop is D T/(eps_r eps0)), and it neglects the lateral
field inside the layer and the layer's own fringe, an O(T/L) correction (T/L ~ 1e-2 for T = 100 um on
a 1 cm electrode; not valid for a pattern whose pitch is not >> T, see device/nearfield.py).

Unknowns: piecewise-constant surface charge on panels of both electrodes (collocation at the panel
centres), graded toward the edges where the charge density diverges like 1/sqrt(distance).

* ``square``: rectangular panels, the exact potential of a uniformly charged rectangle (the corner
  sum below), quadrant symmetry (each panel stands for its four mirror images).
* ``disk``: axisymmetric annular panels; a ring's potential 4 K(m)/sqrt((r + r')^2 + dz^2) integrated
  over the annulus by Gauss-Legendre split at the field point and clustered there (t^2 map) to take the
  logarithmic singularity of K.

:func:`solve` returns, for one gap, the three coefficients of the field energy
U(Q, x) = Q^2/(2 C) - Q sigma A v(x) + (sigma A)^2 u(x)/2 (see device/field.py), dimensionless as
4 pi eps0 L times the SI values.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from scipy.special import ellipkm1

SHAPES = ("square", "disk")


def _xlog(c, a, r, rest2):
    """c ln(a + r) with r = sqrt(a^2 + rest2), without cancellation for a < 0; 0 where c = 0."""
    with np.errstate(divide="ignore", invalid="ignore"):
        val = np.where(a >= 0, np.log(a + r), np.log(rest2 / (r - a)))
        return np.where(c == 0, 0.0, c * val)


def _corner(u, v, z):
    """Antiderivative F(u, v) of 1/sqrt(u^2 + v^2 + z^2) over u and v (z >= 0)."""
    r = np.sqrt(u * u + v * v + z * z)
    out = _xlog(u, v, r, u * u + z * z) + _xlog(v, u, r, v * v + z * z)
    with np.errstate(divide="ignore", invalid="ignore"):
        at = np.where(z > 0, z * np.arctan(u * v / np.where(z > 0, z * r, 1.0)), 0.0)
    return out - at


def rect_potential(x1, x2, y1, y2, px, py, dz):
    """Integral of 1/|r - r'| over the rectangle [x1, x2] x [y1, y2] (plane z' = 0) at (px, py, dz)."""
    z = np.abs(dz)
    u1, u2, v1, v2 = x1 - px, x2 - px, y1 - py, y2 - py
    return _corner(u2, v2, z) - _corner(u1, v2, z) - _corner(u2, v1, z) + _corner(u1, v1, z)


def rect_field_z(x1, x2, y1, y2, px, py, dz):
    """Integral of dz/|r - r'|^3 over the rectangle: E_z 4 pi eps0 / sigma at (px, py, dz), dz > 0."""
    def at(u, v):
        return np.arctan(u * v / (dz * np.sqrt(u * u + v * v + dz * dz)))
    u1, u2, v1, v2 = x1 - px, x2 - px, y1 - py, y2 - py
    return at(u2, v2) - at(u1, v2) - at(u2, v1) + at(u1, v1)


def graded_nodes(n: int, half: float) -> np.ndarray:
    """n + 1 nodes on [0, half] clustered toward ``half`` (the edge): half sin(pi k / 2n)."""
    return half * np.sin(0.5 * np.pi * np.arange(n + 1) / n)


@dataclass(frozen=True, eq=False)
class Panels:
    """One electrode's panels: collocation points, areas (times their symmetry multiplicity), and the
    function giving the potential at arbitrary points (px, py or r, dz) per unit density on each panel."""

    shape: str
    cx: np.ndarray
    cy: np.ndarray
    area: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    lo_y: np.ndarray
    hi_y: np.ndarray
    nodes: np.ndarray

    @property
    def size(self) -> int:
        return self.area.size

    def influence(self, px, py, dz):
        """Matrix [collocation points, panels]: potential (dimensionless, G = integral dA'/|r - r'|) of
        unit density on each panel (with its mirror images) at this electrode's own collocation points
        shifted by ``dz`` normally (``px``, ``py``: those points; the square uses its tensor mesh)."""
        if self.shape == "square":
            return _square_influence(self.nodes, dz)
        return _ring_influence(np.asarray(px), self.lo, self.hi, dz)


def _square_influence(t, dz):
    """Quadrant-symmetric influence matrix of the tensor mesh with 1-D nodes ``t`` at normal offset dz.

    The corner antiderivative is evaluated once per (collocation, mirror sign, node) in x and in y, and
    the double difference over the nodes gives every panel's integral (n^2 x n^2 from (2 n (n + 1))^2)."""
    c = 0.5 * (t[:-1] + t[1:])
    n = c.size
    u = t[None, None, :] - np.array([1.0, -1.0])[None, :, None] * c[:, None, None]  # (i, sign, node)
    f = _corner(u.reshape(-1)[:, None], u.reshape(-1)[None, :], abs(dz)).reshape(n, 2, n + 1, n, 2, n + 1)
    d = np.diff(np.diff(f, axis=2), axis=5).sum(axis=(1, 4))  # (ix, jx, iy, jy)
    return d.transpose(0, 2, 1, 3).reshape(n * n, n * n)


_T, _W = np.polynomial.legendre.leggauss(16)
_T, _W = 0.5 * (_T + 1.0), 0.5 * _W


def _ring_influence(r, r1, r2, dz):
    """Potential at radius r (height offset dz) of unit density on annuli [r1, r2], [points, panels]."""
    r = r[:, None, None]
    a, b = r1[None, :, None], r2[None, :, None]
    s = np.clip(r, a, b)
    total = 0.0
    for end in (a, b):  # two pieces [a, s] and [s, b], each clustered toward s
        h = end - s
        rp = s + h * _T ** 2
        jac = np.abs(2.0 * h * _T)
        den = (r + rp) ** 2 + dz * dz
        p = ((r - rp) ** 2 + dz * dz) / den
        k = ellipkm1(np.maximum(p, 1e-300))
        total = total + np.sum(_W * jac * rp * 4.0 * k / np.sqrt(den), axis=-1)
    return total


def make_panels(shape: str, n: int) -> Panels:
    """Panels of an electrode of size 1 (square side or disk diameter), ``n`` graded panels per half-size."""
    t = graded_nodes(n, 0.5)
    if shape == "square":
        lo, hi = np.meshgrid(t[:-1], t[:-1], indexing="ij"), np.meshgrid(t[1:], t[1:], indexing="ij")
        x1, y1 = lo[0].ravel(), lo[1].ravel()
        x2, y2 = hi[0].ravel(), hi[1].ravel()
        return Panels(shape, 0.5 * (x1 + x2), 0.5 * (y1 + y2), 4.0 * (x2 - x1) * (y2 - y1), x1, x2, y1, y2, t)
    r1, r2 = t[:-1], t[1:]
    z = np.zeros_like(r1)
    return Panels(shape, 0.5 * (r1 + r2), z, np.pi * (r2 ** 2 - r1 ** 2), r1, r2, z, z, t)


@lru_cache(maxsize=8)
def _self_blocks(shape: str, n: int):
    pan = make_panels(shape, n)
    return pan, pan.influence(pan.cx, pan.cy, 0.0)


@lru_cache(maxsize=32)
def _offset_block(shape: str, n: int, dz: float):
    pan = _self_blocks(shape, n)[0]
    return pan.influence(pan.cx, pan.cy, dz)


@dataclass(frozen=True)
class GapSolution:
    """Dimensionless (4 pi eps0 L times SI) coefficients at one gap: 1/C, V_OC and 2 U_sigma per unit charge."""

    cinv: float
    voc: float
    usig: float
    wq: float = 0.0
    """Mean sheet potential minus the back electrode's, per unit Q (problem a): the layer's own voltage."""
    ws: float = 0.0
    """The same per unit sigma A (problem b); the air gap's mean voltage is V - (Q wq + sigma A ws)."""


def solve(shape: str, gap: float, t_e: float, n: int = 40) -> GapSolution:
    """The three field coefficients at gap ``gap`` above a sheet ``t_e`` over the back electrode (units of L).

    Problem (a): +1 on the back electrode, -1 on the moving one, no sheet: 1/C = phi_b - phi_t.
    Problem (b): sheet -1, moving electrode +1, back 0: V_OC = phi_t - phi_b; u = 2 U.
    """
    pan, g0 = _self_blocks(shape, n)
    m = pan.area.size
    h = t_e + gap  # moving electrode above the back electrode
    g_tb = pan.influence(pan.cx, pan.cy, h)  # symmetric offsets: the same for both directions
    g_ts = pan.influence(pan.cx, pan.cy, gap)  # sheet on the moving electrode's points
    g_bs = _offset_block(shape, n, float(t_e))  # sheet on the back electrode's points (gap-free)
    big = np.zeros((2 * m + 2, 2 * m + 2))
    big[:m, :m], big[:m, m:2 * m], big[m:2 * m, :m], big[m:2 * m, m:2 * m] = g0, g_tb, g_tb, g0
    big[:m, 2 * m] = -1.0
    big[m:2 * m, 2 * m + 1] = -1.0
    big[2 * m, :m] = pan.area
    big[2 * m + 1, m:2 * m] = pan.area
    s_sheet = -1.0 / pan.area.sum()
    rhs = np.zeros((2 * m + 2, 2))
    rhs[2 * m, 0], rhs[2 * m + 1, 0] = -1.0, 1.0  # (a): top -1, back +1
    rhs[:m, 1] = -g_ts @ np.full(m, s_sheet)
    rhs[m:2 * m, 1] = -g_bs @ np.full(m, s_sheet)
    rhs[2 * m, 1] = 1.0  # (b): top +1, back 0
    sol = np.linalg.solve(big, rhs)
    cinv = sol[2 * m + 1, 0] - sol[2 * m, 0]
    voc = sol[2 * m, 1] - sol[2 * m + 1, 1]
    phi_sheet = g_ts @ sol[:m, 1] + g_bs @ sol[m:2 * m, 1] + g0 @ np.full(m, s_sheet)
    usig = sol[2 * m, 1] + float(np.sum(pan.area * s_sheet * phi_sheet))
    phi_sheet_a = g_ts @ sol[:m, 0] + g_bs @ sol[m:2 * m, 0]
    mean = lambda phi: float(np.sum(pan.area * phi) / pan.area.sum())  # noqa: E731
    wq = mean(phi_sheet_a) - sol[2 * m + 1, 0]
    ws = mean(phi_sheet) - sol[2 * m + 1, 1]
    return GapSolution(float(cinv), float(voc), float(usig), wq, ws)
