"""Diagnostics of resolution: the law's cohesive window, the process zone measured at every contact
edge (:class:`EdgeScan`), the pixel snap number and the uncertainty of walled faces.

What they decide is in :mod:`tengsim.status.classify`.

Resolution criterion (measured per equilibrium, :class:`EdgeScan`).  At every contact edge on the
grid — every row and column of the gap scanned both ways, not only the row through the apex — the
*cohesive window* ℓ is the distance, normal to the edge, over which the gap opens from the law's
tensile-peak gap g* (P(g*) = −σ0, the most tensile stress; LJ 9-3: g* = 3^{1/6}) to g0 + h0, where g0
is the contact gap (P(g0) = 0; LJ 9-3: 1) and h0 = W/σ0 the Dugdale range of the law (W = −Φ(g0);
LJ 9-3: h0 = 9√3/16 = 0.974), all as the law declares them (:class:`tengsim.laws.Law`: ``g_peak``,
``max_tension``, ``g_zero``, ``work``, ``cohesive_range``).  Positions are interpolated linearly in
the gap between pixels.  Each contact spot (connected pixels with g < g*: an array's K apices,
scattered, tilted and measured surfaces have many) gets the lower quartile of its edge's widths; the
narrowest spot counts.  An equilibrium is **under-resolved when ℓ < 1.2 dx**.  Rows without an
opening edge (no contact, or contact over the whole cell) are not judged.

Walls (cube, line, flat punch, a cliff in a height map): where U0 itself jumps by more than twice the
window within one pixel (and four times its neighbouring step), no dx makes the gap open gradually,
and the edge of the face is a crack tip: its process zone lies inside the face and is the Dugdale zone
of that crack, set by the law and E* alone.  A wall edge whose face pixel is past the tensile peak
counts as ℓ = 0.7 ℓ_D (the window's share of the Dugdale zone at a crack-like edge, measured on the
sphere; ℓ_D below).  The face itself is sampled at pixel centres, so each wall lies anywhere within
half a pixel: a face n pixels wide is known to 2/n of its area (``face_uncertainty``, a-priori); above
FACE_LIMIT = 1 % every judged row is under-resolved.

Calibration against grid convergence (benchmarks/status_calibration.py, docs/statuses.md): coarse →
fine runs of every registered shape and law; runs whose pull-off or jump D move by more than 1 % from the
finest grid must not be ``ok``, runs within 1 % must not be flagged.

Pixel snap (a second, a-priori cause of under-resolution).  A law that softens beyond its tensile
peak faster than one pixel is stiff — s = max_g dP/dg × c_pix (the law's declared ``max_softening``),
with c_pix the gap change of a pixel under unit pressure on that pixel alone (one convolution of the
run's kernel) — has no stable state in that band of gaps when s > 1: pixels snap in and out one at a
time and the contact edge is pinned to the lattice, whatever the process zone; below 1 the lattice
still traps the edge, by less.  Every judged row of a run with s > SNAP_LIMIT is under-resolved
(calibration: docs/statuses.md).  s grows about as μ^{3/2} dx.

A-priori estimate (stated with every run, ``params['process_zone_estimate']``): at a crack-like
contact edge (JKR limit) the Dugdale zone is ℓ_D = (π/4) E* W/σ0², i.e. π/(4 κ σ0²) in units of the
lateral length with κ = μ^{3/2} (E* = 1/κ, W = 1); it exceeds the MD c − a at pull-off by
8.6 / 3.2 / 1.2 % at μ = 3 / 5 / 8 and bounds it from above for smaller μ (μ = 1: 0.75 vs 0.47).
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from scipy import ndimage


# ---- the law's cohesive window ------------------------------------------------------------------

@dataclass(frozen=True)
class CohesiveWindow:
    """Gaps bounding a law's process zone: g_peak (most tensile P = −sigma0), g0 (P = 0), h0 = W/sigma0."""

    g_peak: float
    g0: float
    sigma0: float
    work: float

    @property
    def h0(self) -> float:
        return self.work / self.sigma0

    @property
    def g_end(self) -> float:
        return self.g0 + self.h0


