"""The refinement's tolerance: its default, its bound and its one check, for a contact run's ``resolve_tol`` and a
design's ``tol`` alike (both are the relative change of the observables between the last two grids)."""
from __future__ import annotations

from tengsim.errors import ConfigValueError

DEFAULT_TOL = 0.01
"""The relative tolerance of a refinement (and of a design) that gives none: 1 %."""
MAX_TOL = 0.5
"""A tolerance is below this: a change of half a value between two grids is no convergence."""


def check_tol(v, name: str = "resolve_tol") -> float:
    """``v`` as a float if a number > 0 and < :data:`MAX_TOL` (a ConfigValueError naming ``name`` otherwise)."""
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not 0 < float(v) < MAX_TOL:
        raise ConfigValueError(f"{name} must be > 0 and < {MAX_TOL:g}, got {v!r}")
    return float(v)
