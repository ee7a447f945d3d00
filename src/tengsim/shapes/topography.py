"""Measured topographies: a height map read by SurfaceTopography, detrended, put on the solver grid.

Every format SurfaceTopography reads is accepted (plain-text matrices, NetCDF, Gwyddion, x3p, AFM and
profilometer formats): tengsim has no parser of its own.  Dimensionless form (paper Eq. 7 with
ℓ = ε): heights and in-plane lengths are both divided by ε, so slopes are kept, U0 = (max z − z)/ε
(z up, towards the plate), and the coupling of Eq. (9) is κ = W/(E* ε) = μ^{3/2}.

The physical size comes from the file's metadata or from ``physical_size``; a file with neither is
refused.  A text file carries no unit: its heights (and a size given as a plain number) are in
``unit`` (default metres).  Missing data (NaN, masked pixels) is refused unless ``fill_missing``, which
fills it by SurfaceTopography's harmonic interpolation (``interpolate_undefined_data``); ``fill_missing``
for a file without missing data is refused too (it would change nothing).
"""
from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

from tengsim.errors import TengsimError, positive
from tengsim.grid import Grid
from tengsim.registry import SHAPES
from tengsim.schema import REQUIRED, Field

DETREND_MODES = ("none", "center", "height", "slope", "curvature")
"""'none' keeps the heights; the others are SurfaceTopography's ``detrend_mode``: 'center' the mean,
'height' a plane (tilt), 'slope' a plane fitted to the mean slope, 'curvature' a quadric."""


MAX_RELIEF = 10.0
"""A surface's peak-to-valley height may be at most this many times its smaller lateral size (and a rough
surface's rms slope at most this): beyond it the heights are almost surely in another unit (nm read as
m), and are refused with that advice rather than solved."""

HEADERLESS = {"hgt": (".hgt",)}
"""SurfaceTopography formats with no header or magic number (any file of the right byte count reads as
one), accepted only from a file named as that format: 8 KiB of random bytes is not an SRTM tile."""

TEXT_SUFFIXES = (".txt", ".asc", ".dat", ".csv", ".xyz", "")


@dataclass(frozen=True)
class Measured:
    """A topography in SI after reading: ``heights`` (m, shape (nx, ny)), ``size`` (Lx, Ly) in m;
    ``reader`` the SurfaceTopography format that read it ('asc', 'nc', 'gwy', ...)."""

    heights: np.ndarray
    size: tuple
    periodic: bool
    source: str
    detrend: str
    filled: int
    reader: str = ""

    @property
    def pixel(self) -> tuple:
        return (self.size[0] / self.heights.shape[0], self.size[1] / self.heights.shape[1])


def _unit_factor(unit: str) -> float:
    """Metres per ``unit`` (SurfaceTopography's unit names: m, mm, µm/um, nm, Å, ...)."""
    from SurfaceTopography.Support.UnitConversion import get_unit_conversion_factor

    try:
        f = get_unit_conversion_factor(unit, "m")
    except Exception:  # noqa: BLE001 - SurfaceTopography raises plain errors for unknown units
        f = None
    if f is None or not f > 0:
        raise TengsimError(f"unknown length unit {unit!r} (use m, mm, um, nm, ...)")
    return float(f)


