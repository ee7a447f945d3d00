"""Nested-grid start for large periodic problems (rough surfaces, arrays of cells).

On a periodic cell the fast solver converges slowest on the long wavelengths, where the kernel
2κ/|q| is largest, and a larger cell has longer ones: its iterations per equilibrium grow with the
cell.  Those wavelengths are already resolved by a coarser grid over the same cell, at a quarter of
the cost per convolution.  :func:`nested_solve` therefore solves the coarsest level (pixel 2^L times
larger, heights Fourier-truncated) from the undeformed state, then each finer level from the
Fourier-interpolated elastic pressure q of the level below (w = K q: one convolution), up to the
given grid.

Two prolongations of the pressure: ``"fourier"`` (the default; a smooth adhesive pressure) and ``"block"``
(each coarse pixel's pressure on its 2×2 fine pixels): a hard-wall pressure ends at the contact's edge, where a
Fourier series rings and its clipped start costs the fine level more iterations than a cold start (measured with
``pk`` on the benchmark surface in docs/benchmarks.md).  Under load control (``load``: the mean pressure) each level
solves to the same load (``solver.solve_load``) and the block start is rescaled to it.

Only the finest level's answer is returned, and it is judged like any other: by the Eq. (9) residual
on the given grid, so it is a stable equilibrium of the fine problem.  With adhesion a problem can
have several; the nested start may settle in a different one from a cold start (both are local
minima of the same energy; measured on the benchmark surface in docs/benchmarks.md).

It sits with the solvers and, like them, never imports a kernel module: the periodic kernel is the one
registered as ``"periodic"`` (``tengsim.registry.KERNELS``), and each coarse level's kernel is the given
kernel's own class on the coarse grid, with the same coupling and film.
"""
from __future__ import annotations

import dataclasses

import time
from dataclasses import dataclass, field

import numpy as np

from tengsim.errors import TengsimError
from tengsim.grid import Grid, fourier_resample
from tengsim.registry import KERNELS
from tengsim.solvers.types import Equilibrium, Problem, State


@dataclass
class LevelStat:
    """One level of a nested solve: grid size, convolutions, seconds."""

    shape: tuple
    n_conv: int
    iterations: int
    seconds: float
    residual: float


@dataclass
class NestedSolve:
    """The finest level's equilibrium and the cost of every level (coarsest first)."""

    equilibrium: Equilibrium
    levels: list = field(default_factory=list)
    approach: float = 0.0
    """Load control: the finest level's rigid approach beyond the problem's g0 (ε; ``solve_load``'s dD)."""

    @property
    def seconds(self) -> float:
        return sum(s.seconds for s in self.levels)

    @property
    def n_conv(self) -> int:
        return sum(s.n_conv for s in self.levels)

    @property
    def fine_equivalent_conv(self) -> float:
        """Convolutions weighted by their grid size relative to the finest grid."""
        nf = np.prod(self.levels[-1].shape)
        return float(sum(s.n_conv * np.prod(s.shape) / nf for s in self.levels))


