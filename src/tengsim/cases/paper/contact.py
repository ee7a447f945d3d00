"""The paper's contact cases: pyramid groups A, B, C (Section 3) and the A(P) tables they give.

Physical scaling (Eq. 7) with E* = 0.59 MPa, W = 54 mJ/m², μ = 0.5 (so ε ≈ 0.37 µm for all groups).
Built on the core: :func:`tengsim.run.simulate.simulate` for the runs, :class:`tengsim.device.AreaTable` for A(P).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tengsim.run.plan import ContactPlan
from tengsim.run.simulate import simulate
from tengsim.device.params import AreaTable
from tengsim.errors import TengsimError
from tengsim.io import jsonable
from tengsim.shapes import Pyramid
from tengsim.continuation import LoadPathSpec, PathSpec
from tengsim.cases.paper.units import PAPER_GROUPS, paper_scaling
from tengsim.solvers.types import SOLVER_TOL

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
    tol: float = SOLVER_TOL
    n_loads: int = 80  # load steps of the load-controlled A(P) (Figs. 5 and 8), at least …
    p_step_Pa: float = 10e3  # … so many that a step is at most this nominal pressure (Fig. 8 starts at 10 kPa)

    @classmethod
    def preset(cls, quick: bool) -> "RunSettings":
        return cls(dx=0.15, d_step=0.25, tol=1e-5, n_loads=40) if quick else cls()


def group_shape(group: str) -> Pyramid:
    sc = paper_scaling(group)
    return Pyramid(sc.N, sc.cell)


def run_group(group: str, settings: RunSettings = RunSettings(), progress=None):
    """Approach–retraction run of one pyramid group; params carry the physical scaling."""
    group = group.upper()
    sc = paper_scaling(group)
    # the Fig. 3 maps the path reaches (a shorter path than the paper's has fewer; PathSpec refuses the rest)
    last = float(PathSpec(settings.d_min, settings.d_max, settings.d_step).targets()[-1])
    spec = PathSpec(settings.d_min, settings.d_max, settings.d_step,
                    maps_at=tuple(d for d in FIG3_D if d <= last + 1e-9))
    res = simulate(ContactPlan(group_shape(group), sc.mu, settings.dx, spec, boundary=settings.boundary,
                               solver=settings.solver, solver_tol=settings.tol, extra={"group": group, **sc.params()},
                               scaling=sc), progress=progress)
    return res


def area_table_from_result(res, group: str) -> AreaTable:
    """A(P) picked from a displacement-controlled approach: keep the states whose force exceeds every
    earlier one (where F(D) falls back, a pressed device jumps ahead), F > 0 only.  Kept for comparison
    with :func:`area_table_load_controlled`, which solves the load-controlled path itself.

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


def run_group_load(group: str, f_max: float, settings: RunSettings = RunSettings(), n_loads: int | None = None,
                   f_min: float = 0.0, progress=None):
    """Load-controlled approach of one pyramid group (:class:`tengsim.continuation.LoadPathSpec`): loads
    ``f_min`` … ``f_max`` (F of Eq. 10 per cell) in equal steps, ``n_loads`` (default settings.n_loads)
    or more so that a step is at most settings.p_step_Pa (at most 400 steps), D searched from
    settings.d_min in steps of settings.d_step (to two steps beyond settings.d_max), no retraction."""
    group = group.upper()
    sc = paper_scaling(group)
    if not f_max > f_min:
        raise TengsimError(f"group {group}: f_max ({f_max:g}) must exceed f_min ({f_min:g})")
    n_loads = int(settings.n_loads if n_loads is None else n_loads)
    n_loads = min(max(n_loads, int(np.ceil(sc.pressure(f_max - f_min) / settings.p_step_Pa - 1e-9))), 400)
    spec = LoadPathSpec(f_min, f_max, (f_max - f_min) / n_loads, d_min=settings.d_min,
                        d_max=settings.d_max + 2 * settings.d_step, d_step=settings.d_step, retract=False)
    return simulate(ContactPlan(group_shape(group), sc.mu, settings.dx, spec, boundary=settings.boundary,
                                solver=settings.solver, solver_tol=settings.tol, extra={"group": group, **sc.params()},
                                scaling=sc), progress=progress)