def read(path, physical_size=None, unit: str | None = None, detrend: str = "height",
         fill_missing: bool = False) -> Measured:
    """Read a topography file through SurfaceTopography and return it detrended, in metres.

    ``physical_size`` (Lx, Ly) in metres is needed when the file has none (a text matrix), and refused
    when the file has its own.  ``unit`` is the height unit of a file that declares none (default m).
    ``detrend`` is one of :data:`DETREND_MODES`.  Any failure is one TengsimError naming the file.
    """
    import SurfaceTopography as st

    from pathlib import Path

    p = Path(str(path))
    if not p.is_file():
        raise TengsimError(f"topography file {str(path)!r} not found")
    if detrend not in DETREND_MODES:
        raise TengsimError(f"detrend = {detrend!r} is not one of {', '.join(DETREND_MODES)}")
    try:
        with warnings.catch_warnings():  # its text readers warn on NaN pixels; we report those ourselves
            warnings.simplefilter("ignore", RuntimeWarning)
            reader = st.open_topography(str(p))
        channel = reader.channels[0]
        file_size, file_unit = channel.physical_sizes, channel.unit
    except Exception as exc:  # noqa: BLE001 - SurfaceTopography's errors list every reader it tried
        raise TengsimError(f"cannot read topography file {str(path)!r}: no SurfaceTopography reader "
                           f"recognises it ({_why_not(exc, p)})") from None
    fmt = _format(reader)
    if fmt in HEADERLESS and p.suffix.lower() not in HEADERLESS[fmt]:
        raise TengsimError(f"topography file {str(path)!r} is not a topography: only the headerless "
                           f"'{fmt}' reader takes it (any file of that byte count does), and its name does not "
                           f"end in {' or '.join(HEADERLESS[fmt])}")
    from tengsim.resources import MAX_PIXELS_PER_SIDE

    pts = tuple(int(n) for n in np.atleast_1d(channel.nb_grid_pts))
    if any(n > MAX_PIXELS_PER_SIDE for n in pts):
        raise TengsimError(f"topography file {str(path)!r} (read as '{fmt}') has {'×'.join(map(str, pts))} "
                           f"pixels; at most {MAX_PIXELS_PER_SIDE} per side")
    if channel.dim != 2:
        raise TengsimError(f"topography file {str(path)!r} holds a {channel.dim}-D scan; a 2-D map is needed")
    kw = {}
    if file_unit is None:
        unit = unit or "m"
        kw["unit"] = unit
    elif unit is not None:  # the file's own unit is used; another one given is refused, and so is the same one
        raise TengsimError(f"topography file {str(path)!r} declares its unit {file_unit!r}; drop unit = {unit!r}")
    factor = _unit_factor(file_unit or unit)
    if file_size is None or any(s is None for s in np.atleast_1d(file_size)):
        if physical_size is None:
            raise TengsimError(f"topography file {str(path)!r} has no physical size: give physical_size "
                               "(e.g. --physical-size 2um,2um)")
        ps = tuple(float(v) for v in np.atleast_1d(physical_size))
        if len(ps) == 1:
            ps = ps * 2
        if len(ps) != 2 or not all(math.isfinite(v) and v > 0 for v in ps):
            raise TengsimError(f"physical_size must be two positive lengths Lx,Ly, got {physical_size!r}")
        kw["physical_sizes"] = tuple(v / factor for v in ps)
    elif physical_size is not None:
        raise TengsimError(f"topography file {str(path)!r} has its own physical size "
                           f"{tuple(float(s) for s in file_size)} {file_unit}; drop physical_size")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            topo = reader.topography(**kw)
    except Exception as exc:  # noqa: BLE001
        raise TengsimError(f"cannot read topography file {str(path)!r}: {exc}") from None
    filled = 0
    if topo.has_undefined_data:
        filled = int(np.count_nonzero(np.ma.getmaskarray(topo.heights())))
        if not fill_missing:
            raise TengsimError(f"topography file {str(path)!r} has {filled} missing (NaN or masked) pixels: "
                               "give fill_missing (--fill-missing) to fill them by harmonic interpolation")
        topo = topo.interpolate_undefined_data()
    elif fill_missing:
        raise TengsimError(f"topography file {str(path)!r} has no missing pixels: drop fill_missing (nothing to fill)")
    if detrend != "none":
        topo = topo.detrend(detrend_mode=detrend)
    h = np.asarray(np.ma.getdata(topo.heights()), dtype=float) * factor
    if h.ndim != 2 or min(h.shape) < 3:
        raise TengsimError(f"topography file {str(path)!r}: need a 2-D map of at least 3×3 pixels, got {h.shape}")
    if not np.all(np.isfinite(h)):
        raise TengsimError(f"topography file {str(path)!r} has non-finite heights after reading")
    size = tuple(float(s) * factor for s in topo.physical_sizes)
    _check_relief(h, size, str(path), fmt, file_unit or unit)
    return Measured(h, size, bool(topo.is_periodic), str(path), detrend, filled, fmt)


def _format(reader) -> str:
    """The SurfaceTopography format name of ``reader`` ('asc', 'hgt', 'nc', ...), else its class name."""
    try:
        return str(reader.format())
    except Exception:  # noqa: BLE001 - a reader without a format name
        return type(reader).__name__


