"""Self-affine random roughness: a periodic surface from SurfaceTopography's Fourier-synthesis generator.

The surface is defined independently of the run's grid: SurfaceTopography's ``fourier_synthesis`` draws
it (seeded NumPy generators: the same numbers on every machine, and the same surface on every
SurfaceTopography release from 1.18.2, the floor, to 1.27.1, tested) on a reference grid just fine
enough to hold every Fourier mode below the short-wavelength cut-off, it is rescaled to the exact rms
height (or rms slope) asked for, and it is then evaluated on the run's grid by Fourier interpolation
(exact for a band-limited surface).  So the same ``seed`` gives the same surface, and a finer ``dx``
samples the same surface more finely.
"""
from __future__ import annotations

import threading
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from tengsim.backend import fft as _bf
from tengsim.errors import TengsimError, positive
from tengsim.grid import Grid
from tengsim.registry import KERNELS, SHAPES
from tengsim.schema import Field
from tengsim.shapes.base import Shape, _length


_GLOBAL_RNG = threading.Lock()


def _synthesis(fourier_synthesis, nb_grid_pts, physical_sizes, seed, **kw):
    """SurfaceTopography's generator driven by ``seed``, drawn the same way on every release from 1.18:
    amplitudes from ``amplitude_distribution`` (a PCG64 ``Generator`` seeded with ``seed``), phases from
    NumPy's global (MT19937) state seeded with ``seed`` for the call and restored after it, under a lock.

    Every release keeps that order of draws (1.27 documents ``rng=None`` as "numpy's global random
    state, such that np.random.seed controls the result"); its newer ``rng=`` argument would draw a
    different surface, so it is not used.  Releases differ only in the mean and the overall scale of
    the heights, which :func:`_coefficients` removes; tests/test_rough.py checks stored coefficients."""
    rng = np.random.default_rng(seed)
    with _GLOBAL_RNG:
        state = np.random.get_state()
        np.random.seed(seed)
        try:
            return fourier_synthesis(nb_grid_pts, physical_sizes,
                                     amplitude_distribution=lambda n: rng.normal(size=n), **kw)
        finally:
            np.random.set_state(state)


@lru_cache(maxsize=8)
def _coefficients(cell, hurst, rms_height, rms_slope, short_cutoff, long_cutoff, seed):
    """Fourier coefficients c[kx, ky] (h(x) = Σ c e^{iq·(x − x0)}, x0 the reference grid's first pixel
    centre) of the surface with the exact rms height or slope, and the reference grid's pixel count."""
    from SurfaceTopography.Generation import fourier_synthesis

    n = 2 * int(np.floor(cell / short_cutoff + 1e-9)) + 3  # odd: every mode |k| <= cell/short_cutoff fits
    topo = _synthesis(fourier_synthesis, (n, n), (cell, cell), seed, hurst=hurst, rms_height=1.0,
                      short_cutoff=short_cutoff, long_cutoff=long_cutoff)
    c = _bf.np_fft2(np.asarray(topo.heights(), dtype=float)) / n**2
    c[0, 0] = 0.0
    q = 2 * np.pi * _bf.fftfreq(n, d=1.0 / n) / cell
    q2 = q[:, None] ** 2 + q[None, :] ** 2
    power = np.sum(np.abs(c) ** 2 * (q2 if rms_slope is not None else 1.0))  # Parseval: <h²> or <|∇h|²>
    if not power > 0:
        raise TengsimError(f"rough: the cut-offs short_cutoff = {short_cutoff:g}, long_cutoff = {long_cutoff:g} "
                           f"leave no Fourier mode in the cell {cell:g}")
    c *= (rms_slope if rms_slope is not None else rms_height) / np.sqrt(power)
    c.setflags(write=False)
    return c, n