def _declared(law) -> tuple:
    """(σ0, g_peak, g0, W) as the law declares them (``tengsim.laws.Law``: closed forms in the built-in
    laws, a cached numerical search otherwise); a duck-typed law declaring none gets the laws'
    numerical search (cached where the law is hashable)."""
    if not hasattr(law, "max_tension"):
        try:
            return _undeclared(law)
        except TypeError:  # an unhashable duck-typed law: compute without the cache
            return _undeclared.__wrapped__(law)
    s0 = law.max_tension
    if s0 is None or not float(s0) > 0:
        return 0.0, None, None, 0.0
    return float(s0), law.g_peak, law.g_zero, float(law.work or 0.0)


@lru_cache(maxsize=16)
def _undeclared(law) -> tuple:
    from tengsim.laws.base import numeric_window  # only for a law that is no tengsim.laws.Law

    w = numeric_window(law)
    return (0.0, None, None, 0.0) if w is None else (w[1], w[0], w[2], w[3])


def cohesive_window(law) -> CohesiveWindow | None:
    """The law's cohesive window from its declared numbers (``max_tension``, ``g_peak``, ``g_zero``,
    ``work``; :class:`tengsim.laws.Law`); None for a law without tension, e.g. ``Repulsive``."""
    s0, g_peak, g0, work = _declared(law)
    if not (s0 > 0 and work > 0):
        return None
    return CohesiveWindow(float(g_peak), float(g0), s0, work)


def law_softening(law) -> float:
    """Steepest softening of a law beyond its tensile peak, max dP/dg over g* ≤ g ≤ g0 + 2 h0 (W/ε²
    units), as the law declares it (``max_softening``); 0 for a law without tension."""
    w = cohesive_window(law)
    if w is None:
        return 0.0
    if hasattr(law, "max_softening"):
        soft = law.max_softening
    else:  # a duck-typed law declaring none: the laws' numerical search
        from tengsim.laws.base import numeric_softening

        soft = numeric_softening(law, w.g_peak, w.g_end + w.h0)
    return float(max(soft or 0.0, 0.0))