def block_prolong(q: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
    """``q`` on a grid ``shape`` = an integer multiple of its own: each pixel's value on its block of fine pixels."""
    fx, fy = shape[0] // q.shape[0], shape[1] // q.shape[1]
    if (fx * q.shape[0], fy * q.shape[1]) != tuple(shape):
        raise TengsimError(f"block prolongation needs a multiple of {q.shape}, got {tuple(shape)}")
    return np.repeat(np.repeat(np.asarray(q, dtype=float), fx, axis=0), fy, axis=1)


PROLONGATIONS = {"fourier": fourier_resample, "block": block_prolong}
"""The pressure's prolongation from one level to the next, by name."""


def coarse_levels(shape: tuple[int, int], min_size: int = 128, levels: int | None = None,
                  dx: float | None = None, max_dx: float | None = None) -> list:
    """Grid shapes from the coarsest to ``shape``, halving while both sides stay even and >= min_size
    and, given the pixel ``dx``, while the coarse pixel stays <= ``max_dx``."""
    out = [tuple(shape)]
    f = 1
    while (levels is None or len(out) <= levels) and all(k % 2 == 0 and k // 2 >= min_size for k in out[-1]):
        if dx is not None and max_dx is not None and dx * 2 * f > max_dx * (1 + 1e-9):
            break
        f *= 2
        out.append((out[-1][0] // 2, out[-1][1] // 2))
    return out[::-1]


def nested_solve(solver, g0: np.ndarray, law, kernel, min_size: int = 128,
                 levels: int | None = None, max_dx: float = 0.5, coarse_tol: float | None = 1e-3,
                 coarse_max_iter: int | None = 1000, on_level=None, load: float | None = None,
                 prolong: str = "fourier") -> NestedSolve:
    """Solve the periodic problem (g0 = U0 − D + 1, law, kernel) by nested grids; see the module doc.

    Grids are halved down to ``min_size`` pixels, at most ``levels`` times, and never to a pixel
    coarser than ``max_dx`` (in ε, the range of the surface law: on coarser pixels the adhesive
    contact edge is trapped by the lattice and a level may not converge — measured: on a 2048² rough
    surface with dx = 0.25 the 4 ε, 2 ε and 1 ε levels all ran to max_iter).  A coarse level that
    does not converge still hands its state up as a start; its residual is in ``levels``.

    Coarse levels are only starts, so they are solved to ``coarse_tol`` (in ε; default 1e-3, below
    the difference between two levels' answers) in at most ``coarse_max_iter`` iterations (``None``
    keeps the solver's own); the finest level always to the solver's tolerance.  Measured on the
    scaling study's 4096² surface: its 2048² level, solved to 1e-6, ran past 3000 iterations (~20 min).
    ``on_level(stat)`` is called with each level's :class:`LevelStat` as it finishes (progress).
    ``load``: load control at that mean pressure (W/ε; the solver's ``solve_load``), None: displacement control.
    ``prolong``: ``"fourier"`` or ``"block"`` (module doc).
    ``kernel``: the periodic kernel (``tengsim.kernels.PeriodicKernel`` or a subclass; half-space or film).
    """
    if prolong not in PROLONGATIONS:
        raise TengsimError(f"prolong must be one of {', '.join(PROLONGATIONS)}, got {prolong!r}")
    if load is not None and not hasattr(solver, "solve_load"):
        raise TengsimError(f"load control needs a solver with solve_load; {type(solver).__name__} has none")
    periodic = KERNELS.get("periodic") if "periodic" in KERNELS else None
    if periodic is None or not isinstance(kernel, periodic):
        raise TengsimError("nested_solve needs a periodic kernel (the coarse grids resample the cell "
                           "by Fourier series)")
    g0 = np.asarray(g0, dtype=float)
    grid = kernel.grid
    if g0.shape != grid.shape:
        raise TengsimError(f"g0 has shape {g0.shape}, the kernel's grid {grid.shape}")
    shapes = coarse_levels(grid.shape, min_size, levels, dx=max(grid.dx, grid.dy), max_dx=max_dx)
    stats = []
    q = None
    eq = None
    for shape in shapes:
        t0 = time.perf_counter()
        if shape == grid.shape:
            k, g = kernel, g0
        else:
            cg = Grid(shape[0], shape[1], grid.lx / shape[0], grid.ly / shape[1])
            k = type(kernel)(cg, kernel.coupling, **kernel.film_params())
            g = fourier_resample(g0, shape)
        n_conv = 0
        if q is None:
            start = State.zero(shape)
        else:
            qf = PROLONGATIONS[prolong](q, shape)
            if load is not None and prolong == "block" and qf.mean() > 0:
                qf *= load / qf.mean()
            start = State(qf, k.apply(qf))
            n_conv = 1
        lvl = solver
        if shape != grid.shape:
            kw = {}
            if coarse_tol is not None and hasattr(solver, "tol"):
                kw["tol"] = max(float(coarse_tol), solver.tol)
            if coarse_max_iter is not None and hasattr(solver, "max_iter"):
                kw["max_iter"] = min(int(coarse_max_iter), solver.max_iter)
            lvl = dataclasses.replace(solver, **kw) if kw and dataclasses.is_dataclass(solver) else solver
        if load is None:
            eq = lvl.solve(Problem(g, law, k), start)
        else:
            eq, approach = lvl.solve_load(Problem(g, law, k), float(load), start)
        n_conv += eq.n_conv
        stats.append(LevelStat(shape, n_conv, eq.iterations, time.perf_counter() - t0, eq.residual))
        if on_level is not None:
            on_level(stats[-1])
        q = eq.state.q
    eq = dataclasses.replace(eq, n_conv=stats[-1].n_conv)
    return NestedSolve(eq, stats, approach if load is not None else 0.0)
