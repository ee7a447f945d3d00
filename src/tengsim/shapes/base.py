"""Shapes: the initial gap U0(X, Y) >= 0 of the elastic surface, in units of the interaction range ε.

All shapes are dimensionless (paper Eq. 7): heights are U0 = h0/ε, lengths in the plane X = x/ℓ with
a lateral scale ℓ each shape chooses so that its dimensionless form is simplest (the paper's pyramid:
ℓ = ε m/n).  The apex is at the origin, where U0 = 0.  Every shape has ``gap(grid)``, ``grid(dx)``
and ``params()``.

A registered shape also declares its input: its dimensionless fields are its dataclass fields, its
physical fields (with dimensions) are ``physical_fields``, and ``from_si(values, eps)`` builds it
from SI input with the lateral scale ``lateral_scale(values, eps)`` (then κ = W ℓ/(E* ε²) = μ^{3/2}).
"""
from __future__ import annotations

import dataclasses
from dataclasses import asdict

import numpy as np

from tengsim.errors import TengsimError, positive
from tengsim.grid import Grid
from tengsim.registry import SHAPES
from tengsim.schema import REQUIRED, Field, dataclass_fields, signature_fields
from tengsim.units import eps_for_tabor


def _length(name, help, default=REQUIRED):
    return Field(name, "float", default, dim="length", help=help)


class Shape:
    """Base of all shapes: ``gap(grid)`` gives U0 on the grid, ``cell`` a natural cell side.

    Class attributes a shape may set: ``physical_fields`` (schema Fields with dimensions: the
    physical input), ``field_help`` (help text of the dimensionless fields), ``lateral_unit`` (the
    text of ℓ for result metadata).  With physical fields, a shape overrides ``lateral_scale`` and
    ``from_si``; shapes with ℓ = ε can instead set ``si_map`` (physical name → dimensionless name,
    each length divided by ε).

    Nothing accepted is ignored: every key of a shape changes its gap, its grid or the run's scaling
    (``tests/test_nothing_ignored.py`` walks the registry and checks it), unless the shape names it in
    ``metadata_fields`` (key → why: recorded with the result, changes nothing solved; none of the
    built-in shapes has one).  A key that only some variants of a shape use is refused by the others:
    a shape may define a classmethod ``refuse_unused(values, given)`` (the parsed [contact] values and
    the keys given) raising a one-line TengsimError (the array: seed without a scatter).
    """

    cell: float
    metadata_fields: dict = {}
    physical_fields: tuple = ()
    field_help: dict = {}
    lateral_unit: str = "ℓ"
    si_map: dict = {}
    #: mirror symmetries of the gap about the cell centre (0: X ↦ −X, 1: Y ↦ −Y) that a solve may use
    #: (the irreducible block); none declared, none used.  A run checks them on its grid.
    mirror_axes = ()
    #: how the contact length Λc maps to the charged area A/S (tengsim.run.area.family): 'square' (a square
    #: patch of side Λc), 'disc' (a disc of diameter Λc) or 'line' (a strip of width Λc)
    contact_family = "square"

    def gap(self, grid: Grid) -> np.ndarray:  # pragma: no cover - abstract
        raise NotImplementedError

    def params(self) -> dict:
        d = {k: v for k, v in asdict(self).items() if not isinstance(v, np.ndarray)}
        d["shape"] = type(self).__name__
        return d

    def grid(self, dx: float) -> Grid:
        """A square grid over the shape's cell with spacing about ``dx``."""
        return Grid.square(self.cell, dx)

    def charged_patch(self) -> tuple:
        """(L̄, family): the side of the square cell over which one contact patch is charged and how the contact
        length Λc maps to the patch's area (:attr:`contact_family`), what the paper's A/S asks of a shape
        (:func:`tengsim.run.area.area_fraction`)."""
        return float(self.cell), self.contact_family

    def full_contact_length(self) -> float:
        """Λc of full contact, in X units (what transition_D and the adhesive full-contact flag compare the
        contact length with): NaN where the shape has none (the default)."""
        return float("nan")

    def edge_offsets(self) -> tuple:
        """Distances from the cell centre (the apex pixel) along X to the shape's kinks: the base edge of a
        pyramid, cone, hemisphere or punch, the wall of a cube or line.  Where such an edge falls in its pixel
        sets the sign of the grid's error in what is measured there (the contact edge in full contact), so
        automatic refinement keeps that place from grid to grid (:mod:`tengsim.run.resolve`).  None: ()."""
        return ()

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
        if cls.si_map and cls.lateral_scale.__func__ is Shape.lateral_scale.__func__:
            # ℓ = ε: κ = W/(E* ε), so ε = W/(E* μ^{3/2})
            return positive("W", W) / (positive("E_star", E_star) * positive("tabor", mu) ** 1.5)
        return eps_for_tabor(lambda e: cls.lateral_scale(values, e), E_star, W, mu)


def dimensionless_fields(cls) -> tuple:
    """A shape's dimensionless input fields (its dataclass fields, or its constructor's arguments)."""
    if hasattr(cls, "dimensionless_fields"):
        return tuple(cls.dimensionless_fields())
    if dataclasses.is_dataclass(cls):
        return tuple(Shape.dimensionless_fields.__func__(cls))
    return signature_fields(cls)


def physical_fields(cls) -> tuple:
    """A shape's physical input fields (with dimensions); empty for a shape without physical input."""
    return tuple(getattr(cls, "physical_fields", ()) or ())