def area_table_from_load_result(res, group: str) -> AreaTable:
    """A(P) of a load-controlled approach (:func:`run_group_load`): its rows with F > f_step/2 (the
    loads above zero, and at a jump the last stable state and the landing state; the landing, at the same load, is
    placed 1e-9 relative above it in pressure so the table keeps the step)."""
    sc = paper_scaling(group)
    a = res.branch("approach")
    F, L = np.asarray(a["F"], float), np.asarray(a["contact_length"], float)
    keep = np.flatnonzero(F > 0.5 * float(res.params.get("f_step", 0.0)))
    if len(keep) < 2:
        raise TengsimError(f"group {group}: the load-controlled approach has fewer than 2 positive loads")
    p = np.array(sc.pressure(F[keep]), dtype=float)
    for i in range(1, len(p)):
        p[i] = max(p[i], p[i - 1] * (1 + 1e-9))
    frac = np.clip((sc.length(L[keep]) / sc.L) ** 2, 0.0, 1.0)
    return AreaTable(p, frac)


def area_table_load_controlled(group: str, settings: RunSettings = RunSettings(), f_max: float | None = None,
                               n_loads: int | None = None, progress=None, d_result=None) -> AreaTable:
    """A(P) under load control: the load-controlled approach from F = 0 to ``f_max`` (default:
    the largest F the D-controlled approach ``d_result`` reached, run here if not given)."""
    if f_max is None:
        d_result = d_result if d_result is not None else run_group(group, settings)
        f_max = float(np.max(d_result.branch("approach")["F"]))
    return area_table_from_load_result(run_group_load(group, f_max, settings, n_loads, progress=progress), group)


def area_table(group: str = "A", quick: bool = False, progress=None) -> AreaTable:
    """Run the group and return its load-controlled A(P) table (the area model of the Fig. 8 device run)."""
    settings = RunSettings.preset(quick)
    return area_table_load_controlled(group, settings, n_loads=settings.n_loads,
                                      d_result=run_group(group, settings, progress))


def compare_area_tables(load: AreaTable, picked: AreaTable, group: str, dx: float) -> dict:
    """The load-controlled A(P) against the one picked from the D path, at the pressures both cover.

    A monotone A(P) sampled at two sets of states agrees when each load-controlled A/S lies between
    the A/S of the two picked states that bracket its pressure, to one grid pixel of λc
    (δ(A/S) = 2 (λc/L̄) dx/L̄).  Returns the largest excess over that band ('max_excess', 0 when all
    agree), the largest |ΔA/S| against the picked table interpolated linearly ('max_abs_dA_linear', large
    where A/S steps between two picked states), and the number of pressures compared."""
    cell = paper_scaling(group).cell
    pl, al = load.pressure_Pa, load.area_fraction
    pp, ap = picked.pressure_Pa, picked.area_fraction
    m = (pl >= pp[0]) & (pl <= pp[-1])
    excess, lin, n = 0.0, 0.0, int(np.sum(m))
    for p, a in zip(pl[m], al[m]):
        j = int(np.clip(np.searchsorted(pp, p), 1, len(pp) - 1))
        lo, hi = sorted((ap[j - 1], ap[j]))
        pix = 2 * np.sqrt(max(hi, a)) * dx / cell
        excess = max(excess, lo - pix - a, a - hi - pix)
        lin = max(lin, abs(a - float(np.interp(p, pp, ap))))
    return {"n_compared": n, "max_excess": max(excess, 0.0), "max_abs_dA_linear": lin,
            "pixel_dA_max": float(2 * np.sqrt(max(np.max(ap), np.max(al))) * dx / cell)}


def contact_summary(res, group: str) -> dict:
    """Headline numbers of one group: transition D, pull-off F (Eq. 10 units and newtons), jumps."""
    sc = paper_scaling(group)
    full = 2 * sc.N
    tD = res.transition_D(full)
    pull = res.pull_off_force
    return jsonable({
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

