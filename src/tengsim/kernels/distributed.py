"""The periodic kernel split across MPI processes: slab decomposition of the 2-D real FFT.

For one surface too large for a machine, each of the ``comm.size`` processes (ranks) holds a slab of
rows of every field (rows ``rows[rank]`` of the nx × ny grid: :func:`slabs`), and a convolution
w = K p is

1. a real FFT along Y of the local rows (nothing moves),
2. the transpose: an all-to-all exchange (MPI ``Alltoallv``) after which each rank holds *all* nx rows
   of its own slab of the ny/2 + 1 spectral columns,
3. the FFT along X, the multiplier (:func:`tengsim.kernels.halfspace.periodic_multiplier`, only the
   rank's columns of it are ever built), the inverse FFT along X,
4. the transpose back and the inverse real FFT along Y.

The data transpose is the one distributed piece written here; the transforms are scipy's, the
exchange is MPI's own all-to-all (mpi4py).  Per convolution each rank sends and receives about
2 × 16 B × nx (ny/2 + 1)/size (the complex half-spectrum, twice), minus its own block.
"""
from __future__ import annotations

import numpy as np

from tengsim.backend import fft as _bf
from tengsim.errors import TengsimError
from tengsim.grid import Grid
from tengsim.kernels.film import _Film
from tengsim.kernels.halfspace import periodic_multiplier


def slabs(n: int, size: int) -> list[tuple[int, int]]:
    """Contiguous [start, stop) ranges splitting range(n) into ``size`` near-equal slabs (the first
    ``n % size`` one longer)."""
    if size < 1 or n < size:
        raise TengsimError(f"cannot split {n} rows over {size} processes (need at least one row each)")
    base, extra = divmod(n, size)
    out, start = [], 0
    for r in range(size):
        stop = start + base + (1 if r < extra else 0)
        out.append((start, stop))
        start = stop
    return out


def check_split(comm, boundary: str, solver, grid) -> None:
    """An MPI run (``comm``) splits the periodic kernel's FFT across its processes: refuse what it cannot split
    (another boundary, a ``solver`` that does not split over MPI, a ``grid`` too small for the processes)."""
    n = comm.Get_size()
    if boundary != "periodic":
        raise TengsimError(f"an MPI run ({n} processes) splits the periodic kernel across them: give boundary = "
                           f"'periodic' (got {boundary!r}), or run without mpiexec")
    if not getattr(solver, "splits_over_mpi", False):
        raise TengsimError(f"an MPI run ({n} processes) uses the fast solver, not {getattr(solver, 'name', solver)!r}")
    if grid.nx < n or grid.ny // 2 + 1 < n:
        raise TengsimError(f"the {grid.nx}×{grid.ny} grid is too small to split over {n} processes")


