"""Surface grid: cell-centred square pixels on a rectangle centred at the origin."""
from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from tengsim.errors import TengsimError, positive


@dataclass(frozen=True)
class Grid:
    """``nx`` × ``ny`` pixels of size ``dx`` × ``dy`` covering [-Lx/2, Lx/2] × [-Ly/2, Ly/2].

    Pixel centres are at ``x_i = (i - (nx - 1)/2) dx``; an odd count puts a pixel on the origin.
    """

    nx: int
    ny: int
    dx: float
    dy: float

    def __post_init__(self):
        for name in ("nx", "ny"):
            v = getattr(self, name)
            if int(v) != v or v < 3:
                raise TengsimError(f"grid {name} must be an integer >= 3, got {v!r}")
        positive("grid dx", self.dx)
        positive("grid dy", self.dy)

    @classmethod
    def square(cls, length: float, dx: float, odd: bool = True) -> "Grid":
        """A square grid of side ``length`` with spacing close to (at most) ``dx``: the pixel count is
        the next FFT-friendly one (odd, prime factors 3 to 13 only, by default)."""
        length = positive("cell length", length)
        dx = positive("dx", dx)
        if dx > length / 3:
            raise TengsimError(f"dx={dx} is too coarse for a cell of length {length} (need >= 3 pixels)")
        from tengsim import _fft

        n = max(3, int(round(length / dx)))
        # FFT-friendly pixel counts (small prime factors), odd so that a pixel sits on the apex
        n = _fft.fast_odd_len(n) if odd else _fft.fast_len(n)
        return cls(n, n, length / n, length / n)

    @property
    def shape(self) -> tuple[int, int]:
        return (self.nx, self.ny)

    @property
    def lx(self) -> float:
        return self.nx * self.dx

    @property
    def ly(self) -> float:
        return self.ny * self.dy

    @property
    def area(self) -> float:
        """Area of one pixel."""
        return self.dx * self.dy

    @cached_property
    def x(self) -> np.ndarray:
        return (np.arange(self.nx) - (self.nx - 1) / 2) * self.dx

    @cached_property
    def y(self) -> np.ndarray:
        return (np.arange(self.ny) - (self.ny - 1) / 2) * self.dy

    def mesh(self) -> tuple[np.ndarray, np.ndarray]:
        """Coordinate arrays X, Y of shape ``(nx, ny)`` (indexing 'ij')."""
        return np.meshgrid(self.x, self.y, indexing="ij")
