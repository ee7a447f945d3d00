"""Roughness on any shape: a shape's gap with the ``rough`` shape's self-affine surface
superimposed — the micro-pattern carrying nano-scale roughness.

``Roughened(base, hurst, rms_height | rms_slope, short_cutoff, long_cutoff, seed)`` is a composition, not a
change to any shape: the roughness h is :class:`tengsim.shapes.rough.Rough`'s surface (SurfaceTopography's
generator seeded by ``seed`` — the same surface on every machine —, rescaled to the exact rms height or
slope, Fourier-interpolated onto the run's grid) over the base shape's cell, periodic in that cell, and

    U0 = U0_base − h − min(U0_base − h)

(a height h lowers the gap).  Re-referencing keeps every shape's apex convention, min U0 = 0: D = 0 is the
plate touching the highest point of the *roughened* surface.  For the same plate position the two runs'
approaches differ by that re-referencing, D_roughened = D_smooth + min(U0_base − h), i.e. D is smaller by
the height the highest rough peak stands above the smooth apex.  With the free (isolated-patch) kernel the
roughness is still the periodic surface of the shape's cell, the patch being that cell.

Units are the base shape's: heights (rms_height) in ε, in-plane lengths (cut-offs) in X units (the shape's
lateral scale ℓ), rms slope as dU0/dX.  The [contact] keys (``roughness = true`` and ``roughness_*``,
:func:`roughness_fields`) are parsed by :func:`roughen`: in a physical run a length with a unit is divided by
ε (rms height) or ℓ (cut-offs), a bare number is in ε or X units as in a dimensionless run (as for dx and
thickness), and the rms slope is the true slope dh/dx (times ℓ/ε).

The roughened shape declares no mirror symmetry (a random surface has none): it forwards only the base's
cell, cell area, native pixel, lateral unit and grid.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from tengsim.errors import TengsimError
from tengsim.grid import Grid
from tengsim.schema import Field
from tengsim.units import number_or_text
from tengsim.shapes.rough import Rough, settle_spectrum

LENGTH_KEYS = {"roughness_rms_height": "height", "roughness_short_cutoff": "lateral",
               "roughness_long_cutoff": "lateral"}
"""The roughness keys that are lengths: a height (in ε) or an in-plane length (in X units, ℓ)."""


def _length_value(v, label="roughness length"):
    """A roughness length: a number (ε or X units) or, in a physical run, a length with a unit (checked later)."""
    return number_or_text(v, label, "a length")


def roughness_fields() -> tuple:
    """The [contact] keys of a superimposed roughness (common to every shape but ``rough``)."""
    return (
        Field("roughness", "bool", False,
              help="superimpose a self-affine random roughness (the rough shape's surface, periodic in the "
              "shape's cell; the gap re-referenced to min U0 = 0) on the shape; the roughness_* keys set it"),
        Field("roughness_hurst", "float", 0.8, help="roughness: Hurst exponent H, 0 < H < 1"),
        Field("roughness_rms_height", "any", None, check=_length_value,
              help="roughness: rms height in ε; in a physical run also a length, e.g. '5nm' (default 1 ε "
              "unless roughness_rms_slope is given)"),
        Field("roughness_rms_slope", "float", None,
              help="roughness: rms slope instead of the rms height (dU0/dX; in a physical run the slope dh/dx)"),
        Field("roughness_short_cutoff", "any", None, check=_length_value,
              help="roughness: short-wavelength cut-off in X units; in a physical run also a length "
              "(default cell/32; >= 2 dx)"),
        Field("roughness_long_cutoff", "any", None, check=_length_value,
              help="roughness: long-wavelength cut-off in X units, PSD flat beyond it; in a physical run also "
              "a length (default the cell)"),
        Field("roughness_seed", "int", 0, help="roughness: random seed: the same seed, the same surface"),
    )


@dataclass(frozen=True)
class Roughened:
    """``base`` (any shape but ``rough``) with a self-affine random roughness superimposed; see the module
    docstring.  The fields are the rough shape's, in the base shape's units (heights in ε, lengths in X)."""

    base: object
    hurst: float = 0.8
    rms_height: float | None = None
    rms_slope: float | None = None
    short_cutoff: float | None = None
    long_cutoff: float | None = None
    seed: int = 0
    _rough: Rough = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        if isinstance(self.base, (Rough, Roughened)):
            raise TengsimError("roughness: the shape is already rough (give the rough shape's own hurst, rms_height, "
                               "rms_slope, short_cutoff, long_cutoff and seed instead of the roughness keys)")
        cell = float(self.base.cell)
        settle_spectrum(self, cell, key=lambda k: "roughness_" + k, cell_name="the shape's cell")
        s = self.seed
        object.__setattr__(self, "_rough", Rough(cell=cell, hurst=self.hurst, rms_height=self.rms_height,
                                                 rms_slope=self.rms_slope, short_cutoff=self.short_cutoff,
                                                 long_cutoff=self.long_cutoff, seed=int(s)))

    # ---- what the base shape gives ----------------------------------------------------------------
    @property
    def cell(self) -> float:
        return self.base.cell

    @property
    def cell_area(self) -> float:
        return getattr(self.base, "cell_area", self.base.cell ** 2)

    @property
    def native_dx(self) -> float:  # AttributeError (so getattr's default) where the base has none
        return self.base.native_dx

    @property
    def lateral_unit(self) -> str:
        return getattr(self.base, "lateral_unit", "ℓ")

    def full_contact_length(self) -> float:
        """The base shape's (NaN if it has none)."""
        return float(getattr(self.base, "full_contact_length", lambda: float("nan"))())

    mirror_axes = ()
    """No mirror symmetry (tengsim.run.simulate.choose_symmetry): a random surface has none, whatever the base's."""

    def grid(self, dx: float) -> Grid:
        g = self.base.grid(dx)
        self._check_grid(g)
        return g

    def _check_grid(self, grid: Grid) -> None:
        cell = float(self.base.cell)
        if (grid.nx != grid.ny or abs(grid.dx - grid.dy) > 1e-9 * grid.dx
                or abs(grid.lx - cell) > 1e-9 * cell):
            raise TengsimError(f"roughness needs a square grid over the shape's cell {cell:g}: the grid is "
                               f"{grid.nx}×{grid.ny} pixels, {grid.lx:g}×{grid.ly:g}")
        if self.short_cutoff < 2 * grid.dx * (1 - 1e-9):
            raise TengsimError(f"roughness_short_cutoff = {self.short_cutoff:g} (X units) is below 2 pixels of the "
                               f"grid (dx = {grid.dx:g}): use dx <= {self.short_cutoff / 2:g} or a longer "
                               "roughness_short_cutoff")

    # ---- the gap ----------------------------------------------------------------------------------
    def heights(self, grid: Grid) -> np.ndarray:
        """The roughness h on ``grid`` (mean 0; the rough shape's surface over the base's cell)."""
        self._check_grid(grid)
        return self._rough.heights(grid)

    def gap(self, grid: Grid) -> np.ndarray:
        u = self.base.gap(grid) - self.heights(grid)
        return u - u.min()

    def params(self) -> dict:
        d = dict(self.base.params())
        d["roughness"] = True
        for k in ("hurst", "rms_height", "rms_slope", "short_cutoff", "long_cutoff", "seed"):
            v = getattr(self, k)
            if v is not None:
                d[f"roughness_{k}"] = v
        d["roughness_reference"] = "min U0 = 0 after the roughness: D from the highest rough point"
        return d


