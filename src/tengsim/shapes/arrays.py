"""Arrays with fabrication scatter: a periodic super-cell of K × K cells of one pattern shape.

Cell (i, j) holds the pattern z(X) = Umax − U0_p(X) (its height above the cell's flat base, U0_p the
pattern's own gap of Eq. 11 and Umax its largest value over the cell) with its own

* height factor  h_ij = 1 + s_h ξ:   z → h_ij z;
* size factor    s_ij = 1 + s_s ξ:   z(X) → z(X/s_ij) (the pattern widened about its centre);
* tilt           t_ij = s_t (ξ, ξ'): z → z + t_ij · X on the pattern's footprint (z > 0), clipped at
  z ≥ 0: a rigid rotation by the small slope t (in ε per ℓ), to first order;

with ξ independent draws of unit variance (``distribution`` 'normal', or 'uniform' on ±√3) from
``numpy.random.default_rng(seed)``.  An optional waviness of the plate or film (the gap only sees their
sum) adds  a/2 [cos(2πX/λ) + cos(2πY/λ)]  to z, amplitude a (ε), wavelength λ = ``waviness_wavelength``
cells (K/λ must be a whole number so the super-cell stays periodic).  The gap is U0 = max z − z.

The pattern's parameters are its own fields (dimensionless or physical, as for the pattern alone); the
array's cell is K L̄ and the force of Eq. (10) is over the whole super-cell, so the nominal pressure
is force / (K L̄)².  The observer ``array_area`` reports the charged area over the array.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from tengsim.errors import TengsimError, positive
from tengsim.grid import Grid
from tengsim.registry import SHAPES
from tengsim.schema import Field
from tengsim.shapes.base import dimensionless_fields, physical_fields

DISTRIBUTIONS = ("normal", "uniform")


@dataclass(frozen=True)
class ArrayGrid(Grid):
    """A grid of ``cells`` × ``cells`` equal pattern cells (``cells`` = K; 1 for any other grid)."""

    cells: int = 1


def _pattern_shapes():
    return [n for n in SHAPES.names() if getattr(SHAPES.get(n), "is_pattern", True)]


def _own_fields():
    return (
        Field("pattern", "str", "pyramid", choices=_pattern_shapes, help="the pattern shape of each cell"),
        Field("K", "int", 2, help="cells per side of the periodic super-cell (K × K cells)"),
        Field("scatter_height", "float", 0.0, help="rms of the relative height scatter (0.05 = 5 %)"),
        Field("scatter_size", "float", 0.0, help="rms of the relative lateral-size scatter"),
        Field("distribution", "str", "normal", choices=DISTRIBUTIONS, help="scatter distribution"),
        Field("seed", "int", 0, help="seed of the scatter draws"),
        Field("waviness_wavelength", "float", 1.0, help="waviness wavelength in cells (K a multiple of it)"),
    )


def _dim_only_fields():
    return (Field("scatter_tilt", "float", 0.0, help="rms tilt slope of a pattern, per component (ε per ℓ)"),
            Field("waviness_amplitude", "float", 0.0, help="waviness amplitude a in ε (peak to valley 2a)"))


def _phys_only_fields():
    return (Field("tilt", "float", 0.0, help="rms tilt angle of a pattern, per component, in radians"),
            Field("waviness", "float", 0.0, dim="length", help="waviness amplitude a (peak to valley 2a)"))


def _union(kind):
    """The fields of every pattern shape (physical or dimensionless), each name once, none required."""
    out = {}
    for n in _pattern_shapes():
        cls = SHAPES.get(n)
        for f in (dimensionless_fields(cls) if kind == "dim" else physical_fields(cls)):
            if f.name not in out:
                out[f.name] = dataclasses.replace(f, default=None, help=f"{f.help} (of the pattern)")
    return tuple(out.values())


class Array:
    """K × K cells of ``pattern`` (a Shape, or a registered name with its fields in ``fields``) with
    per-cell height, size and tilt scatter and a waviness; see the module docstring."""

    is_pattern = False
    lateral_unit = "the pattern's ℓ"

    @property
    def mirror_axes(self) -> tuple:
        """The pattern's mirrors when no cell differs from another (no scatter, no tilt, no waviness),
        else none: a scattered array has no symmetry to use."""
        if self.scatter_height or self.scatter_size or self.scatter_tilt or self.waviness_amplitude:
            return ()
        return tuple(getattr(self.pattern, "mirror_axes", ()))

    def charged_patch(self) -> tuple:
        """The pattern's (L̄, family) (:meth:`tengsim.shapes.Shape.charged_patch`): Λc is measured on one pattern,
        and its patch charged over one pattern's cell."""
        return self.pattern.charged_patch()

    def full_contact_length(self) -> float:
        """The pattern's (Λc is measured on one pattern, through the highest apex)."""
        return float(getattr(self.pattern, "full_contact_length", lambda: float("nan"))())

    def __init__(self, pattern="pyramid", K=2, scatter_height=0.0, scatter_size=0.0, scatter_tilt=0.0,
                 distribution="normal", seed=0, waviness_amplitude=0.0, waviness_wavelength=1.0, **fields):
        if isinstance(pattern, str):
            name = SHAPES.canonical(pattern)
            cls = SHAPES.get(name)
            if not getattr(cls, "is_pattern", True):
                raise TengsimError(f"array pattern {pattern!r} cannot be a cell pattern")
            own = [f.name for f in dimensionless_fields(cls)]
            bad = [k for k, v in fields.items() if v is not None and k not in own]
            if bad:
                raise TengsimError(f"array of {name}: the pattern has no key {', '.join(map(repr, bad))} "
                                   f"(its keys: {', '.join(own)})")
            try:
                pattern = cls(**{k: v for k, v in fields.items() if v is not None})
            except TypeError as exc:
                raise TengsimError(f"array pattern {name}: {exc}") from None
        elif fields:
            raise TengsimError(f"give the pattern's fields to the pattern, not the array: {', '.join(fields)}")
        self.pattern = pattern
        self.pattern_name = SHAPES.name_of(pattern)
        if isinstance(K, bool) or int(K) != K or K < 1:
            raise TengsimError(f"array K must be a whole number >= 1, got {K!r}")
        self.K = int(K)
        for k, v in (("scatter_height", scatter_height), ("scatter_size", scatter_size),
                     ("scatter_tilt", scatter_tilt), ("waviness_amplitude", waviness_amplitude)):
            if not (math.isfinite(v) and v >= 0):
                raise TengsimError(f"array {k} must be >= 0, got {v!r}")
        self.scatter_height, self.scatter_size = float(scatter_height), float(scatter_size)
        self.scatter_tilt, self.waviness_amplitude = float(scatter_tilt), float(waviness_amplitude)
        if distribution not in DISTRIBUTIONS:
            raise TengsimError(f"array distribution {distribution!r} is not one of {', '.join(DISTRIBUTIONS)}")
        self.distribution, self.seed = distribution, int(seed)
        self.waviness_wavelength = positive("waviness_wavelength", waviness_wavelength)
        if self.waviness_amplitude > 0:
            r = self.K / self.waviness_wavelength
            if abs(r - round(r)) > 1e-9:
                raise TengsimError(f"waviness_wavelength {waviness_wavelength:g} cells does not divide K = {K}: "
                                   "the super-cell would not be periodic")
        self.heights, self.sizes, self.tilts = self._draw()
        if np.any(self.heights <= 0):
            raise TengsimError(f"scatter_height {self.scatter_height:g} gives a pattern of height factor "
                               f"{self.heights.min():.3g} <= 0 (seed {self.seed}): reduce the scatter")
        if np.any(self.sizes <= 0):
            raise TengsimError(f"scatter_size {self.scatter_size:g} gives a pattern of size factor "
                               f"{self.sizes.min():.3g} <= 0 (seed {self.seed}): reduce the scatter")

    # ---- scatter ------------------------------------------------------------------------------
    def _draw(self):
        rng = np.random.default_rng(self.seed)
        K = self.K

        def xi(shape):
            if self.distribution == "uniform":
                return rng.uniform(-math.sqrt(3), math.sqrt(3), shape)
            return rng.standard_normal(shape)

        h = 1 + self.scatter_height * xi((K, K))
        s = 1 + self.scatter_size * xi((K, K))
        t = self.scatter_tilt * xi((K, K, 2))
        return h, s, t

    # ---- declared input -----------------------------------------------------------------------
    @classmethod
    def dimensionless_fields(cls) -> tuple:
        return (*_own_fields(), *_dim_only_fields(), *_union("dim"))

    @classmethod
    def _physical_fields(cls) -> tuple:
        return (*_own_fields(), *_phys_only_fields(), *_union("phys"))

    @classmethod
    def _split(cls, values):
        own = {f.name for f in (*_own_fields(), *_phys_only_fields())}
        pname = values.get("pattern") or "pyramid"
        pcls = SHAPES.get(pname)
        if not getattr(pcls, "is_pattern", True):
            raise TengsimError(f"array pattern {pname!r} cannot be a cell pattern")
        mine = {f.name for f in physical_fields(pcls)}
        extra = [k for k, v in values.items() if k not in own and k not in mine and v is not None]
        if extra:
            raise TengsimError(f"array of {pname}: the pattern has no physical key {', '.join(map(repr, extra))}")
        return pcls, {k: v for k, v in values.items() if k in mine and v is not None}

    @classmethod
    def refuse_unused(cls, values: dict, given) -> None:
        """Refuse, in one line, the keys of a [contact] table (``given``; ``values`` parsed) that this array
        does not use: seed and distribution without any scatter, waviness_wavelength without a waviness."""
        physical = "tilt" in values
        tilt, wav = ("tilt", "waviness") if physical else ("scatter_tilt", "waviness_amplitude")
        unused = []
        if not any(values.get(k) for k in ("scatter_height", "scatter_size", tilt)):
            keys = [k for k in ("seed", "distribution") if k in given]
            if keys:
                unused.append(f"{' and '.join(keys)} {'apply' if len(keys) > 1 else 'applies'} only with a scatter "
                              f"(scatter_height, scatter_size or {tilt} > 0)")
        if not values.get(wav) and "waviness_wavelength" in given:
            unused.append(f"waviness_wavelength applies only with a waviness ({wav} > 0)")
        if unused:
            raise TengsimError(f"array: {'; '.join(unused)}")

    @classmethod
    def lateral_scale(cls, values, eps):
        pcls, pv = cls._split(values)
        return pcls.lateral_scale(pv, eps)

    @classmethod
    def eps_from_tabor(cls, values, E_star, W, mu):
        pcls, pv = cls._split(values)
        return pcls.eps_from_tabor(pv, E_star, W, mu)

    @classmethod
    def from_si(cls, values, eps):
        pcls, pv = cls._split(values)
        lat = pcls.lateral_scale(pv, eps)
        pattern = pcls.from_si(pv, eps)
        g = {f.name: values.get(f.name) for f in _own_fields() if values.get(f.name) is not None}
        g.pop("pattern", None)
        tilt = math.tan(values.get("tilt") or 0.0) * lat / eps  # slope dz/dx → ε per ℓ
        return cls(pattern, scatter_tilt=tilt, waviness_amplitude=(values.get("waviness") or 0.0) / eps, **g)

    # ---- geometry -----------------------------------------------------------------------------
    @property
    def cell(self) -> float:
        return self.K * self.pattern.cell

    def grid(self, dx: float) -> ArrayGrid:
        g = self.pattern.grid(dx)
        return ArrayGrid(self.K * g.nx, self.K * g.ny, g.dx, g.dy, cells=self.K)

    def cell_grid(self, grid: Grid) -> Grid:
        return Grid(grid.nx // self.K, grid.ny // self.K, grid.dx, grid.dy)

    def _pattern_height(self, cg: Grid, s: float):
        """z(X/s) = Umax − U0_p(X/s) on the cell grid ``cg`` and the footprint check."""
        U = self.pattern.gap(cg)
        umax = float(U.max())
        if s == 1.0:
            return umax - U
        Us = self.pattern.gap(Grid(cg.nx, cg.ny, cg.dx / s, cg.dy / s))
        z = np.clip(umax - Us, 0.0, None)
        border = np.concatenate([z[0], z[-1], z[:, 0], z[:, -1]])
        if s > 1 and np.any(border > 1e-12 * max(umax, 1.0)):
            raise TengsimError(f"scatter_size {self.scatter_size:g} makes a {self.pattern_name} {s:.3g}× as wide "
                               f"(seed {self.seed}): wider than its cell allows; reduce the scatter")
        return z

    def heights_map(self, grid: Grid) -> np.ndarray:
        """z over the super-cell (ε): each cell's pattern with its scatter, plus the waviness."""
        K = self.K
        if grid.nx % K or grid.ny % K:
            raise TengsimError(f"grid {grid.shape} is not {K} × {K} equal cells")
        cg = self.cell_grid(grid)
        X, Y = cg.mesh()
        z = np.empty(grid.shape)
        base = self._pattern_height(cg, 1.0)
        for i in range(K):
            for j in range(K):
                s = float(self.sizes[i, j])
                zc = base if s == 1.0 else self._pattern_height(cg, s)
                zc = self.heights[i, j] * zc
                tx, ty = self.tilts[i, j]
                if tx or ty:
                    zc = np.where(zc > 0, np.clip(zc + tx * X + ty * Y, 0.0, None), 0.0)
                z[i * cg.nx:(i + 1) * cg.nx, j * cg.ny:(j + 1) * cg.ny] = zc
        if self.waviness_amplitude > 0:
            lam = self.waviness_wavelength * self.pattern.cell
            x = (np.arange(grid.nx) + 0.5) * grid.dx
            y = (np.arange(grid.ny) + 0.5) * grid.dy
            z += 0.5 * self.waviness_amplitude * (np.cos(2 * np.pi * x / lam)[:, None]
                                                  + np.cos(2 * np.pi * y / lam)[None, :])
        return z

    def gap(self, grid: Grid) -> np.ndarray:
        z = self.heights_map(grid)
        return z.max() - z

    @property
    def cell_area(self) -> float:
        """Area of the super-cell, (K L̄)²: the nominal area the force of Eq. (10) is over."""
        return self.cell ** 2

    def params(self) -> dict:
        """The pattern's parameters as ``pattern_<name>`` (``pattern_cell``: one cell's side L̄), the
        super-cell's side ``cell`` = K L̄ and area ``cell_area`` (the nominal area of the force), K and the
        scatter settings with their realised rms."""
        d = {f"pattern_{k}": v for k, v in self.pattern.params().items()}
        d.update(shape="Array", pattern=self.pattern_name, K=self.K, cell=self.cell, cell_area=self.cell_area,
                 scatter_height=self.scatter_height,
                 scatter_size=self.scatter_size, scatter_tilt=self.scatter_tilt, distribution=self.distribution,
                 seed=self.seed, waviness_amplitude=self.waviness_amplitude,
                 waviness_wavelength=self.waviness_wavelength,
                 realised_height_rms=float(self.heights.std()), realised_size_rms=float(self.sizes.std()))
        return d


class _PhysFields:
    """``Array.physical_fields`` read on the class: the union is computed when asked (plugins included)."""

    def __get__(self, obj, owner):
        return owner._physical_fields()


Array.physical_fields = _PhysFields()

SHAPES.register("array", Array, summary="K × K super-cell of a pattern with height/size/tilt scatter")