def pixel_compliance(kernel) -> float:
    """Gap change of the centre pixel under unit pressure on it alone (one convolution)."""
    g = kernel.grid
    p = np.zeros((g.nx, g.ny))
    c = (g.nx // 2, g.ny // 2)
    p[c] = 1.0
    return float(abs(np.asarray(kernel.apply(p))[c]))


def pixel_snap_number(law, kernel) -> float:
    """s = (steepest softening of the law) × (pixel compliance); s > 1: pixels snap one at a time."""
    soft = law_softening(law)
    return soft * pixel_compliance(kernel) if soft > 0 else 0.0


def process_zone_estimate(law, coupling: float) -> float:
    """A-priori Dugdale zone ℓ_D = (π/4) E* W/σ0² = π W/(4 κ σ0²) (lateral units, κ the coupling); NaN
    for a law without tension.  Johnson & Greenwood (1997); equals MD c − a at the sphere's pull-off
    for large λ."""
    w = cohesive_window(law)
    if w is None:
        return float("nan")
    return float(np.pi * w.work / (4.0 * coupling * w.sigma0**2))


# ---- the measured, per-equilibrium process zone -------------------------------------------------

def _rise(h: np.ndarray, level: float, start: int = 0) -> float:
    """First fractional index >= start where h rises through ``level`` (NaN if it never does)."""
    above = h[start:] >= level
    k = int(np.argmax(above))
    if not above[k]:
        return float("nan")
    i = start + k
    if i == 0:
        return float("nan")
    a, b = h[i - 1], h[i]
    return i - 1 + (level - a) / (b - a)


def _window_1d(g: np.ndarray, w: CohesiveWindow) -> float:
    """Index distance over which the gap profile g (apex first) opens from g_peak to g_end; NaN if none."""
    if g[0] >= w.g_peak:
        return float("nan")
    a = _rise(g, w.g_peak)
    if a != a:
        return float("nan")
    c = _rise(g, w.g_end, int(a))
    return c - a


def process_zone_width(H: np.ndarray, dx: float, apex: tuple[int, int], law) -> float:
    """The cohesive window ℓ along the X row through ``apex`` only: the distance over which the gap
    g = H + 1 opens from g* to g0 + h0, the smaller of the two sides; NaN if the row has no such edge or
    the law has no tension.  The measure before :class:`EdgeScan` (which the status uses), kept as the
    1-D reference and for the calibration's comparison (benchmarks/status_calibration.py)."""
    w = cohesive_window(law)
    if w is None:
        return float("nan")
    row = np.asarray(H, dtype=float)[:, apex[1]] + 1.0
    i0 = apex[0]
    sides = [_window_1d(row[i0:], w), _window_1d(row[i0::-1], w)]
    sides = [s for s in sides if s == s]
    return float(min(sides) * dx) if sides else float("nan")


# ---- the measured process zone at every contact edge of the grid ---------------------------------

#: an opening from g* to g0 + h0 within one pixel step of the undeformed gap U0 that rises there by more
#: than WALL_STEP × (g0 + h0 − g*) and WALL_RATIO × its step on the face side is a wall (a geometric
#: edge: cube, line, flat punch, a cliff in a height map), where the gap cannot open gradually
WALL_STEP = 2.0
WALL_RATIO = 4.0
#: at a wall edge the process zone is the crack-tip (Dugdale) zone inside the face: WALL_FACTOR × ℓ_D,
#: the measured window's share of ℓ_D at a crack-like edge (sphere, JKR limit: ℓ ≈ 0.7 (c − a) ≈ 0.7 ℓ_D)
WALL_FACTOR = 0.7
#: a contact spot's edge width is the EDGE_QUANTILE of its crossings (robust to single pixels: the
#: lattice meets the edge differently along each row); the worst spot counts
EDGE_QUANTILE = 0.25


def _wall_steps(U0: np.ndarray, w: CohesiveWindow, axis: int) -> np.ndarray:
    """Steps i → i+1 along ``axis`` (shape n−1 along it) where U0 jumps like a wall (WALL_STEP, WALL_RATIO)."""
    d = np.abs(np.diff(U0, axis=axis))
    before = d.copy()  # the step on the face side (i−1 → i), and after (i+1 → i+2) for the other way;
    after = d.copy()   # at the grid's border a step is compared with itself (no wall there)
    sl = [slice(None)] * 2
    lo, hi = list(sl), list(sl)
    lo[axis], hi[axis] = slice(1, None), slice(None, -1)
    before[tuple(lo)] = d[tuple(hi)]
    after[tuple(hi)] = d[tuple(lo)]
    big = d > WALL_STEP * (w.g_end - w.g_peak)
    return big & ((d > WALL_RATIO * before) | (d > WALL_RATIO * after))


class _Cosine:
    """|cos| of the angle between a scan (axis 1 of ``G``) and the gap's gradient, at given pixels only: the
    gradient as :func:`numpy.gradient` makes it (central differences inside, one-sided at the border; a
    reversed view flips only the sign), so no gradient field of the whole box is made.  ``fixed``: the
    value everywhere (a box one pixel wide)."""

    def __init__(self, G, d_along: float, d_across: float, fixed: float | None = None):
        self.G, self.d, self.e, self.fixed = G, d_along, d_across, fixed

    @staticmethod
    def _diff(G, r, c, axis, h):
        n = G.shape[axis]
        k = c if axis == 1 else r
        lo, hi = np.maximum(k - 1, 0), np.minimum(k + 1, n - 1)
        a = G[r, hi] if axis == 1 else G[hi, c]
        b = G[r, lo] if axis == 1 else G[lo, c]
        inner = (k > 0) & (k < n - 1)
        return np.where(inner, (a - b) / (2.0 * h), (a - b) / h)

    def at(self, r, c):
        if self.fixed is not None:
            return np.full(np.shape(r), self.fixed)
        along = self._diff(self.G, r, c, 1, self.d)
        across = self._diff(self.G, r, c, 0, self.e)
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.nan_to_num(np.abs(along) / np.hypot(along, across))


_ROWS = 16
"""Rows of the gap made at a time where only a mask of it is kept."""


def _scan(G, walls, labels, cos, w, wall_pix):
    """Openings along axis 1 of G (m × n) in the + direction: (labels of the contact spot each opening
    leaves, normal widths in pixels).  See :class:`EdgeScan`."""
    n = G.shape[1]
    if n < 2:
        return np.empty(0, int), np.empty(0)
    a, b = G[:, :-1], G[:, 1:]
    P = np.flatnonzero((a < w.g_peak) & (b >= w.g_peak))
    E = np.flatnonzero((a < w.g_end) & (b >= w.g_end))
    if not len(P) or not len(E):
        return np.empty(0, int), np.empty(0)
    nxt = np.append(P[1:], np.iinfo(np.int64).max)  # the next opening: its g* crossing ends this one's window
    k = np.searchsorted(E, P)
    keep = k < len(E)
    P, nxt, e = P[keep], nxt[keep], E[np.minimum(k[keep], len(E) - 1)]
    keep = (P // (n - 1) == e // (n - 1)) & (e < nxt)
    P, e = P[keep], e[keep]
    # indexed by (row, column), never raveled: G is a transposed or reversed view, and a ravel would copy it
    rp, cp = np.divmod(P, n - 1)  # the pixel the opening leaves is (rp, cp), the one beyond it (rp, cp + 1)
    re_, ce = np.divmod(e, n - 1)
    pos_p = cp + (w.g_peak - a[rp, cp]) / (b[rp, cp] - a[rp, cp])
    pos_e = ce + (w.g_end - a[re_, ce]) / (b[re_, ce] - a[re_, ce])
    at_wall = walls[re_, ce]
    c = cos.at(rp, cp + 1)
    width = np.where(at_wall, wall_pix, (pos_e - pos_p) * c)
    # a wall opening is judged once the face pixel at the wall is past the peak (its zone has formed);
    # a gradual opening where the scan runs within 45° of the edge normal (the other scan sees the rest)
    judged = np.where(at_wall, e > P, c >= np.sqrt(0.5))
    return labels[rp, cp][judged], width[judged]


def face_uncertainty(U0: np.ndarray, walls) -> float:
    """Relative uncertainty of the area of the flat faces bounded by walls (0: no walls).  The grid samples
    U0 at pixel centres, so a wall lies anywhere within half a pixel of the step: each wall step leaves
    half a pixel of a face's area unknown.  A face is a connected region below the walls' mid-heights;
    the worst face counts: (its wall steps) / (2 × its pixels), 2/n for a square face n pixels wide."""
    wx, wy = walls
    if not (wx.any() or wy.any()):
        return 0.0
    U0 = np.asarray(U0, dtype=float)
    mids = np.concatenate([(0.5 * (U0[:-1] + U0[1:]))[wx], (0.5 * (U0[:, :-1] + U0[:, 1:]))[wy]])
    labels, n = ndimage.label(U0 < np.median(mids))
    if n == 0:
        return 0.0
    lo_x = np.where(U0[:-1] < U0[1:], labels[:-1], labels[1:])[wx]  # the face side of each wall step
    lo_y = np.where(U0[:, :-1] < U0[:, 1:], labels[:, :-1], labels[:, 1:])[wy]
    steps = np.bincount(np.concatenate([lo_x, lo_y]), minlength=n + 1)[1:]
    pixels = np.bincount(labels.ravel(), minlength=n + 1)[1:]
    return float(np.max(steps / (2.0 * np.maximum(pixels, 1))))


class EdgeScan:
    """The process zone of one equilibrium measured at every contact edge of the grid (one per run:
    the walls of U0 and the law's numbers are found once; each call is element-wise on the gap).

    Every row and every column of the gap g = H + 1 is scanned both ways; an *opening* leaves a pixel
    with g < g* and reaches g0 + h0 before g falls below g* again.  Its width (linear interpolation of
    g between pixels, times the cosine between the scan and the gap's gradient, so that it is the width
    normal to the edge; an opening is read only by the scan within 45° of that normal) is the cohesive
    window ℓ there.  An opening whose g0 + h0 crossing is a wall step of U0 (:data:`WALL_STEP`) is a
    geometric edge: its zone is the crack tip's inside the face, WALL_FACTOR × ℓ_D (the a-priori Dugdale
    zone, :func:`process_zone_estimate`), judged once the face pixel at the wall is past the peak.
    Openings are grouped by the contact spot they leave (connected pixels with g < g*); a spot's width is
    the EDGE_QUANTILE of its openings; the result is the narrowest spot's, in lateral units (NaN: no
    opening anywhere, or a law without tension).
    """

    def __init__(self, U0, law, dx: float, dy: float | None = None, coupling: float | None = None):
        self.w = cohesive_window(law)
        self.dx, self.dy = float(dx), float(dy if dy is not None else dx)
        self.face = 0.0  # a law without tension: nothing is judged
        if self.w is None:
            return
        U0 = np.asarray(U0, dtype=float)
        self.walls = (_wall_steps(U0, self.w, 0), _wall_steps(U0, self.w, 1))
        lD = process_zone_estimate(law, coupling) if coupling else float("nan")
        self.wall_zone = WALL_FACTOR * lD if lD == lD else 0.0
        self.face = face_uncertainty(U0, self.walls)

    def __call__(self, H) -> float:
        w = self.w
        if w is None:
            return float("nan")
        H = np.asarray(H, dtype=float)
        near = np.empty(H.shape, dtype=bool)
        for k in range(0, H.shape[0], _ROWS):  # g = H + 1 a band of rows at a time: no full-grid float temporary
            np.less(H[k:k + _ROWS] + 1.0, w.g_end, out=near[k:k + _ROWS])
        rows, cols = np.flatnonzero(near.any(axis=1)), np.flatnonzero(near.any(axis=0))
        del near
        if not len(rows):
            return float("nan")
        # the work is element-wise on the box around the edges (2 pixels' margin: central differences)
        i0, i1 = max(rows[0] - 2, 0), min(rows[-1] + 3, H.shape[0])
        j0, j1 = max(cols[0] - 2, 0), min(cols[-1] + 3, H.shape[1])
        g = H[i0:i1, j0:j1] + 1.0
        wx, wy = self.walls[0][i0:i1 - 1, j0:j1], self.walls[1][i0:i1, j0:j1 - 1]
        inside = g < w.g_peak
        if not inside.any() or inside.all():
            return float("nan")
        labels, _ = ndimage.label(inside)
        flat = min(g.shape) <= 1  # no gradient across a single row or column: cosines 1 along axis 0, 0 along 1
        labs, widths = [], []
        for G, W, L, d, e in ((g.T, wx.T, labels.T, self.dx, self.dy), (g, wy, labels, self.dy, self.dx)):
            for s in (slice(None), slice(None, None, -1)):
                cos = _Cosine(G[:, s], d, e, 1.0 if (flat and G is not g) else 0.0 if flat else None)
                lab, wid = _scan(G[:, s], W[:, s], L[:, s], cos, w, self.wall_zone / d)
                labs.append(lab)
                widths.append(wid * d)
        lab, wid = np.concatenate(labs), np.concatenate(widths)
        if not len(wid):
            return float("nan")
        order = np.lexsort((wid, lab))
        lab, wid = lab[order], wid[order]
        starts = np.flatnonzero(np.r_[True, lab[1:] != lab[:-1]])
        counts = np.diff(np.r_[starts, len(lab)])
        return float(wid[starts + np.floor(EDGE_QUANTILE * (counts - 1)).astype(int)].min())


def edge_process_zone(H, dx: float, law, U0=None, coupling: float | None = None, dy: float | None = None) -> float:
    """The process zone of one equilibrium at every contact edge (:class:`EdgeScan`; U0 None: no walls)."""
    return EdgeScan(np.zeros_like(np.asarray(H, float)) if U0 is None else U0, law, dx, dy, coupling)(H)
