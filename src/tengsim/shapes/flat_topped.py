"""Flat-topped patterns with vertical walls: the cube (square pillar) and the line (ridge)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tengsim.errors import GeometryError, positive
from tengsim.grid import Grid
from tengsim.registry import SHAPES
from tengsim.shapes.base import Shape, _length


@dataclass(frozen=True)
class _FlatTop(Shape):
    """A flat top at U0 = 0 (half width a) and ``height`` elsewhere in its cell; subclasses say where
    the top is.  Physical input (half_width, height, pitch): ℓ = ε, every length divided by ε."""

    half_width: float = 1.0
    height: float = 5.0
    cell: float = 6.0

    si_map = {"pitch": "cell"}
    lateral_unit = "ε"
    mirror_axes = (0, 1)  # the cube: X and Y; the line (uniform along Y): X, and Y trivially

    def __post_init__(self):
        positive("half_width", self.half_width)
        positive("height", self.height)
        positive("cell", self.cell)
        if 2 * self.half_width > self.cell:
            raise GeometryError(type(self).__name__.lower() + " width {width} exceeds its cell {cell}",
                                width=2 * self.half_width, cell=self.cell)

    def _on_top(self, X, Y) -> np.ndarray:  # pragma: no cover - abstract
        raise NotImplementedError

    def gap(self, grid: Grid) -> np.ndarray:
        X, Y = grid.mesh()
        return np.where(self._on_top(X, Y), 0.0, self.height)

    def full_contact_length(self) -> float:
        """The cell: the flat top is in full contact from the first touch and the plate lies on the land
        between the pillars (ridges)."""
        return float(self.cell)

    def edge_offsets(self) -> tuple:
        """The wall, half_width from the centre."""
        return (float(self.half_width),)


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

    contact_family = "line"

    physical_fields = _flat_top_fields("ridge")
    field_help = {"half_width": "half the ridge width a", "height": "ridge height in ε", "cell": "cell side"}

    def _on_top(self, X, Y):
        return np.abs(X) <= self.half_width


SHAPES.register("cube", Cube, summary="square flat-topped pillar")
SHAPES.register("line", Line, summary="flat-topped ridge along Y")
