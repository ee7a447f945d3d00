"""Is this process one of several MPI processes (``mpiexec -n N tengsim ...``)?  The one place that asks.

Under an MPI launcher the environment names the world size (MPICH/Hydra ``PMI_SIZE``, Open MPI
``OMPI_COMM_WORLD_SIZE``, Slurm ``PMI_SIZE``/``SLURM_NTASKS`` through PMI); only then is mpi4py
imported, so a serial run never loads MPI.  :func:`world` returns ``mpi4py.MPI.COMM_WORLD`` when
the world has more than one process, else None.
"""
from __future__ import annotations

import os

from tengsim.errors import TengsimError

_SIZE_VARS = ("PMI_SIZE", "OMPI_COMM_WORLD_SIZE", "MPI_LOCALNRANKS", "PMIX_SIZE")


def launched_size() -> int:
    """The world size an MPI launcher announced in the environment (1 when there is none)."""
    for var in _SIZE_VARS:
        v = os.environ.get(var)
        if v and v.strip().isdigit():
            return int(v)
    return 1


def world():
    """MPI.COMM_WORLD when this process is one of more than one MPI processes, else None."""
    if launched_size() <= 1:
        return None
    try:
        from mpi4py import MPI
    except ImportError as exc:  # launched by mpiexec without mpi4py: say so, do not run N serial copies
        raise TengsimError(f"started by an MPI launcher ({launched_size()} processes) but mpi4py does not "
                           f"import ({exc}); install it: pip install 'tengsim[mpi]'") from None
    comm = MPI.COMM_WORLD
    return comm if comm.Get_size() > 1 else None


def is_root() -> bool:
    """True on rank 0 of an MPI world and in every serial run: the process that writes and reports."""
    comm = world()
    return comm is None or comm.Get_rank() == 0
