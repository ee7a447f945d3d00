"""Initial gap U0(X, Y) >= 0 of the elastic surface, in units of the interaction range ε.

All shapes are dimensionless (paper Eq. 7): heights are U0 = h0/ε, lengths in the plane X = x/ℓ with
a lateral scale ℓ each shape chooses so that its dimensionless form is simplest (the paper's pyramid:
ℓ = ε m/n).  The apex is at the origin, where U0 = 0.  Every shape has ``gap(grid)``, ``grid(dx)``
and ``params()``.

A registered shape also declares its input: its dimensionless fields are its dataclass fields, its
physical fields (with dimensions) are ``physical_fields``, and ``from_si(values, eps)`` builds it
from SI input with the lateral scale ``lateral_scale(values, eps)`` (then κ = W ℓ/(E* ε²) = μ^{3/2}).
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from tengsim.errors import TengsimError, positive
from tengsim.grid import Grid
from tengsim.registry import SHAPES
from tengsim.schema import REQUIRED, Field, dataclass_fields


def _length(name, help, default=REQUIRED):
    return Field(name, "float", default, dim="length", help=help)


class Shape:
    """Base of all shapes: ``gap(grid)`` gives U0 on the grid, ``cell`` a natural cell side.

    Class attributes a shape may set: ``physical_fields`` (schema Fields with dimensions: the
    physical input), ``field_help`` (help text of the dimensionless fields), ``lateral_unit`` (the
    text of ℓ for result metadata).  With physical fields, a shape overrides ``lateral_scale`` and
    ``from_si``; shapes with ℓ = ε can instead set ``si_map`` (physical name → dimensionless name,
    each length divided by ε).
    """

    cell: float
    physical_fields: tuple = ()
    field_help: dict = {}
    lateral_unit: str = "ℓ"
    si_map: dict = {}

    def gap(self, grid: Grid) -> np.ndarray:  # pragma: no cover - abstract
        raise NotImplementedError

    def params(self) -> dict:
        d = {k: v for k, v in asdict(self).items() if not isinstance(v, np.ndarray)}
        d["shape"] = type(self).__name__
        return d

    def grid(self, dx: float) -> Grid:
        """A square grid over the shape's cell with spacing about ``dx``."""
        return Grid.square(self.cell, dx)

    # ---- declared input -----------------------------------------------------------------------
    @classmethod
    def dimensionless_fields(cls) -> tuple:
        """Schema fields of the dimensionless input: the dataclass fields (plain numbers, no units)."""
        return dataclass_fields(cls, helps=cls.field_help)

    @classmethod
    def lateral_scale(cls, values: dict, eps: float) -> float:
        """ℓ (m per unit of X) for physical ``values`` (SI) and interaction range ``eps`` (m)."""
        if cls.si_map:
            return eps
        raise TengsimError(f"shape {SHAPES.name_of(cls)} has no physical input")

    @classmethod
    def from_si(cls, values: dict, eps: float) -> "Shape":
        """The dimensionless shape for physical ``values`` (SI, the keys of ``physical_fields``)."""
        if not cls.si_map:
            raise TengsimError(f"shape {SHAPES.name_of(cls)} has no physical input")
        kw = {}
        for k, v in values.items():
            if v is None:
                continue
            f = next(f for f in cls.physical_fields if f.name == k)
            kw[cls.si_map.get(k, k)] = v / eps if f.dim == "length" else v
        return cls(**kw)

    @classmethod
    def eps_from_tabor(cls, values: dict, E_star: float, W: float, mu: float) -> float:
        """ε (m) giving the Tabor parameter ``mu``: κ(ε) = W ℓ(ε)/(E* ε²) = μ^{3/2}, solved numerically
        (shapes with a closed form override this)."""
        from tengsim.units import eps_for_tabor

        if cls.si_map and cls.lateral_scale.__func__ is Shape.lateral_scale.__func__:
            # ℓ = ε: κ = W/(E* ε), so ε = W/(E* μ^{3/2})
            return positive("W", W) / (positive("E_star", E_star) * positive("tabor", mu) ** 1.5)
        return eps_for_tabor(lambda e: cls.lateral_scale(values, e), E_star, W, mu)


