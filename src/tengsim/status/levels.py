"""The status of an equilibrium and of a run, and how statuses aggregate: the worst one counts.

A status is a :class:`Status` (a ``str`` enum: it is written to CSV, NetCDF and JSON as its value and
compares equal to it, ``Status.OK == "ok"``).  Worst last in :data:`SEVERITY`: a row's status is the
worst of its problems, a run's the worst of its rows (:func:`overall`).
"""
from __future__ import annotations

from enum import StrEnum

import numpy as np

from tengsim.errors import TengsimError


class Status(StrEnum):
    """The status of one equilibrium or one run."""

    OK = "ok"
    #: the process zone is narrower than the grid resolves, pixels snap, or a walled face is too coarse
    UNDER_RESOLVED = "under_resolved"
    #: some gap fell below the law's g_safe (the state is in the law's safe extension)
    OUT_OF_LAW_RANGE = "out_of_law_range"
    #: the solver stopped before the residual of Eq. (9) reached tol
    NOT_CONVERGED = "not_converged"

    @property
    def label(self) -> str:
        """The status in words, as a warning line names it."""
        return _LABEL[self]


OK = Status.OK
UNDER_RESOLVED = Status.UNDER_RESOLVED
OUT_OF_LAW_RANGE = Status.OUT_OF_LAW_RANGE
NOT_CONVERGED = Status.NOT_CONVERGED
#: worst last: a row's status is the worst of its problems, a run's the worst of its rows
SEVERITY = tuple(Status)

_LABEL = {OK: "ok", NOT_CONVERGED: "not converged", OUT_OF_LAW_RANGE: "out of the law's range",
          UNDER_RESOLVED: "under-resolved"}


def overall(statuses) -> Status:
    """The worst status of the rows (``Status.OK`` for an empty run)."""
    s = set(np.asarray(statuses).astype(str).tolist())
    return Status(max(s, key=SEVERITY.index)) if s else OK


class ResultStatusError(TengsimError):
    """A run finished with a status other than 'ok' and ``throw=True`` was asked; ``.result`` has it all."""

    def __init__(self, message: str, result=None):
        super().__init__(message)
        self.result = result
