"""Initial gap U0(X, Y) >= 0 of the elastic surface, in units of the interaction range ε.

All shapes are dimensionless (paper Eq. 7): lengths in the plane are X = x n/(ε m) for the paper's
pyramid (or any lateral scale ℓ for other shapes), heights are U0 = h0/ε.  The apex is at the origin,
where U0 = 0.  Every shape has ``gap(grid)`` and ``params()``.
"""
from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from tengsim.errors import TengsimError, positive
from tengsim.grid import Grid


class Shape:
    """Base of all shapes: ``gap(grid)`` gives U0 on the grid, ``cell`` a natural cell side."""

    cell: float

    def gap(self, grid: Grid) -> np.ndarray:  # pragma: no cover - abstract
        raise NotImplementedError

    def params(self) -> dict:
        d = {k: v for k, v in asdict(self).items() if not isinstance(v, np.ndarray)}
        d["shape"] = type(self).__name__
        return d

    def grid(self, dx: float) -> Grid:
        """A square grid over the shape's cell with spacing about ``dx``."""
        return Grid.square(self.cell, dx)


@dataclass(frozen=True)
class Pyramid(Shape):
    """Square pyramid in a square unit cell, paper Eqs. (5)/(11).

    U0 = |X − Y| + |X + Y| = 2 max(|X|, |Y|) inside [−N, N]², 2N outside; the cell is
    [−L̄/2, L̄/2]² with ``cell`` = L̄.  ``N`` = n/(2ε).
    """

    N: float
    cell: float

    def __post_init__(self):
        positive("pyramid N", self.N)
        positive("cell", self.cell)
        if 2 * self.N > self.cell * (1 + 1e-12):
            raise TengsimError(
                f"pyramid base 2N = {2 * self.N:g} is wider than its cell L̄ = {self.cell:g}"
            )

    @classmethod
    def from_physical(cls, pitch: float, base: float, height: float, eps: float) -> "Pyramid":
        """From pitch L, base m, height n and interaction range ε (any one length unit), Eq. (7)."""
        pitch, base = positive("pitch", pitch), positive("base", base)
        height, eps = positive("height", height), positive("eps", eps)
        if base > pitch:
            raise TengsimError(f"pyramid base {base:g} is wider than its pitch {pitch:g}")
        return cls(N=height / (2 * eps), cell=pitch * height / (eps * base))

    def gap(self, grid: Grid) -> np.ndarray:
        X, Y = grid.mesh()
        return np.minimum(2 * np.maximum(np.abs(X), np.abs(Y)), 2 * self.N)


@dataclass(frozen=True)
class Paraboloid(Shape):
    """Sphere in the Hertz (paraboloid) approximation, U0 = (X² + Y²)/(2R).

    With lateral scale ℓ = sqrt(R_phys ε) the radius is R = 1 and the coupling is μ^{3/2} with
    Tabor's μ = (R W²/(E*² ε³))^{1/3}.
    """

    radius: float = 1.0
    cell: float = 10.0

    def __post_init__(self):
        positive("radius", self.radius)
        positive("cell", self.cell)

    def gap(self, grid: Grid) -> np.ndarray:
        X, Y = grid.mesh()
        return (X**2 + Y**2) / (2 * self.radius)


@dataclass(frozen=True)
class Hemisphere(Shape):
    """Exact hemisphere of radius R on a flat base, U0 = R − sqrt(R² − r²) for r < R, R outside."""

    radius: float
    cell: float

    def __post_init__(self):
        positive("radius", self.radius)
        positive("cell", self.cell)
        if 2 * self.radius > self.cell:
            raise TengsimError(f"hemisphere diameter {2 * self.radius:g} exceeds its cell {self.cell:g}")

    def gap(self, grid: Grid) -> np.ndarray:
        X, Y = grid.mesh()
        r2 = np.minimum(X**2 + Y**2, self.radius**2)
        return self.radius - np.sqrt(self.radius**2 - r2)