@dataclass(frozen=True)
class Pyramid(Shape):
    """Square pyramid in a square unit cell, paper Eqs. (5)/(11).

    U0 = |X − Y| + |X + Y| = 2 max(|X|, |Y|) inside [−N, N]², 2N outside; the cell is
    [−L̄/2, L̄/2]² with ``cell`` = L̄.  ``N`` = n/(2ε).
    """

    N: float
    cell: float

    physical_fields = (_length("pitch", "pitch L (cell side)"), _length("base", "base width m"),
                       _length("height", "height n"))
    field_help = {"N": "n/(2ε): half the base in X, the height in ε over 2", "cell": "cell side L̄ = L n/(ε m)"}
    lateral_unit = "ε m/n"

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

    @classmethod
    def lateral_scale(cls, values, eps):
        """ℓ = ε m/n (paper Eq. 7)."""
        return eps * positive("base", values["base"]) / positive("height", values["height"])

    @classmethod
    def from_si(cls, values, eps):
        return cls.from_physical(values["pitch"], values["base"], values["height"], eps)

    @classmethod
    def eps_from_tabor(cls, values, E_star, W, mu):
        """Closed form: ε = m W/(n E* μ^{3/2})."""
        return values["base"] * W / (values["height"] * positive("E_star", E_star) * positive("tabor", mu) ** 1.5)

    def gap(self, grid: Grid) -> np.ndarray:
        X, Y = grid.mesh()
        return np.minimum(2 * np.maximum(np.abs(X), np.abs(Y)), 2 * self.N)


@dataclass(frozen=True)
class Paraboloid(Shape):
    """Sphere in the Hertz (paraboloid) approximation, U0 = (X² + Y²)/(2R).

    Physical input (radius R, pitch): ℓ = sqrt(R ε), so the dimensionless radius is 1, the cell
    pitch/ℓ, and the coupling μ^{3/2} with Tabor's μ = (R W²/(E*² ε³))^{1/3}.
    """

    radius: float = 1.0
    cell: float = 10.0

    physical_fields = (_length("radius", "sphere radius R"), _length("pitch", "cell side (default 10 ℓ)", None))
    field_help = {"radius": "radius in X units (1 with ℓ = sqrt(Rε))", "cell": "cell side"}
    lateral_unit = "sqrt(R ε)"

    @classmethod
    def lateral_scale(cls, values, eps):
        """ℓ = sqrt(R ε)."""
        return math.sqrt(positive("radius", values["radius"]) * eps)

    @classmethod
    def from_si(cls, values, eps):
        lat = cls.lateral_scale(values, eps)
        pitch = values.get("pitch")
        # U0 = r²/(2Rε) = X² ℓ²/(2Rε) = X²/2: the dimensionless radius is Rε/ℓ² = 1
        cell = {} if pitch is None else {"cell": positive("pitch", pitch) / lat}
        return cls(radius=values["radius"] * eps / lat**2, **cell)

    @classmethod
    def eps_from_tabor(cls, values, E_star, W, mu):
        """Closed form: ε = (sqrt(R) W/(E* μ^{3/2}))^{2/3}."""
        R = positive("radius", values["radius"])
        return (math.sqrt(R) * W / (positive("E_star", E_star) * positive("tabor", mu) ** 1.5)) ** (2 / 3)

    def __post_init__(self):
        positive("radius", self.radius)
        positive("cell", self.cell)

    def gap(self, grid: Grid) -> np.ndarray:
        X, Y = grid.mesh()
        return (X**2 + Y**2) / (2 * self.radius)