def _why_not(exc, p) -> str:
    """The cause worth naming from SurfaceTopography's list of refusals: for a text file, what its text
    reader (AscReader) said; else the first reason given."""
    import re

    text = str(exc)
    reasons = dict(re.findall(r"tried (\w+):\s*\n\s*(.+)", text))
    if p.suffix.lower() in TEXT_SUFFIXES and reasons.get("AscReader"):
        return f"as a text matrix: {reasons['AscReader'].strip()[:200]}"
    first = next((f"{k}: {v.strip()[:200]}" for k, v in reasons.items() if v.strip()), "")
    if first:
        return first
    line = text.strip().splitlines()[0] if text.strip() else type(exc).__name__
    return line.rstrip(":")[:200]


def _check_relief(h, size, path, fmt, unit) -> None:
    """Refuse heights implausible for the scan: peak-to-valley more than :data:`MAX_RELIEF` times the
    smaller lateral size (heights in nm read as m, 5e292 m), with the advice to give their unit."""
    pv = float(np.max(h) - np.min(h))
    side = min(size)
    if math.isfinite(pv) and pv <= MAX_RELIEF * side:
        return
    raise TengsimError(f"topography file {path!r} (read as '{fmt}', heights in {unit}): its heights span {pv:.3g} m "
                       f"over a {size[0]:.3g} m × {size[1]:.3g} m scan, more than {MAX_RELIEF:g} times its size: "
                       "implausible; give the height unit (e.g. --unit nm) or check the file")


def resample(z: np.ndarray, grid: Grid, size: tuple, periodic: bool) -> np.ndarray:
    """``z`` (pixel-centred samples over ``size``) on ``grid`` (same size) by cubic-spline interpolation,
    wrapped at the edges when ``periodic``, the edge values held otherwise."""
    from scipy.ndimage import map_coordinates

    nx, ny = z.shape
    if abs(grid.lx - size[0]) > 1e-9 * size[0] or abs(grid.ly - size[1]) > 1e-9 * size[1]:
        raise TengsimError(f"grid {grid.lx:g}×{grid.ly:g} does not cover the topography {size[0]:g}×{size[1]:g}")
    # new pixel centres, in old pixel-index units (old pixel i has its centre at (i + ½) a)
    xi = (np.arange(grid.nx) + 0.5) * (nx / grid.nx) - 0.5
    yi = (np.arange(grid.ny) + 0.5) * (ny / grid.ny) - 0.5
    X, Y = np.meshgrid(xi, yi, indexing="ij")
    return map_coordinates(z, [X, Y], order=3, mode="grid-wrap" if periodic else "nearest")