@dataclass(frozen=True)
class Cone(Shape):
    """Axisymmetric cone U0 = slope · r (slope = tan of the surface inclination), capped at ``height``."""

    slope: float
    cell: float
    height: float = np.inf

    def __post_init__(self):
        positive("slope", self.slope)
        positive("cell", self.cell)
        if not self.height > 0:
            raise TengsimError(f"cone height must be > 0, got {self.height!r}")

    def gap(self, grid: Grid) -> np.ndarray:
        X, Y = grid.mesh()
        return np.minimum(self.slope * np.hypot(X, Y), self.height)


@dataclass(frozen=True)
class FlatPunch(Shape):
    """Circular flat-ended punch of radius a: U0 = 0 for r <= a, ``step`` outside."""

    radius: float
    cell: float
    step: float = 50.0

    def __post_init__(self):
        positive("radius", self.radius)
        positive("cell", self.cell)
        positive("step", self.step)

    def gap(self, grid: Grid) -> np.ndarray:
        X, Y = grid.mesh()
        return np.where(np.hypot(X, Y) <= self.radius, 0.0, self.step)


@dataclass(frozen=True)
class Cube(Shape):
    """Square flat-topped pillar (cube pattern): U0 = 0 on [−a, a]², ``height`` outside."""

    half_width: float
    height: float
    cell: float

    def __post_init__(self):
        positive("half_width", self.half_width)
        positive("height", self.height)
        positive("cell", self.cell)
        if 2 * self.half_width > self.cell:
            raise TengsimError(f"cube width {2 * self.half_width:g} exceeds its cell {self.cell:g}")

    def gap(self, grid: Grid) -> np.ndarray:
        X, Y = grid.mesh()
        inside = (np.abs(X) <= self.half_width) & (np.abs(Y) <= self.half_width)
        return np.where(inside, 0.0, self.height)


@dataclass(frozen=True)
class Line(Shape):
    """Ridge along Y (line pattern): flat top |X| <= a at U0 = 0, ``height`` elsewhere."""

    half_width: float
    height: float
    cell: float

    def __post_init__(self):
        positive("half_width", self.half_width)
        positive("height", self.height)
        positive("cell", self.cell)

    def gap(self, grid: Grid) -> np.ndarray:
        X, _ = grid.mesh()
        return np.where(np.abs(X) <= self.half_width, 0.0, self.height)


@dataclass(frozen=True)
class Sinusoid1D(Shape):
    """1-D sinusoid U0 = Δ (1 − cos(2πX/λ)) (peak-to-valley 2Δ); use the periodic kernel."""

    wavelength: float
    amplitude: float

    def __post_init__(self):
        positive("wavelength", self.wavelength)
        positive("amplitude", self.amplitude)

    @property
    def cell(self) -> float:
        return self.wavelength

    def gap(self, grid: Grid) -> np.ndarray:
        X, _ = grid.mesh()  # an odd, cell-centred grid puts the crest (U0 = 0) on the centre pixel
        return self.amplitude * (1 - np.cos(2 * np.pi * X / self.wavelength))


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
        nx, ny = self.heights.shape
        return Grid(nx, ny, self.cell / nx, self.cell / nx)

    def gap(self, grid: Grid) -> np.ndarray:
        if grid.shape != self.heights.shape:
            raise TengsimError(f"grid shape {grid.shape} does not match height map {self.heights.shape}")
        return self.heights.max() - self.heights


def random_rough(n: int, cell: float, hurst: float = 0.8, rms_height: float = 1.0,
                 short_cutoff: float | None = None, seed: int = 0) -> HeightMap:
    """Periodic self-affine random surface (power spectrum C(q) ~ q^{-2(1+H)}) with given rms height."""
    rng = np.random.default_rng(seed)
    qx = 2 * np.pi * np.fft.fftfreq(n, d=cell / n)
    q = np.hypot(*np.meshgrid(qx, qx, indexing="ij"))
    q0 = 2 * np.pi / cell
    qs = 2 * np.pi / short_cutoff if short_cutoff else np.inf
    amp = np.where((q >= q0) & (q <= qs), np.maximum(q, q0) ** (-(1 + hurst)), 0.0)
    spec = amp * np.exp(2j * np.pi * rng.random((n, n)))
    z = np.fft.ifft2(spec).real
    z *= rms_height / z.std()
    return HeightMap(z, cell)
