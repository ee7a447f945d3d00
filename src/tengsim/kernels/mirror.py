"""Symmetry-reduced kernels: the free or periodic kernel acting on the irreducible block of
a mirror-symmetric field, without ever building the full grid's kernel.

A field even about the centre pixel of an odd grid along one or both axes (:class:`tengsim.grid.Mirror`)
is held as its block (about a quarter or a half of the grid).  :class:`MirrorKernel` wraps the same
body as :func:`tengsim.kernels.make_kernel` (half-space or film, free or periodic) and gives

* ``reduced`` — the kernel on the block: ``reduced.apply(p_block)`` is w = K p of the unfolded field,
  restricted to the block, in one convolution with even-symmetric transforms (the solvers run on it);
* ``apply(p_full)`` — the same on the full grid for the few full-grid uses (it refuses an asymmetric
  field rather than return a wrong answer).

The free kernel: the influence coefficients (the exact pixel integrals of the half-space plus the film's
correction, both functions of the offset alone and even in it) are tabulated on offsets 0 … M along a
mirrored axis, M ≥ 2c (c = the block's last index), and transformed by a DCT-I (an rfft of period 2M):
the period-2M circular convolution of the even extension equals the linear convolution on the block,
since the offsets it uses, |i − j| ≤ 2c ≤ M, never wrap.  An axis that is not mirrored is zero-padded
as in :class:`~tengsim.kernels.halfspace.FreeKernel`.  The periodic kernel on an odd grid: an even field of
odd period n has a real, even DFT (a DCT-V, which scipy lacks: no DCT of an odd period); it is computed
from the unfolded lines, only the block's lines being transformed, two real lines per complex FFT (both
transforms are real, so they separate exactly), and the multiplier 2κ/|q| (times the film's C(|q| T))
is tabulated on the c + 1 non-negative wave numbers of each mirrored axis.  The spectra are real and
about a quarter of the full kernel's entries; nothing of the full grid's size is built.
See :class:`tengsim.kernels.dct.MirrorConvolver` and docs/benchmarks.md for the costs measured.
"""
from __future__ import annotations

import numpy as np

from tengsim import backend
from tengsim.backend import fft as _bf
from tengsim.errors import TengsimError
from tengsim.grid import Grid, Mirror
from tengsim.kernels import dct, film
from tengsim.kernels.base import pixel_influence
from tengsim.kernels.film import _Film, film_pixel_correction

BOUNDARIES = ("free", "periodic")
_FILM_KEYS = ("thickness", "substrate", "poisson")
SYMMETRY_CHOICES = ("auto", "off")
_AXIS_NAMES = ("x", "y")


def choose_symmetry(shape, U0, grid, boundary: str, solver, symmetry: str = "auto"):
    """(mirror axes, label) of a run: the mirrors the shape declares (``mirror_axes``) that its gap U0 has on
    ``grid`` (odd pixel counts along them), when the kernel is the free or periodic one (half-space or
    film) and the solver (an object or a registered name) solves on a weighted block (its ``weighted_block``
    attribute: fast, vsr); else () and the reason.  ``symmetry='off'``: always ()."""
    sym = str(symmetry).strip().lower()
    if sym not in SYMMETRY_CHOICES:
        raise TengsimError(f"symmetry = {symmetry!r} is not one of {', '.join(SYMMETRY_CHOICES)}")
    if sym == "off":
        return (), "off"
    declared = tuple(getattr(shape, "mirror_axes", ()) or ())
    if not declared:
        return (), "none (shape has no mirror)"
    if boundary not in BOUNDARIES:  # the kernels that have a symmetry-reduced form
        return (), f"none (boundary {boundary})"
    if isinstance(solver, str):
        from tengsim.registry import SOLVERS

        name, solver = solver, (SOLVERS.get(solver) if solver in SOLVERS.names() else None)
    else:
        name = getattr(solver, "name", None)
    if not getattr(solver, "weighted_block", False):
        return (), f"none (solver {name or '?'})"
    axes = tuple(a for a in sorted(set(declared)) if grid.shape[a] % 2 == 1 and grid.shape[a] >= 5
                 and Mirror(grid, (a,)).is_symmetric(U0))
    if not axes:
        return (), "none (gap not mirror symmetric on the grid)"
    return axes, "+".join(_AXIS_NAMES[a] for a in axes)


