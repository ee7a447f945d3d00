"""Per-state analysis: force (Eq. 10), contact length by Greenwood's tensile peak, contact areas (the charged
area of Eq. 12 measured on the 2-D gap map, :func:`charged_area`; the repulsive area)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tengsim.grid import Grid


def force(P: np.ndarray, grid: Grid) -> float:
    """Paper Eq. (10): F = (1/3π) ∬ P dX dY over the cell."""
    return float(P.sum() * grid.area / (3 * np.pi))


def _parabolic_min(f: np.ndarray, i: int) -> float:
    """Sub-pixel position (in index units) of a discrete minimum at i, by a parabola through 3 points."""
    if i <= 0 or i >= len(f) - 1:
        return float(i)
    a, b, c = f[i - 1], f[i], f[i + 1]
    den = a - 2 * b + c
    if den <= 0:
        return float(i)
    return i + 0.5 * (a - c) / den


def tensile_peak_offset(profile: np.ndarray) -> float:
    """Distance (index units) from profile[0] (the apex) to the innermost tensile pressure minimum.

    Walk outward from the apex; the contact edge is the first local minimum of P with P < 0 that
    follows the compressive (or least tensile) core.  If the apex itself is the minimum, return 0.
    The innermost rule ignores the spurious tensile extremum of a free cell at its boundary.
    """
    f = np.asarray(profile, dtype=float)
    n = len(f)
    if n < 3 or (f[0] < 0 and f[1] >= f[0]):
        return 0.0  # the apex is itself the tensile minimum: no contact patch
    for i in range(1, n - 1):
        if f[i] < 0 and f[i] <= f[i - 1] and f[i] < f[i + 1]:
            return _parabolic_min(f, i)
    return float(n - 1)  # minimum at the grid edge


def contact_length(P: np.ndarray, grid: Grid, apex: tuple[int, int]) -> float:
    """Greenwood contact length Λc = |2Xc| (paper Section 3): twice the distance from the apex to the
    tensile pressure peak along the X row through the apex, averaged over the +X and −X sides.
    """
    i0, j0 = apex
    row = P[:, j0]
    right = tensile_peak_offset(row[i0:])
    left = tensile_peak_offset(row[i0::-1])
    return float((right + left) * grid.dx)


def repulsive_area(P: np.ndarray, grid: Grid) -> float:
    """Area where the pressure is repulsive (P > 0): a second contact-area definition."""
    return float(np.count_nonzero(P > 0) * grid.area)


#: The paper's law's peak-tension separation 3^{1/6} (LJ 9-3, Eq. 8), used when no law is given.
PAPER_PEAK_SEPARATION = 3.0 ** (1.0 / 6.0)


def law_edge(law) -> tuple[float, float]:
    """(g_c, opening) of a law for :func:`charged_area`: its ``peak_separation`` (else its ``g_peak``, else 1)
    and its ``edge_opening`` (else 1)."""
    g = getattr(law, "peak_separation", None)
    if g is None:
        g = getattr(law, "g_peak", None)
    return (1.0 if g is None else float(g)), float(getattr(law, "edge_opening", 1.0) or 1.0)


def _scan_length(f: np.ndarray, periodic: bool) -> float:
    """Σ over the lines along axis 0 of the length (in pixels) where f < 0: the pixels with f < 0, and at each
    crossing a correction within ±½ pixel from the outside of the edge: the line through the first two
    outside pixels (f_o, f_oo) puts the edge at d = f_o/(f_oo − f_o) pixels from the first (the outside is
    where the gap opens smoothly; the inside may be flat, a wall).  Where that line does not cross within
    the pixel pair (a step: a flat top beside a flat land), the edge is the pixels' common border."""
    inside = f < 0
    total = float(np.count_nonzero(inside))
    n = f.shape[0]
    if n < 2:
        return total
    for step in (1, -1):
        if periodic:
            ins_o, fo, foo = (np.roll(a, -step * k, axis=0) for a, k in ((inside, 1), (f, 1), (f, 2)))
        else:
            ins_o = np.zeros_like(inside)
            fo = np.full_like(f, np.nan)
            foo = np.full_like(f, np.nan)
            if step == 1:
                ins_o[:-1], fo[:-1], foo[:-2] = inside[1:], f[1:], f[2:]
            else:
                ins_o[1:], fo[1:], foo[2:] = inside[:-1], f[:-1], f[:-2]
        edge = inside & ~ins_o & np.isfinite(fo)
        m = foo - fo
        with np.errstate(invalid="ignore", divide="ignore"):
            d = np.where(edge & (m > 0), fo / np.where(m > 0, m, 1.0), np.inf)
        total += float(np.sum(np.where(edge & (d < 1.0), 0.5 - d, 0.0)))
    return total