@dataclass(frozen=True, eq=False)
class Topography:
    """A measured surface in the units of Eq. (7) with ℓ = ε: heights z/ε on its native pixels over
    ``size`` = (Lx, Ly)/ε; U0 = max z − z on the solver grid.

    Physical input only (a file, see :func:`read`): ``file``, ``physical_size`` (Lx,Ly, when the file
    has none), ``unit``, ``detrend``, ``fill_missing``.  ``grid(dx)`` is the native grid when ``dx`` is
    its pixel (the default of a run), else an FFT-friendly grid of pixel ≈ ``dx`` over the same area,
    onto which the heights are interpolated (cubic splines, wrapped if the file is periodic).
    """

    heights: np.ndarray
    size: tuple
    periodic: bool = False
    source: str = ""
    detrend: str = "height"
    reader: str = ""

    physical_fields = (
        Field("file", "str", REQUIRED, help="topography file (any format SurfaceTopography reads)"),
        Field("physical_size", "floats", None, dim="length",
              help="Lx,Ly of a file without a size, e.g. 2um,2um (one value: square)"),
        Field("unit", "str", None, help="height unit of a file that declares none (default m), e.g. um; "
              "refused for a file with its own"),
        Field("detrend", "str", "height", choices=DETREND_MODES,
              help="trend removed first: none, center (mean), height (plane), slope, curvature (quadric)"),
        Field("fill_missing", "bool", False,
              help="fill missing pixels by harmonic interpolation (a file with missing pixels is refused "
              "without it, one without them refused with it)"),
    )
    lateral_unit = "ε"
    positional = "file"  # tengsim contact topography FILE
    is_pattern = False  # not a cell pattern of tengsim.shapes.arrays

    def __post_init__(self):
        z = np.asarray(self.heights, dtype=float)
        if z.ndim != 2 or min(z.shape) < 3:
            raise TengsimError(f"topography must be a 2-D map of at least 3×3, got shape {z.shape}")
        if not np.all(np.isfinite(z)):
            raise TengsimError("topography contains NaN or infinite heights")
        size = tuple(float(s) for s in self.size)
        if len(size) != 2:
            raise TengsimError(f"topography size must be (Lx, Ly), got {self.size!r}")
        positive("topography Lx", size[0])
        positive("topography Ly", size[1])
        object.__setattr__(self, "heights", z)
        object.__setattr__(self, "size", size)

    # ---- declared input (physical only) ----------------------------------------------------------
    @classmethod
    def dimensionless_fields(cls) -> tuple:
        return ()

    @classmethod
    def lateral_scale(cls, values, eps):
        """ℓ = ε."""
        return positive("eps", eps)

    @classmethod
    def eps_from_tabor(cls, values, E_star, W, mu):
        """Closed form: κ = W/(E* ε), so ε = W/(E* μ^{3/2})."""
        return positive("W", W) / (positive("E_star", E_star) * positive("tabor", mu) ** 1.5)

    @classmethod
    def from_measured(cls, m: Measured, eps: float) -> "Topography":
        eps = positive("eps", eps)
        return cls(m.heights / eps, (m.size[0] / eps, m.size[1] / eps), m.periodic, m.source, m.detrend, m.reader)

    @classmethod
    def from_file(cls, path, eps: float, physical_size=None, unit=None, detrend="height",
                  fill_missing=False) -> "Topography":
        """Read ``path`` (see :func:`read`) and scale by the interaction range ``eps`` (m)."""
        return cls.from_measured(read(path, physical_size, unit, detrend, fill_missing), eps)

    @classmethod
    def from_si(cls, values, eps):
        return cls.from_file(values["file"], eps, values.get("physical_size"), values.get("unit"),
                             values.get("detrend") or "height", bool(values.get("fill_missing")))

    # ---- geometry -----------------------------------------------------------------------------
    @property
    def cell(self) -> float:
        """Side of the square of the same area (sqrt(Lx Ly))."""
        return math.sqrt(self.size[0] * self.size[1])

    @property
    def cell_area(self) -> float:
        return self.size[0] * self.size[1]

    @property
    def native_dx(self) -> float:
        return self.size[0] / self.heights.shape[0]

    def native_grid(self) -> Grid:
        nx, ny = self.heights.shape
        return Grid(nx, ny, self.size[0] / nx, self.size[1] / ny)

    def grid(self, dx: float | None = None) -> Grid:
        g = self.native_grid()
        if dx is None or abs(positive("dx", dx) - g.dx) <= 1e-9 * g.dx:
            return g
        from tengsim import backend

        lx, ly = self.size
        if dx > min(lx, ly) / 3:
            raise TengsimError(f"dx={dx:g} is too coarse for a topography of {lx:g}×{ly:g} (need >= 3 pixels)")
        nx, ny = (backend.fast_len(max(3, int(round(s / dx)))) for s in (lx, ly))
        return Grid(nx, ny, lx / nx, ly / ny)

    def gap(self, grid: Grid) -> np.ndarray:
        z = self.heights
        if grid.shape != z.shape or abs(grid.lx - self.size[0]) > 1e-9 * self.size[0]:
            z = resample(z, grid, self.size, self.periodic)
        return z.max() - z

    def params(self) -> dict:
        nx, ny = self.heights.shape
        return {"shape": "Topography", "file": self.source, "size_x": self.size[0], "size_y": self.size[1],
                "native_nx": nx, "native_ny": ny, "periodic_file": self.periodic, "detrend": self.detrend,
                "rms_height": float(self.heights.std()), "reader": self.reader}


SHAPES.register("topography", Topography, summary="measured surface from a file (SurfaceTopography)")
