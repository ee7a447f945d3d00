"""Axisymmetric shapes: sphere (Hertz paraboloid), hemisphere, cone, flat punch."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tengsim.errors import GeometryError, TengsimError, positive
from tengsim.grid import Grid
from tengsim.registry import SHAPES
from tengsim.schema import REQUIRED, Field
from tengsim.shapes.base import Shape, _length


@dataclass(frozen=True)
class Paraboloid(Shape):
    """Sphere in the Hertz (paraboloid) approximation, U0 = (X² + Y²)/(2R).

    Physical input (radius R, pitch): ℓ = sqrt(R ε), so the dimensionless radius is 1, the cell
    pitch/ℓ, and the coupling μ^{3/2} with Tabor's μ = (R W²/(E*² ε³))^{1/3}.
    """

    contact_family = "disc"

    radius: float = 1.0
    cell: float = 10.0

    physical_fields = (_length("radius", "sphere radius R"), _length("pitch", "cell side (default 10 ℓ)", None))
    field_help = {"radius": "radius in X units (1 with ℓ = sqrt(Rε))", "cell": "cell side"}
    lateral_unit = "sqrt(R ε)"
    mirror_axes = (0, 1)  # axisymmetric: X and Y mirrors

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

    contact_family = "disc"

    radius: float = 3.0
    cell: float = 10.0
    k: float = 1.0

    physical_fields = (_length("radius", "hemisphere radius R"), _length("pitch", "cell side"))
    field_help = {"radius": "radius ρ in X units", "cell": "cell side",
                  "k": "lateral/vertical unit ratio ℓ/ε (1: X and U0 both in ε)"}
    lateral_unit = "sqrt(R ε)"
    mirror_axes = (0, 1)  # axisymmetric: X and Y mirrors

    def __post_init__(self):
        positive("radius", self.radius)
        positive("cell", self.cell)
        positive("k", self.k)
        if 2 * self.radius > self.cell:
            raise GeometryError("hemisphere diameter {diameter} exceeds its cell {cell}", diameter=2 * self.radius,
                                cell=self.cell)

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

    def full_contact_length(self) -> float:
        """The base diameter, 2ρ."""
        return 2 * float(self.radius)

    def edge_offsets(self) -> tuple:
        """The base edge (vertical tangent), the radius from the apex."""
        return (float(self.radius),)


@dataclass(frozen=True)
class Cone(Shape):
    """Axisymmetric cone U0 = slope · r (slope = tan of the surface inclination), capped at ``height``.

    Physical input (slope, pitch, optional height): ℓ = ε/slope, so the dimensionless slope is 1, the
    cell pitch/ℓ and the cap height/ε.
    """

    contact_family = "disc"

    slope: float = 1.0
    cell: float = 10.0
    height: float = np.inf

    physical_fields = (Field("slope", "float", REQUIRED, help="tan of the surface inclination"),
                       _length("pitch", "cell side"), _length("height", "cap height (default: none)", None))
    field_help = {"slope": "tan of the surface inclination", "cell": "cell side",
                  "height": "cap height in ε (default: none)"}
    lateral_unit = "ε/slope"
    mirror_axes = (0, 1)  # axisymmetric: X and Y mirrors

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

    def full_contact_length(self) -> float:
        """The cap's diameter, 2 height/slope (NaN for an uncapped cone)."""
        return 2 * float(self.height) / float(self.slope) if np.isfinite(self.height) else float("nan")

    def edge_offsets(self) -> tuple:
        """The cap's edge, height/slope from the apex (none for an uncapped cone)."""
        return (float(self.height / self.slope),) if np.isfinite(self.height) else ()


@dataclass(frozen=True)
class FlatPunch(Shape):
    """Circular flat-ended punch of radius a: U0 = 0 for r <= a, ``step`` outside.

    Physical input (radius, step, pitch): ℓ = ε, every length divided by ε.
    """

    contact_family = "disc"

    radius: float = 1.0
    cell: float = 6.0
    step: float = 50.0

    physical_fields = (_length("radius", "punch radius"), _length("step", "height of the step (default 50 ε)", None),
                       _length("pitch", "cell side"))
    field_help = {"radius": "punch radius a", "cell": "cell side", "step": "height of the step in ε"}
    si_map = {"pitch": "cell"}
    lateral_unit = "ε"
    mirror_axes = (0, 1)  # axisymmetric: X and Y mirrors

    def __post_init__(self):
        positive("radius", self.radius)
        positive("cell", self.cell)
        positive("step", self.step)

    def gap(self, grid: Grid) -> np.ndarray:
        X, Y = grid.mesh()
        return np.where(np.hypot(X, Y) <= self.radius, 0.0, self.step)

    def edge_offsets(self) -> tuple:
        """The punch's rim, its radius from the centre."""
        return (float(self.radius),)


SHAPES.register("sphere", Paraboloid, aliases=("paraboloid",), summary="sphere, Hertz paraboloid")
SHAPES.register("cone", Cone, summary="axisymmetric cone")
SHAPES.register("hemisphere", Hemisphere, summary="exact hemisphere on a flat base")
SHAPES.register("flat_punch", FlatPunch, summary="circular flat punch")