class ReducedKernel:
    """The kernel on the irreducible block: ``grid`` the block's grid, ``apply`` one convolution."""

    def __init__(self, owner: "MirrorKernel", conv):
        self.grid = owner.mirror.reduced_grid
        self.mirror = owner.mirror
        self.coupling = owner.coupling
        self.periodic = owner.periodic
        self.pinned_mean = owner.pinned_mean
        if owner.periodic:
            self.mean_compliance = owner.mean_compliance
        self._conv = conv

    def apply(self, p: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
        """w = K p of the unfolded field, on the block (one convolution), into ``out`` if given."""
        p = np.asarray(p, dtype=float)
        if p.shape != self.grid.shape:
            raise TengsimError(f"field of shape {p.shape} is not the {self.grid.shape} block")
        return self._conv(p, out)


class MirrorKernel(_Film):
    """The ``boundary`` ('free' or 'periodic') kernel of ``grid`` (half-space, or a film with
    ``thickness``, ``substrate``, ``poisson`` as in make_kernel) for fields with the symmetry ``mirror``."""

    def __init__(self, boundary: str, grid: Grid, coupling: float, mirror: Mirror, **params):
        if not isinstance(boundary, str) or boundary not in BOUNDARIES:
            raise TengsimError(f"a symmetry-reduced kernel needs boundary 'free' or 'periodic', got {boundary!r}")
        if not isinstance(mirror, Mirror):
            raise TengsimError(f"mirror must be a tengsim.grid.Mirror, got {mirror!r}")
        if mirror.grid != grid:
            raise TengsimError(f"the mirror's grid {mirror.grid} is not the kernel's grid {grid}")
        bad = sorted(set(params) - set(_FILM_KEYS))
        if bad:
            raise TengsimError(f"unknown kernel parameter {bad[0]!r} (known: {', '.join(_FILM_KEYS)})")
        self.boundary, self.grid, self.mirror, self.coupling = boundary, grid, mirror, coupling
        self.thickness = params.get("thickness")
        self.substrate = params.get("substrate", "bonded")
        self.poisson = params.get("poisson", 0.5)
        self.coupling = self._init_body()
        self.periodic = boundary == "periodic"
        if self.periodic:
            modes, lengths, spectrum = self._periodic()
        else:
            modes, lengths, spectrum = self._free()
            self.pinned_mean = False
        self.modes, self.lengths = modes, lengths
        self._conv = dct.MirrorConvolver(mirror.reduced_shape, modes, lengths, spectrum)
        self.reduced = ReducedKernel(self, self._conv)

    # --- construction ---------------------------------------------------------------------------
    def _free(self):
        g, red = self.grid, self.mirror.reduced_shape
        modes, lengths, offsets = [], [], []
        for k, (n, h) in enumerate(zip(g.shape, (g.dx, g.dy))):
            if k in self.mirror.axes:
                L = dct.mirror_dct1_len(red[k])  # M = L − 1 >= 2c + 2 = n + 1
                modes.append("dct1")
                offsets.append(np.arange(L) * h)
            else:
                L = backend.fast_len(2 * n - 1)
                modes.append("pad")
                i = np.arange(L)
                offsets.append(np.minimum(i, L - i) * h)  # even layout: its rfft is real
            lengths.append(L)
        X, Y = np.meshgrid(*offsets, indexing="ij")
        coeff = pixel_influence(X, Y, g.dx, g.dy)
        if self.film:
            coeff += film_pixel_correction(X, Y, g.dx, g.dy, self.thickness, self.poisson, self.substrate)
        coeff *= self.coupling / np.pi
        del X, Y
        spectrum = dct.mirror_spectrum(coeff, modes)
        norm = 1.0
        for m, L in zip(modes, lengths):
            norm *= 2 * (L - 1) if m == "dct1" else L
        spectrum /= norm
        return tuple(modes), tuple(lengths), spectrum

    def _periodic(self):
        g = self.grid
        modes = tuple("even" if k in self.mirror.axes else "periodic" for k in (0, 1))
        # both layouts hold the wave numbers 2πk/L, k = 0 … n // 2: the mirrored axis by evenness, the
        # other as the rfft's half spectrum
        qx = 2 * np.pi * _bf.rfftfreq(g.nx, d=g.dx)
        qy = 2 * np.pi * _bf.rfftfreq(g.ny, d=g.dy)
        q = np.hypot(*np.meshgrid(qx, qy, indexing="ij"))
        with np.errstate(divide="ignore"):
            mult = np.where(q > 0, 2 * self.coupling / np.where(q > 0, q, 1.0), 0.0)
        if self.film:
            mult *= film.compliance_factor(q * self.thickness, self.poisson, self.substrate)
            mult[0, 0] = film.mean_compliance(self.thickness, self.poisson, self.coupling)
        self.mean_compliance = float(mult[0, 0])
        self.pinned_mean = not self.mean_compliance > 0
        return modes, tuple(g.shape), mult / (g.nx * g.ny)

    # --- use ------------------------------------------------------------------------------------
    def apply(self, p: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
        """w = K p on the full grid for a symmetric ``p`` (reduce → block convolution → unfold)."""
        p = np.asarray(p, dtype=float)
        if p.shape != self.grid.shape:
            raise TengsimError(f"field of shape {p.shape} is not on the {self.grid.shape} grid")
        if not self.mirror.is_symmetric(p):
            raise TengsimError(f"the field is not mirror symmetric along axes {self.mirror.axes}: "
                               "a symmetry-reduced kernel cannot apply to it (use the full kernel)")
        w = self.mirror.unfold(self.reduced.apply(self.mirror.reduce(p)))
        if out is None:
            return w
        np.copyto(out, w)
        return out

    def params(self) -> dict:
        """The same dict as the full kernel's ``params()``: results record the same body."""
        return {"boundary": self.boundary, "coupling": self.coupling, **self.film_params()}

    @property
    def backend(self) -> str:
        return self._conv.backend

    def __repr__(self):
        return (f"MirrorKernel({self.boundary!r}, {self.grid}, coupling={self.coupling}, "
                f"axes={self.mirror.axes}, {self.film_params()})")


def make_mirror_kernel(boundary: str, grid: Grid, coupling: float, axes, **params) -> MirrorKernel:
    """:class:`MirrorKernel` for the mirror of ``grid`` along ``axes`` (0: X, 1: Y)."""
    return MirrorKernel(boundary, grid, coupling, Mirror(grid, tuple(axes)), **params)