def roughen(shape, values: dict, given, scaling=None):
    """``shape`` with the roughness of a parsed [contact] table (``values``; ``given`` its keys) and the extra
    result parameters of a physical run (``scaling``: ε and ℓ of the run, None for a dimensionless one).

    Without ``roughness = true``: ``shape`` itself, and any roughness_* key given is refused in one line."""
    keys = [f.name for f in roughness_fields()]
    extra_keys = [k for k in keys[1:] if k in given]
    if not values.get("roughness"):
        if extra_keys:
            raise TengsimError(f"{', '.join(extra_keys)} {'apply' if len(extra_keys) > 1 else 'applies'} only with "
                               "roughness = true (--roughness)")
        return shape, {}
    if isinstance(shape, Rough):
        raise TengsimError("shape rough is already rough: roughness and the roughness_* keys apply to the other "
                           "shapes (give the rough shape's own hurst, rms_height, rms_slope, cut-offs and seed)")
    from tengsim.units import parse_quantity

    kw, extra = {}, {}
    for k, where in LENGTH_KEYS.items():
        v = values.get(k)
        if v is None:
            continue
        if isinstance(v, str):
            si = parse_quantity(v, "length", name=k)  # a bad unit or no number: its own one line
            if not (math.isfinite(si) and si > 0):
                raise TengsimError(f"{k} must be finite and > 0, got {v!r}")
            if scaling is None:
                raise TengsimError(f"{k} = {v!r} has a unit, but this run is dimensionless: give it in "
                                   f"{'ε' if where == 'height' else 'X units'} (or the shape's physical sizes "
                                   "with E_star and W)")
            v = si / (scaling.eps if where == "height" else scaling.lateral)
        kw[k[len("roughness_"):]] = v
    slope = values.get("roughness_rms_slope")
    if slope is not None:
        kw["rms_slope"] = slope if scaling is None else slope * scaling.lateral / scaling.eps
    kw["hurst"] = 0.8 if values.get("roughness_hurst") is None else values["roughness_hurst"]
    kw["seed"] = 0 if values.get("roughness_seed") is None else values["roughness_seed"]
    out = Roughened(shape, **kw)
    if scaling is not None:
        extra["roughness_rms_height_m"] = None if out.rms_height is None else out.rms_height * scaling.eps
        extra["roughness_short_cutoff_m"] = out.short_cutoff * scaling.lateral
        extra["roughness_long_cutoff_m"] = out.long_cutoff * scaling.lateral
        if slope is not None:
            extra["roughness_rms_slope_dh_dx"] = float(slope)
        extra = {k: v for k, v in extra.items() if v is not None}
    return out, extra
