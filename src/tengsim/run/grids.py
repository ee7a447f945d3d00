"""The refinement's grids: the first grid's spacing and the sequence of finer grids that keeps a shape's edges in place.

:func:`default_dx` is the first grid's spacing of a refinement; :func:`start_dx` the same sequence's first grid
fine enough for a process zone of a given number of pixels (a design's start).  :func:`next_grid` is the grid
after a spacing ``dx``: the plain grid of the cell at ``dx`` moved, for a shape with kinks, to the first
FFT-friendly grid whose edges fall where the first grid's did (:func:`aligned`; why: :mod:`tengsim.run.resolve`,
"Edges kept in place"), skipping a pixel count already walked.  :func:`grid_sequence` gives the sequence (:func:`refinement_grids` its first grids), so
whoever plans a refinement (its cost, its budget) plans on the grids :func:`tengsim.run.resolve.resolve`
walks.
"""
from __future__ import annotations

import itertools
import math

from tengsim import backend
from tengsim.grid import Grid
from tengsim.run.memory import check_memory

FACTOR = math.sqrt(2.0)
"""Refinement factor in dx between two grids (twice the pixels)."""
MIN_SIDE = 9
"""Fewest pixels across the cell of a default starting grid."""
PHASE_TOL = 0.1
"""How far (in pixels) a shape's edge may sit from its place in the first grid's pixel on a finer grid."""
PHASE_SPAN = 1.3
"""Largest pixel count, relative to the plain next grid's, searched for a grid that keeps the edges' places."""


def default_dx(shape, law, coupling: float, boundary: str = "free") -> float:
    """Starting dx when none is given: the a-priori Dugdale zone ℓ_D (:func:`tengsim.status.process_zone_estimate`)
    over ``status.RESOLUTION`` (the zone spans the pixels the grid status asks for) and the dx at which the pixel
    snap number s ∝ dx (:func:`tengsim.status.pixel_snap_number`, measured on a grid of the cell) falls to
    ``status.SNAP_LIMIT``, whichever is
    smaller, and at most cell/MIN_SIDE.  Coarser grids are under-resolved by those criteria whatever their
    observables do, so they would only be spent."""
    from tengsim import status
    from tengsim.kernels import make_kernel

    cell = float(getattr(shape, "cell"))
    dx = cell / MIN_SIDE
    lD = status.process_zone_estimate(law, coupling)
    if math.isfinite(lD) and lD > 0:
        dx = min(dx, lD / status.RESOLUTION)  # the zone spans the pixels the status asks for
    g = shape.grid(dx)
    check_memory(g.nx, g.ny, boundary)  # the kernel below is the grid's: one line, not an allocation that fails
    s = status.pixel_snap_number(law, make_kernel(boundary, g, coupling))
    if s > status.SNAP_LIMIT:
        dx = g.dx * status.SNAP_LIMIT / s
    return dx


def edge_phases(shape, grid) -> tuple:
    """Where each of the shape's edges (``Shape.edge_offsets``, from the centre pixel along X) falls in its
    pixel on ``grid``: the fractional part of offset/dx, in [0, 1)."""
    offsets = getattr(shape, "edge_offsets", lambda: ())()
    return tuple(float((e / grid.dx) % 1.0) for e in offsets)


def aligned(shape, grid, phases, max_pixels: int):
    """``grid`` or, for a shape with edges, the first plain square grid of the same cell with FFT-friendly odd
    pixel count between grid.nx and PHASE_SPAN × grid.nx (and within ``max_pixels``) whose edges fall where the
    first grid's did (``phases``, to PHASE_TOL of a pixel); ``grid`` itself if none does."""
    if not phases or type(grid) is not Grid or grid.nx != grid.ny:
        return grid
    L = grid.nx * grid.dx
    n, top = grid.nx, min(int(PHASE_SPAN * grid.nx), int(math.isqrt(int(max_pixels))))
    while n <= top:
        g = Grid(n, n, L / n, L / n)
        if all(min(abs(a - b), 1.0 - abs(a - b)) <= PHASE_TOL for a, b in zip(edge_phases(shape, g), phases)):
            return g
        n = backend.fast_odd_len(n + 2)
    return grid


def next_grid(shape, dx: float, phases: tuple, seen, max_pixels: int = 2**40):
    """The refinement's grid at spacing ``dx`` after a first grid whose edges fell at ``phases``
    (:func:`edge_phases`; None: this is the first grid): :func:`aligned`, and one √2 step further while its
    pixel count is one of ``seen`` (the FFT-friendly count did not change)."""
    while True:
        grid = shape.grid(dx)
        if phases is not None:
            grid = aligned(shape, grid, phases, max_pixels)
        if (grid.nx, grid.ny) not in seen:
            return grid
        dx /= FACTOR


def grid_sequence(shape, dx: float, max_pixels: int = 2**40):
    """The grids the refinement walks from a first grid of spacing ``dx`` (:func:`next_grid`), one at a time and
    without end: a caller stops when it has what it needs (a grid past the cell's pixel limit raises)."""
    seen, phases = set(), None
    while True:
        g = next_grid(shape, dx, phases, seen, max_pixels)
        if phases is None:
            phases = edge_phases(shape, g)
        seen.add((g.nx, g.ny))
        yield g
        dx = g.dx / FACTOR


class GridSequence:
    """The grids the refinement walks from a first grid of spacing ``dx`` (:func:`grid_sequence`), each computed
    once, when first asked for (by index, slice or iteration), and kept: one sequence for whoever plans a
    refinement (its cost, its budget, the next grid's line) and the refinement itself."""

    def __init__(self, shape, dx: float, max_pixels: int = 2**40):
        self.dx = dx
        self._gen, self._grids = grid_sequence(shape, dx, max_pixels), []

    def _upto(self, n: int) -> None:
        while len(self._grids) < n:
            self._grids.append(next(self._gen))

    def __getitem__(self, k):
        if isinstance(k, slice):
            if k.stop is None or k.stop < 0 or (k.start or 0) < 0:
                raise ValueError("a GridSequence (without end) is sliced with non-negative bounds")
            self._upto(k.stop)
        else:
            self._upto(k + 1)
        return self._grids[k]

    def __iter__(self):
        i = 0
        while True:
            self._upto(i + 1)
            yield self._grids[i]
            i += 1


def refinement_grids(shape, dx: float, count: int = 12, max_pixels: int = 2**40) -> list:
    """The first ``count`` grids of :func:`grid_sequence`."""
    return list(itertools.islice(grid_sequence(shape, dx, max_pixels), count))


def start_dx(shape, law, coupling: float, boundary: str = "free", zone_pixels: float | None = None) -> float:
    """The first grid's dx: :func:`default_dx` or, given ``zone_pixels``, the first grid of the refinement from
    it (:func:`refinement_grids`) whose dx is at most the law's a-priori process zone over ``zone_pixels``: the
    same grids as from the default start, less those too coarse to be the last."""
    from tengsim import status

    dx = default_dx(shape, law, coupling, boundary)
    if zone_pixels is None:
        return dx
    zone = status.process_zone_estimate(law, coupling)
    if not (math.isfinite(zone) and zone > 0) or dx <= zone / zone_pixels:
        return dx
    for g in refinement_grids(shape, dx):
        if g.dx <= zone / zone_pixels:
            return g.dx
    return zone / zone_pixels