@dataclass(frozen=True)
class Hemisphere(Shape):
    """Exact hemisphere of radius ρ on a flat base, U0 = k(ρ − sqrt(ρ² − r²)) for r < ρ, kρ outside.

    ``k`` = ℓ/ε is the ratio of the lateral to the vertical unit (k = 1: both ε).  Physical input
    (radius R, pitch): ℓ = sqrt(R ε), ρ = R/ℓ, k = ℓ/ε, cell = pitch/ℓ, so U0 = h0/ε exactly.
    """

    radius: float = 3.0
    cell: float = 10.0
    k: float = 1.0

    physical_fields = (_length("radius", "hemisphere radius R"), _length("pitch", "cell side"))
    field_help = {"radius": "radius ρ in X units", "cell": "cell side",
                  "k": "lateral/vertical unit ratio ℓ/ε (1: X and U0 both in ε)"}
    lateral_unit = "sqrt(R ε)"

    def __post_init__(self):
        positive("radius", self.radius)
        positive("cell", self.cell)
        positive("k", self.k)
        if 2 * self.radius > self.cell:
            raise TengsimError(f"hemisphere diameter {2 * self.radius:g} exceeds its cell {self.cell:g}")

    @classmethod
    def lateral_scale(cls, values, eps):
        """ℓ = sqrt(R ε)."""
        return math.sqrt(positive("radius", values["radius"]) * eps)

    @classmethod
    def from_si(cls, values, eps):
        lat = cls.lateral_scale(values, eps)
        return cls(radius=values["radius"] / lat, cell=positive("pitch", values["pitch"]) / lat, k=lat / eps)

    @classmethod
    def eps_from_tabor(cls, values, E_star, W, mu):
        """Closed form (as the sphere's): ε = (sqrt(R) W/(E* μ^{3/2}))^{2/3}."""
        return Paraboloid.eps_from_tabor(values, E_star, W, mu)

    def gap(self, grid: Grid) -> np.ndarray:
        X, Y = grid.mesh()
        r2 = np.minimum(X**2 + Y**2, self.radius**2)
        return self.k * (self.radius - np.sqrt(self.radius**2 - r2))


@dataclass(frozen=True)
class Cone(Shape):
    """Axisymmetric cone U0 = slope · r (slope = tan of the surface inclination), capped at ``height``.

    Physical input (slope, pitch, optional height): ℓ = ε/slope, so the dimensionless slope is 1, the
    cell pitch/ℓ and the cap height/ε.
    """

    slope: float = 1.0
    cell: float = 10.0
    height: float = np.inf

    physical_fields = (Field("slope", "float", REQUIRED, help="tan of the surface inclination"),
                       _length("pitch", "cell side"), _length("height", "cap height (default: none)", None))
    field_help = {"slope": "tan of the surface inclination", "cell": "cell side",
                  "height": "cap height in ε (default: none)"}
    lateral_unit = "ε/slope"

    @classmethod
    def lateral_scale(cls, values, eps):
        """ℓ = ε/slope."""
        return eps / positive("slope", values["slope"])

    @classmethod
    def from_si(cls, values, eps):
        lat = cls.lateral_scale(values, eps)
        h = values.get("height")
        return cls(slope=1.0, cell=positive("pitch", values["pitch"]) / lat,
                   height=np.inf if h is None else positive("height", h) / eps)

    @classmethod
    def eps_from_tabor(cls, values, E_star, W, mu):
        """Closed form: κ = W/(E* slope ε), so ε = W/(E* slope μ^{3/2})."""
        return positive("W", W) / (positive("E_star", E_star) * positive("slope", values["slope"])
                                   * positive("tabor", mu) ** 1.5)

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
    """Circular flat-ended punch of radius a: U0 = 0 for r <= a, ``step`` outside.

    Physical input (radius, step, pitch): ℓ = ε, every length divided by ε.
    """

    radius: float = 1.0
    cell: float = 6.0
    step: float = 50.0

    physical_fields = (_length("radius", "punch radius"), _length("step", "height of the step (default 50 ε)", None),
                       _length("pitch", "cell side"))
    field_help = {"radius": "punch radius a", "cell": "cell side", "step": "height of the step in ε"}
    si_map = {"pitch": "cell"}
    lateral_unit = "ε"

    def __post_init__(self):
        positive("radius", self.radius)
        positive("cell", self.cell)
        positive("step", self.step)

    def gap(self, grid: Grid) -> np.ndarray:
        X, Y = grid.mesh()
        return np.where(np.hypot(X, Y) <= self.radius, 0.0, self.step)


