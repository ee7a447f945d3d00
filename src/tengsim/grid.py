"""Surface grid: cell-centred square pixels on a rectangle centred at the origin."""
from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from tengsim import backend
from tengsim.backend import fft as _bf
from tengsim.errors import GeometryError, TengsimError, positive


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
            raise GeometryError("dx {dx} is too coarse for a cell of length {length} (need >= 3 pixels)", dx=dx,
                                length=length)
        from tengsim.resources import MAX_PIXELS_PER_SIDE

        if not length / dx <= MAX_PIXELS_PER_SIDE:  # before any count or allocation (also: an overflow to inf)
            raise GeometryError("a cell of length {length} at dx {dx} is " + f"{length / dx:.3g} pixels per side; "
                                f"at most {MAX_PIXELS_PER_SIDE} are allowed: use a larger dx or a smaller cell",
                                length=length, dx=dx)
        n = max(3, int(round(length / dx)))
        # FFT-friendly pixel counts (small prime factors), odd so that a pixel sits on the apex
        n = backend.fast_odd_len(n) if odd else backend.fast_len(n)
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


@dataclass(frozen=True)
class Mirror:
    """Mirror symmetry of fields on an odd ``grid`` about its centre pixel, along ``axes`` (0: X, 1: Y).

    The irreducible block holds the centre pixel and the pixels after it along each mirrored axis:
    reduced index i is full index c + i (c = (n − 1)/2), and full index c − i holds the same value.
    A pixel of the block stands for ``weights()`` pixels of the full grid (1 on a mirror line, 2 off
    it, per mirrored axis), so a full-grid sum is the weighted sum over the block.
    """

    grid: Grid
    axes: tuple

    def __post_init__(self):
        axes = tuple(sorted(set(int(a) for a in self.axes)))
        if not axes or any(a not in (0, 1) for a in axes):
            raise TengsimError(f"mirror axes must be a non-empty subset of (0, 1), got {self.axes!r}")
        for a in axes:
            n = self.grid.shape[a]
            if n % 2 == 0 or n < 5:
                raise TengsimError(f"a mirror along axis {a} needs an odd pixel count >= 5, got {n}")
        object.__setattr__(self, "axes", axes)

    def _centre(self, a: int) -> int:
        return (self.grid.shape[a] - 1) // 2

    @property
    def reduced_shape(self) -> tuple[int, int]:
        return tuple(n - self._centre(a) if a in self.axes else n for a, n in enumerate(self.grid.shape))

    @property
    def reduced_grid(self) -> Grid:
        """The block's grid: same pixel size (pixel area ``grid.area``), reduced counts."""
        nx, ny = self.reduced_shape
        return Grid(nx, ny, self.grid.dx, self.grid.dy)

    @property
    def fraction(self) -> float:
        """Pixels of the block over pixels of the full grid."""
        return float(np.prod(self.reduced_shape)) / float(np.prod(self.grid.shape))

    def reduce(self, a: np.ndarray) -> np.ndarray:
        """The irreducible block of a full-grid field (a contiguous copy)."""
        a = np.asarray(a)
        if a.shape != self.grid.shape:
            raise TengsimError(f"field of shape {a.shape} is not on the {self.grid.shape} grid")
        sl = tuple(slice(self._centre(k), None) if k in self.axes else slice(None) for k in range(2))
        return np.ascontiguousarray(a[sl])

    def unfold(self, r: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
        """The full-grid field whose irreducible block is ``r`` (mirrored copies), into ``out`` if given."""
        r = np.asarray(r)
        if r.shape != self.reduced_shape:
            raise TengsimError(f"block of shape {r.shape} is not the {self.reduced_shape} block")
        out = np.empty(self.grid.shape, dtype=r.dtype) if out is None else out
        c = [self._centre(k) if k in self.axes else 0 for k in range(2)]
        out[c[0]:, c[1]:] = r
        if 0 in self.axes:  # row c0 - i is row c0 + i
            out[:c[0], c[1]:] = r[:0:-1, :]
        if 1 in self.axes:  # column c1 - j is column c1 + j
            out[:, :c[1]] = out[:, :c[1]:-1]
        return out

    def weights(self) -> np.ndarray:
        """Multiplicity of each block pixel in the full grid (1, 2 or 4), shape ``reduced_shape``."""
        w = np.ones(self.reduced_shape)
        for k in self.axes:
            m = np.full(self.reduced_shape[k], 2.0)
            m[0] = 1.0
            w *= m[:, None] if k == 0 else m[None, :]
        return w

    def is_symmetric(self, a: np.ndarray, rtol: float = 1e-12) -> bool:
        """Is the full-grid field ``a`` mirror symmetric along every axis of the mirror (to ``rtol``)?"""
        a = np.asarray(a, dtype=float)
        scale = max(float(np.max(np.abs(a))) if a.size else 0.0, 1e-300)
        return all(float(np.max(np.abs(a - np.flip(a, axis=k)))) <= rtol * scale for k in self.axes)


def fourier_resample(a: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
    """Resample a periodic real field to ``shape`` by truncating or zero-padding its spectrum.

    Keeps the wavenumbers |k| below both grids' Nyquist limits (the Nyquist row/column is dropped),
    so the mean and every resolved harmonic are preserved exactly.
    """
    n0, n1 = a.shape
    m0, m1 = shape
    A = _bf.np_rfft2(a)
    B = np.zeros((m0, m1 // 2 + 1), complex)
    k0 = min(n0, m0) // 2
    k1 = min(n1, m1) // 2
    B[:k0, :k1] = A[:k0, :k1]
    if k0 > 1:
        B[-(k0 - 1):, :k1] = A[-(k0 - 1):, :k1]
    return _bf.np_irfft2(B, s=shape) * (m0 * m1 / (n0 * n1))
