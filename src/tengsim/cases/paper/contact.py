"""The paper's contact cases: pyramid groups A, B, C (Section 3) and the A(P) tables they give.

Physical scaling (Eq. 7) with E* = 0.59 MPa, W = 54 mJ/m², μ = 0.5 (so ε ≈ 0.37 µm for all groups).
Built on the core: :func:`tengsim.contact.simulate` for the runs, :class:`tengsim.device.AreaTable` for A(P).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tengsim.cases._json import json_safe
from tengsim.contact import simulate
from tengsim.device.params import AreaTable
from tengsim.errors import TengsimError
from tengsim.geometry import Pyramid
from tengsim.path import PathSpec
from tengsim.units import PAPER_GROUPS, paper_scaling

# The paper's reported partial-to-full contact transitions (Fig. 4a), for comparison only.
PAPER_TRANSITION_D = {"A": 1.75, "B": 5.20, "C": 10.95}
# Fig. 3 pressure maps (approach).
FIG3_D = (1.0, 3.0, 6.0, 14.0)


@dataclass(frozen=True)
class RunSettings:
    """Grid and path of a paper run; ``quick`` trades accuracy for time."""

    dx: float = 0.1
    d_step: float = 0.1
    d_min: float = -1.0
    d_max: float = 14.0
    boundary: str = "free"
    solver: str = "fast"
    tol: float = 1e-6

    @classmethod
    def preset(cls, quick: bool) -> "RunSettings":
        return cls(dx=0.15, d_step=0.25, tol=1e-5) if quick else cls()


def group_shape(group: str) -> Pyramid:
    sc = paper_scaling(group)
    return Pyramid(sc.N, sc.cell)


def run_group(group: str, settings: RunSettings = RunSettings(), progress=None):
    """Approach–retraction run of one pyramid group; params carry the physical scaling."""
    group = group.upper()
    sc = paper_scaling(group)
    spec = PathSpec(settings.d_min, settings.d_max, settings.d_step, maps_at=FIG3_D)
    res = simulate(group_shape(group), sc.mu, settings.dx, spec, boundary=settings.boundary,
                   solver=settings.solver, tol=settings.tol, progress=progress,
                   extra_params={"group": group, **sc.params()}, scaling=sc)
    return res


def area_table_from_result(res, group: str) -> AreaTable:
    """A(P) under load control from a displacement-controlled approach: keep the states whose force
    exceeds every earlier one (where F(D) falls back, a pressed device jumps ahead), F > 0 only.

    A/S = λc²/L² against the pressure f/L² (Pa) on the array (Eq. 12's area; the device's area model).
    """
    sc = paper_scaling(group)
    a = res.branch("approach")
    F, L = a["F"], a["contact_length"]
    keep, best = [], 0.0
    for i, f in enumerate(F):
        if f > best:
            keep.append(i)
            best = f
    keep = np.array(keep, dtype=int)
    if len(keep) < 2:
        raise TengsimError(f"group {group}: the approach never reached a positive load; raise d_max")
    p = sc.pressure(F[keep])
    frac = np.clip((sc.length(L[keep]) / sc.L) ** 2, 0.0, 1.0)
    return AreaTable(p, frac)


def area_table(group: str = "A", quick: bool = False, progress=None) -> AreaTable:
    """Run the group and return its A(P) table (the area model of the Fig. 8 device run)."""
    return area_table_from_result(run_group(group, RunSettings.preset(quick), progress), group)


def contact_summary(res, group: str) -> dict:
    """Headline numbers of one group: transition D, pull-off F (Eq. 10 units and newtons), jumps."""
    sc = paper_scaling(group)
    full = 2 * sc.N
    tD = res.transition_D(full)
    pull = res.pull_off_force
    return json_safe({
        "N": sc.N,
        "cell": sc.cell,
        "transition_D": tD,
        "transition_D_paper": PAPER_TRANSITION_D[group],
        "pull_off_F": pull,
        "pull_off_N_per_cell": sc.force(pull),
        "pull_off_Pa": sc.pressure(pull),
        "final_contact_length": float(res.branch("approach")["contact_length"][-1]),
        "full_contact_length_2N": full,
        "jumps": [dict(kind=j.kind, **j.__dict__) for j in res.jumps],
        "all_converged": res.all_converged,
        "median_conv_per_equilibrium": float(np.median(res.table["n_conv"])),
        "seconds": res.seconds,
    })


GROUPS = tuple(PAPER_GROUPS)