@dataclass(frozen=True)
class _FlatTop(Shape):
    """A flat top at U0 = 0 (half width a) and ``height`` elsewhere in its cell; subclasses say where
    the top is.  Physical input (half_width, height, pitch): ℓ = ε, every length divided by ε."""

    half_width: float = 1.0
    height: float = 5.0
    cell: float = 6.0

    si_map = {"pitch": "cell"}
    lateral_unit = "ε"

    def __post_init__(self):
        positive("half_width", self.half_width)
        positive("height", self.height)
        positive("cell", self.cell)
        if 2 * self.half_width > self.cell:
            raise TengsimError(f"{type(self).__name__.lower()} width {2 * self.half_width:g} exceeds its cell "
                               f"{self.cell:g}")

    def _on_top(self, X, Y) -> np.ndarray:  # pragma: no cover - abstract
        raise NotImplementedError

    def gap(self, grid: Grid) -> np.ndarray:
        X, Y = grid.mesh()
        return np.where(self._on_top(X, Y), 0.0, self.height)


def _flat_top_fields(what: str):
    return (_length("half_width", f"half the {what} width"), _length("height", f"{what} height"),
            _length("pitch", "cell side"))


@dataclass(frozen=True)
class Cube(_FlatTop):
    """Square flat-topped pillar (cube pattern): U0 = 0 on [−a, a]², ``height`` outside.

    Physical input (half_width, height, pitch): ℓ = ε, every length divided by ε.
    """

    physical_fields = _flat_top_fields("pillar")
    field_help = {"half_width": "half the pillar width a", "height": "pillar height in ε", "cell": "cell side"}

    def _on_top(self, X, Y):
        return (np.abs(X) <= self.half_width) & (np.abs(Y) <= self.half_width)


@dataclass(frozen=True)
class Line(_FlatTop):
    """Ridge along Y (line pattern): flat top |X| <= a at U0 = 0, ``height`` elsewhere.

    Physical input (half_width, height, pitch): ℓ = ε, every length divided by ε.
    """

    physical_fields = _flat_top_fields("ridge")
    field_help = {"half_width": "half the ridge width a", "height": "ridge height in ε", "cell": "cell side"}

    def _on_top(self, X, Y):
        return np.abs(X) <= self.half_width


@dataclass(frozen=True)
class Sinusoid1D(Shape):
    """1-D sinusoid U0 = Δ (1 − cos(2πX/λ)) (peak-to-valley 2Δ); use the periodic kernel.

    Physical input (wavelength, amplitude): ℓ = ε, every length divided by ε.
    """

    wavelength: float = 10.0
    amplitude: float = 1.0

    physical_fields = (_length("wavelength", "wavelength λ (the cell side)"), _length("amplitude", "amplitude Δ"))
    field_help = {"wavelength": "wavelength λ (the cell side)", "amplitude": "amplitude Δ in ε"}
    si_map = {"wavelength": "wavelength"}
    lateral_unit = "ε"

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


SHAPES.register("pyramid", Pyramid, summary="the paper's square pyramid, Eq. (11)")
SHAPES.register("sphere", Paraboloid, aliases=("paraboloid",), summary="sphere, Hertz paraboloid")
SHAPES.register("cone", Cone, summary="axisymmetric cone")
SHAPES.register("hemisphere", Hemisphere, summary="exact hemisphere on a flat base")
SHAPES.register("cube", Cube, summary="square flat-topped pillar")
SHAPES.register("line", Line, summary="flat-topped ridge along Y")
SHAPES.register("flat_punch", FlatPunch, summary="circular flat punch")
SHAPES.register("sinusoid", Sinusoid1D, summary="1-D sinusoid (periodic kernel)")

# shapes defined in their own modules register themselves on import
from tengsim import topography as _topography  # noqa: E402,F401  ('topography')
from tengsim import arrays as _arrays  # noqa: E402,F401  ('array')