def charged_area(H: np.ndarray, grid: Grid, g_c: float, opening: float = 1.0, periodic: bool = False) -> float:
    """The charged contact area (ℓ²): the area where the gap g = H + 1 is at most ``g_c``, the separation of the
    law's peak tension (:attr:`tengsim.laws.Law.peak_separation`; Greenwood's contact edge), on the 2-D map:
    no apex, axis or patch shape assumed, so the same for every shape, array, rough or measured surface.

    Measured line by line along X and along Y (the mean of the two): the pixels inside, and each edge
    placed within its pixel pair from the outside profile (:func:`_scan_length`) of the level function
    f = sign(g − g_c)|g − g_c|^(1/opening), linear in the distance from an edge where the gap opens as
    s^opening (``opening`` 1.5 for a law whose peak tension starts at its wall, :attr:`~tengsim.laws.Law.
    edge_opening`).  A step (a flat top in contact beside a land that is not) counts its top's pixels
    exactly.  ``periodic``: the lines wrap around the cell (the periodic kernel)."""
    H = np.asarray(H, dtype=float)

    def level(h):
        s = h + (1.0 - float(g_c))
        f = np.sign(s) * np.abs(s) ** (1.0 / float(opening))
        return np.where(s <= 0, np.minimum(f, -1e-300), f)  # a gap at g_c itself is inside (a closed wall)

    nx, ny = H.shape
    ax = ay = 0.0
    # lines in blocks: at most ~_CHUNK values and an eighth of the map, so the scan's temporaries (about ten
    # blocks) stay below one map's size while its Python overhead is a few blocks, not a block per 4 lines
    step_y = max(4, min(ny // 8 + 1, _CHUNK // max(nx, 1)))
    step_x = max(4, min(nx // 8 + 1, _CHUNK // max(ny, 1)))
    for j in range(0, ny, step_y):
        f = level(H[:, j:j + step_y])
        ax += _scan_length(f, periodic) if nx > 1 else float(np.count_nonzero(f < 0))
    for i in range(0, nx, step_x):
        f = level(H[i:i + step_x, :].T)
        ay += _scan_length(f, periodic) if ny > 1 else float(np.count_nonzero(f < 0))
    return float(0.5 * (ax + ay) * grid.area)


_CHUNK = 1 << 16
"""Most map values measured at a time by :func:`charged_area`."""


def apex_index(U0: np.ndarray) -> tuple[int, int]:
    """Grid index of the highest point (smallest initial gap); the centre pixel wins ties."""
    m = U0.min()
    idx = np.argwhere(U0 <= m + 1e-12)
    c = np.array(U0.shape) // 2
    k = np.argmin(((idx - c) ** 2).sum(axis=1))
    return tuple(int(v) for v in idx[k])


@dataclass(frozen=True)
class StateSummary:
    """Scalar outputs of one equilibrium."""

    F: float
    contact_length: float
    area_repulsive: float
    charged_fraction: float
    min_gap: float
    max_pressure: float
    min_pressure: float


def summarize(P: np.ndarray, H: np.ndarray, grid: Grid, apex: tuple[int, int], law=None,
              periodic: bool = False) -> StateSummary:
    """The scalar outputs of one equilibrium; the charged area with ``law``'s peak separation (the paper's
    law without one) on a free (or ``periodic``) cell."""
    g_c, opening = (PAPER_PEAK_SEPARATION, 1.0) if law is None else law_edge(law)
    return StateSummary(
        F=force(P, grid),
        contact_length=contact_length(P, grid, apex),
        area_repulsive=repulsive_area(P, grid),
        charged_fraction=charged_area(H, grid, g_c, opening, periodic) / (grid.nx * grid.ny * grid.area),
        min_gap=float(H.min()),
        max_pressure=float(P.max()),
        min_pressure=float(P.min()),
    )


def edge_radius(H: np.ndarray, grid: Grid, apex: tuple[int, int], window: float = 2.5) -> float:
    """Radius a of the closed zone H <= 0 (g <= 1, Maugis' contact) around ``apex``, sub-pixel.

    At the edge of an adhesive (Dugdale-like) contact the stress intensity vanishes and the gap opens
    as H ≈ β (r − a)^{3/2}; so y = H^{2/3} is linear in r just outside the edge.  The pixels with
    H > 0 whose centre radius r lies within ``window``·dx outside the outermost closed pixel give a
    least-squares line y = β^{2/3}(r − a), and a is its root.  Unlike sqrt(area/π), a moves
    continuously with the state (the pixel lattice only adds scatter).  0 if the apex pixel is open;
    NaN if fewer than 3 open pixels lie in the window (the zone reaches the cell's edge).
    """
    i0, j0 = apex
    if H[i0, j0] > 0:
        return 0.0
    x = (np.arange(grid.nx) - i0) * grid.dx
    y = (np.arange(grid.ny) - j0) * grid.dy
    r = np.hypot(x[:, None], y[None, :])
    r_in = float(r[H <= 0].max())
    sel = (H > 0) & (r <= r_in + window * max(grid.dx, grid.dy))
    if np.count_nonzero(sel) < 3:
        return float("nan")
    slope, icpt = np.polyfit(r[sel], H[sel] ** (2.0 / 3.0), 1)
    return float(-icpt / slope) if slope > 0 else float("nan")


def quadratic_vertex(x, F, n: int = 7) -> tuple[float, float]:
    """(x*, F*) at the minimum of F(x): vertex of the least-squares parabola through the ``n`` samples
    nearest (in sample order) to the smallest F.  For the sphere's pull-off with x the contact radius
    a this is Maugis' condition dF/da = 0, well posed where the row with the least F is not (dF/dD = 0
    there too).  Raises TengsimError if the parabola opens downwards or its vertex lies outside the
    samples used."""
    from tengsim.errors import TengsimError

    x = np.asarray(x, dtype=float)
    F = np.asarray(F, dtype=float)
    if x.shape != F.shape or len(x) < 3 or n < 3:
        raise TengsimError(f"need at least 3 samples of x and F (got {len(x)}) and n >= 3 (got {n})")
    i = int(np.argmin(F))
    lo = max(0, min(i - n // 2, len(F) - n))
    xs, Fs = x[lo:lo + n], F[lo:lo + n]
    c2, c1, c0 = np.polyfit(xs, Fs, 2)
    if not c2 > 0:
        raise TengsimError("quadratic_vertex: the parabola through the samples has no minimum")
    xv = -c1 / (2 * c2)
    if not xs.min() <= xv <= xs.max():
        raise TengsimError(f"quadratic_vertex: vertex x = {xv:.6g} outside the samples [{xs.min():.6g}, {xs.max():.6g}]")
    return float(xv), float(c0 - c1 * c1 / (4 * c2))
