"""A user surface given as an array of heights."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tengsim.errors import TengsimError, positive
from tengsim.grid import Grid
from tengsim.shapes.base import Shape


@dataclass(frozen=True, eq=False)
class HeightMap(Shape):
    """Any user surface given as heights z (larger = higher, closer to the plate), U0 = max z − z."""

    heights: np.ndarray
    cell: float

    def __post_init__(self):
        z = np.asarray(self.heights, dtype=float)
        if z.ndim != 2 or min(z.shape) < 3:
            raise TengsimError(f"height map must be a 2-D array of at least 3×3, got shape {z.shape}")
        if not np.all(np.isfinite(z)):
            raise TengsimError("height map contains NaN or infinite values")
        positive("cell", self.cell)
        object.__setattr__(self, "heights", z)

    def grid(self, dx: float | None = None) -> Grid:
        """The map's own grid (pixel cell/nx); a ``dx`` that differs from that pixel is refused."""
        nx, ny = self.heights.shape
        h = self.cell / nx
        if dx is not None and abs(positive("dx", dx) - h) > 1e-9 * h:
            raise TengsimError(f"dx={dx:g} does not match the height map's pixel {h:g} (cell {self.cell:g} / "
                               f"{nx} pixels); resample the map or give dx={h:g}")
        return Grid(nx, ny, h, h)

    def gap(self, grid: Grid) -> np.ndarray:
        if grid.shape != self.heights.shape:
            raise TengsimError(f"grid shape {grid.shape} does not match height map {self.heights.shape}")
        return self.heights.max() - self.heights