def _interpolate(c: np.ndarray, n_ref: int, cell: float, grid: Grid) -> np.ndarray:
    """The band-limited surface of coefficients ``c`` (reference grid of ``n_ref`` pixels) on ``grid``."""
    n = grid.nx
    k = _bf.fftfreq(n_ref, d=1.0 / n_ref).round().astype(int)
    keep = np.abs(k) <= (n_ref - 3) // 2  # the modes that can be nonzero (below the short cut-off)
    if (n_ref - 3) // 2 > (n - 1) // 2:  # pragma: no cover - the grid check refuses this first
        raise TengsimError(f"rough: a {n}×{n} grid cannot hold the surface's modes")
    k = k[keep]
    c = c[np.ix_(keep, keep)]
    idx = np.mod(k, n)  # the same integer wave numbers on the run's grid (all |k| < n/2: no aliasing)
    # the run's first pixel centre lies (dx − dx_ref)/2 past the reference one's
    shift = np.exp(2j * np.pi * k * (grid.dx - cell / n_ref) / 2 / cell)
    spec = np.zeros((n, n), dtype=complex)
    spec[np.ix_(idx, idx)] = c * shift[:, None] * shift[None, :]
    return _bf.np_ifft2(spec).real * n * n


@dataclass(frozen=True)
class Rough(Shape):
    """Periodic self-affine random surface (PSD C(q) ∝ q^{−2(1+H)} between the cut-offs), from
    SurfaceTopography's generator; U0 = max(h) − h (the apex at the highest point).  Use the periodic
    kernel (boundary = 'periodic'; 'free' is refused).

    Give the rms height or the rms slope (not both; neither: rms height 1 ε).  Cut-offs: short (default
    cell/32, at least 2 pixels of the run's grid), long (default the cell; the PSD is flat below it).
    Physical input: ℓ = ε, every length divided by ε.
    """

    cell: float = 32.0
    hurst: float = 0.8
    rms_height: float | None = None
    rms_slope: float | None = None
    short_cutoff: float | None = None
    long_cutoff: float | None = None
    seed: int = 0

    physical_fields = (
        _length("cell", "periodic cell side"),
        Field("hurst", "float", 0.8, help="Hurst exponent H, 0 < H < 1"),
        _length("rms_height", "rms height (default 1 ε unless rms_slope is given)", None),
        Field("rms_slope", "float", None, help="rms slope (instead of rms_height)"),
        _length("short_cutoff", "short-wavelength cut-off (default cell/32; >= 2 dx)", None),
        _length("long_cutoff", "long-wavelength cut-off, PSD flat beyond it (default the cell)", None),
        Field("seed", "int", 0, help="random seed: the same seed, the same surface"),
    )
    field_help = {"cell": "periodic cell side in ε", "hurst": "Hurst exponent H, 0 < H < 1",
                  "rms_height": "rms height in ε (default 1 unless rms_slope is given)",
                  "rms_slope": "rms slope (instead of rms_height)",
                  "short_cutoff": "short-wavelength cut-off in ε (default cell/32; >= 2 dx)",
                  "long_cutoff": "long-wavelength cut-off in ε, PSD flat beyond it (default the cell)",
                  "seed": "random seed: the same seed, the same surface"}
    si_map = {"cell": "cell"}
    lateral_unit = "ε"
    is_pattern = False  # already a periodic surface: not a cell pattern of tengsim.shapes.arrays

    def __post_init__(self):
        positive("cell", self.cell)
        # implausible surfaces are refused, not solved with overflow warnings (topography.MAX_RELIEF)
        from tengsim.shapes.topography import MAX_RELIEF

        if self.rms_slope is not None and not positive("rms_slope", self.rms_slope) <= MAX_RELIEF:
            raise TengsimError(f"rough: rms_slope = {self.rms_slope:g} is implausible (at most {MAX_RELIEF:g}, a "
                               "slope of 84°)")
        if self.rms_height is not None and not positive("rms_height", self.rms_height) <= MAX_RELIEF * self.cell:
            raise TengsimError(f"rough: rms_height = {self.rms_height:g} is more than {MAX_RELIEF:g} times the "
                               f"cell {self.cell:g}: implausible (a height in another unit?)")
        settle_spectrum(self, float(self.cell), key=lambda k: k, lead="rough: ", cell_name="the cell")

    @classmethod
    def refuse_unused(cls, values: dict, given) -> None:
        b = values.get("boundary") or "free"
        if KERNELS.canonical(b) != "periodic":
            raise TengsimError(f"rough: boundary = {b!r} is refused: the random surface is periodic, "
                               "give boundary = 'periodic'")

    def grid(self, dx: float) -> Grid:
        g = Grid.square(self.cell, dx)
        self._check_grid(g)
        return g

    def _check_grid(self, grid: Grid) -> None:
        if grid.nx != grid.ny or abs(grid.lx - self.cell) > 1e-9 * self.cell or abs(grid.ly - self.cell) > 1e-9 * self.cell:
            raise TengsimError(f"rough: the grid ({grid.nx}×{grid.ny}, {grid.lx:g}×{grid.ly:g}) must tile the "
                               f"cell {self.cell:g} exactly")
        if self.short_cutoff < 2 * grid.dx * (1 - 1e-9):
            raise TengsimError(f"rough: short_cutoff = {self.short_cutoff:g} is below 2 pixels of the grid "
                               f"(dx = {grid.dx:g}): use dx <= {self.short_cutoff / 2:g} or a longer short_cutoff")

    def heights(self, grid: Grid) -> np.ndarray:
        """The surface h on ``grid`` (mean 0)."""
        self._check_grid(grid)
        c, n_ref = _coefficients(float(self.cell), float(self.hurst), self.rms_height, self.rms_slope,
                                 float(self.short_cutoff), float(self.long_cutoff), int(self.seed))
        return _interpolate(c, n_ref, float(self.cell), grid)

    def gap(self, grid: Grid) -> np.ndarray:
        h = self.heights(grid)
        return h.max() - h