class SlabPeriodicKernel(_Film):
    """The periodic half-space (or film) kernel on the rows ``rows`` of ``grid`` owned by this rank.

    ``apply(p_local)`` is one distributed convolution: every rank of ``comm`` must call it together.
    ``grid`` is the full grid; ``local_grid`` the rank's slab (same pixel size).  Film parameters
    as :class:`tengsim.kernels.halfspace.PeriodicKernel`.
    """

    def __init__(self, grid: Grid, coupling: float, comm, thickness=None, substrate: str = "bonded",
                 poisson: float = 0.5):
        self.grid, self.coupling, self.comm = grid, coupling, comm
        self.thickness, self.substrate, self.poisson = thickness, substrate, poisson
        self.coupling = self._init_body()
        self.size, self.rank = comm.Get_size(), comm.Get_rank()
        self.row_slabs = slabs(grid.nx, self.size)
        self.nyh = grid.ny // 2 + 1
        self.col_slabs = slabs(self.nyh, self.size) if self.nyh >= self.size else None
        if self.col_slabs is None:
            raise TengsimError(f"a {grid.ny}-pixel row has too few spectral columns for {self.size} processes")
        self.rows = self.row_slabs[self.rank]
        c0, c1 = self.col_slabs[self.rank]
        self.local_grid = Grid(max(3, self.rows[1] - self.rows[0]), grid.ny, grid.dx, grid.dy)
        self.local_shape = (self.rows[1] - self.rows[0], grid.ny)
        self._mult = periodic_multiplier(self, grid, slice(c0, c1))
        self.mean_compliance = float(self._mult[0, 0]) if c0 == 0 else None
        self.mean_compliance = comm.bcast(self.mean_compliance, root=0)
        self.pinned_mean = not self.mean_compliance > 0
        self.periodic = True
        self.padded_shape = grid.shape
        nl, nc = self.local_shape[0], c1 - c0
        rcounts = [(r1 - r0) * nc for r0, r1 in self.row_slabs]          # rows of every rank, my columns
        scounts = [nl * (b - a) for a, b in self.col_slabs]               # my rows, every rank's columns
        self._fwd = (scounts, _displs(scounts), rcounts, _displs(rcounts))
        self._bwd = (rcounts, _displs(rcounts), scounts, _displs(scounts))
        self._send = np.empty(sum(scounts), complex)
        self._cols = np.empty((grid.nx, nc), complex)   # all rows of my spectral columns
        self._recv = np.empty(sum(scounts), complex)
        self.bytes_per_apply = 2 * 16 * (sum(scounts) - scounts[self.rank])

    def _exchange(self, send, recv, plan):
        from mpi4py import MPI

        sc, sd, rc, rd = plan
        self.comm.Alltoallv([send, sc, sd, MPI.C_DOUBLE_COMPLEX], [recv, rc, rd, MPI.C_DOUBLE_COMPLEX])

    def apply(self, p: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
        """w = K p on this rank's rows (one distributed convolution), into ``out`` if given."""
        p = np.asarray(p, dtype=float)
        if p.shape == self.grid.shape and p.shape != self.local_shape:  # a full field (every rank): full K p
            r0, r1 = self.rows
            full = self.gather(self.apply(p[r0:r1]))
            if out is None:
                return full
            np.copyto(out, full)
            return out
        if p.shape != self.local_shape:
            raise TengsimError(f"field of shape {p.shape} is not this rank's slab {self.local_shape}")
        nl, ny = self.local_shape
        w = _bf.workers((self.grid.nx, ny))
        spec = _bf.rfft(p, axis=1, workers=w)                                      # (nl, nyh)
        off = 0
        for a, b in self.col_slabs:                                      # pack: block j = my rows × cols_j
            k = nl * (b - a)
            self._send[off:off + k] = spec[:, a:b].ravel()
            off += k
        self._exchange(self._send, self._cols.reshape(-1), self._fwd)   # → all rows × my cols
        cols = _bf.fft(self._cols, axis=0, workers=w, overwrite_x=True)
        cols *= self._mult
        cols = _bf.ifft(cols, axis=0, workers=w, overwrite_x=True)
        self._exchange(np.ascontiguousarray(cols).reshape(-1), self._recv, self._bwd)  # → my rows × all cols
        off = 0
        for a, b in self.col_slabs:
            k = nl * (b - a)
            spec[:, a:b] = self._recv[off:off + k].reshape(nl, b - a)
            off += k
        res = _bf.irfft(spec, n=ny, axis=1, workers=w)
        if out is None:
            return res
        np.copyto(out, res)
        return out

    def gather(self, a: np.ndarray) -> np.ndarray:
        """The full field from every rank's rows ``a`` (on every rank: MPI Allgatherv)."""
        from mpi4py import MPI

        ny = self.grid.ny
        counts = [(r1 - r0) * ny for r0, r1 in self.row_slabs]
        displs = [r0 * ny for r0, _ in self.row_slabs]
        full = np.empty(self.grid.shape)
        self.comm.Allgatherv(np.ascontiguousarray(a, dtype=float), [full, counts, displs, MPI.DOUBLE])
        return full

    def params(self) -> dict:
        return {"boundary": "periodic", "coupling": self.coupling, **self.film_params()}


def _displs(counts):
    return [int(x) for x in np.concatenate([[0], np.cumsum(counts)[:-1]])]