SHAPES.register("rough", Rough, summary="self-affine random rough surface (periodic kernel)")


def settle_spectrum(obj, cell: float, key, lead: str = "", cell_name: str = "the cell") -> None:
    """Check a self-affine spectrum's fields on ``obj`` (a frozen dataclass with ``hurst``, ``rms_height``,
    ``rms_slope``, ``short_cutoff``, ``long_cutoff``, ``seed``) for a surface over ``cell``, and fill the
    defaults (rms height 1 without a slope, long cut-off the cell, short cut-off cell/32).  ``key(name)``
    spells a field in the messages, ``lead`` starts them: one-line TengsimErrors naming the value."""
    def pos(name, v):
        if isinstance(v, bool) or not isinstance(v, (int, float, np.floating)) or not (np.isfinite(v) and v > 0):
            raise TengsimError(f"{key(name)} must be finite and > 0, got {v!r}")
        return float(v)

    h = obj.hurst
    if isinstance(h, bool) or not isinstance(h, (int, float)) or not 0 < h < 1:
        raise TengsimError(f"{lead}{key('hurst')} must be in (0, 1), got {h!r}")
    if obj.rms_height is not None and obj.rms_slope is not None:
        raise TengsimError(f"{lead}give {key('rms_height')} or {key('rms_slope')}, not both (got "
                           f"{key('rms_height')} = {obj.rms_height!r}, {key('rms_slope')} = {obj.rms_slope!r})")
    if obj.rms_slope is not None:
        pos("rms_slope", obj.rms_slope)
    else:
        object.__setattr__(obj, "rms_height", 1.0 if obj.rms_height is None else pos("rms_height", obj.rms_height))
    if obj.long_cutoff is None:
        object.__setattr__(obj, "long_cutoff", float(cell))
    if obj.short_cutoff is None:
        object.__setattr__(obj, "short_cutoff", cell / 32)
    pos("long_cutoff", obj.long_cutoff)
    pos("short_cutoff", obj.short_cutoff)
    if obj.long_cutoff > cell * (1 + 1e-12):
        raise TengsimError(f"{lead}{key('long_cutoff')} = {obj.long_cutoff:g} exceeds {cell_name} {cell:g}")
    if obj.short_cutoff >= obj.long_cutoff:
        raise TengsimError(f"{lead}{key('short_cutoff')} = {obj.short_cutoff:g} must be below {key('long_cutoff')} = "
                           f"{obj.long_cutoff:g}")
    sd = obj.seed
    if isinstance(sd, bool) or not isinstance(sd, (int, np.integer)) or sd < 0:
        raise TengsimError(f"{lead}{key('seed')} must be an integer >= 0, got {sd!r}")
