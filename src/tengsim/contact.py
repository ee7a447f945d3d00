"""One entry point composing shape, law, kernel, solver and path into a contact run."""
from __future__ import annotations

from dataclasses import is_dataclass, replace

from tengsim import status
from tengsim._version import __version__
from tengsim.config import plan_contact
from tengsim.errors import TengsimError, positive
from tengsim.shapes import Pyramid, Shape
from tengsim.laws import LJ93, Law, make_law
from tengsim.kernels import make_kernel
from tengsim.loadpath import LoadPathSpec, run_load_path
from tengsim.path import PathSpec, run_path
from tengsim.plugins import KERNELS
from tengsim.resources import check_memory
from tengsim.solvers import make_solver

MONITOR_MIN_POINTS = 1024**2  # grids from this size on report progress inside each solve


def simulate(shape: Shape, tabor: float, dx: float, path: PathSpec, boundary: str = "free",
             solver="fast", tol: float = 1e-6, law: Law | str | None = None, progress=None,
             grid=None, extra_params: dict | None = None, observers=(), scaling=None,
             kernel_params: dict | None = None, throw: bool = False, check_memory_first: bool = True,
             sink=None):
    """Approach–retraction run of ``shape`` against a rigid flat plate (paper Eq. 9).

    ``tabor`` is μ (the elastic coupling is μ^{3/2}); ``dx`` the grid spacing in X units;
    ``boundary`` a registered kernel name ('free', 'periodic'); ``solver`` a registered name
    ('fast', 'vsr') or a solver object; ``law`` a law object or registered name (default the
    paper's LJ93).  ``kernel_params`` go to the kernel's factory (e.g. a film: ``thickness`` in X
    units, ``substrate``, ``poisson``; see :mod:`tengsim.kernels`).  ``observers`` (registered names
    or objects) add columns to the table; with a ``scaling`` (:class:`tengsim.units.Scaling`) the
    table also gets F_N, pressure_Pa and contact_length_m and the units metadata of that scaling.
    Returns a ContactResult whose ``status`` (and per-row ``status`` column) says ok /
    not_converged / out_of_law_range / under_resolved (:mod:`tengsim.status`); with ``throw=True``
    a status other than 'ok' raises :class:`tengsim.status.ResultStatusError`, which carries the
    result.  The grid's memory is checked once, before anything is built (``check_memory_first=False``:
    the caller has checked it, as :func:`run_contact` does through :func:`tengsim.config.plan_contact`).

    ``sink`` (a callable or None) receives each equilibrium as it is recorded, ``sink(row, maps)``
    (:class:`tengsim.continuation.Recorder`); if it has a ``begin(params)`` method, that is called first,
    before any solve, with the run's parameters known then (all but the recorded pixel snap number and
    the status): :class:`tengsim.results.RowStream` writes them as its header, or refuses a file to
    resume that another run wrote.
    """
    tabor = positive("tabor", tabor)
    if scaling is not None and abs(scaling.mu - tabor) > 1e-9 * tabor:
        raise TengsimError(f"tabor = {tabor:g} does not match the scaling's μ = {scaling.mu:g}")
    law = make_law(law) if isinstance(law, str) else (law or LJ93())
    boundary = KERNELS.canonical(boundary)
    grid = grid or shape.grid(dx)
    solver_obj = make_solver(solver, tol=tol) if isinstance(solver, str) else solver
    if check_memory_first:  # before any large array: one clear error, needed vs available
        check_memory(grid.nx, grid.ny, boundary, getattr(solver_obj, "name", ""), getattr(solver_obj, "memory", 10),
                     maps=2 * len(path.maps_at))
    if (hasattr(progress, "monitor") and grid.nx * grid.ny >= MONITOR_MIN_POINTS and is_dataclass(solver_obj)
            and getattr(solver_obj, "monitor", 0) is None):  # long solves report as they go
        solver_obj = replace(solver_obj, monitor=progress.monitor(), monitor_every=10)
    kernel = make_kernel(boundary, grid, tabor**1.5, **(kernel_params or {}))
    walk = run_load_path if isinstance(path, LoadPathSpec) else run_path  # load or rigid-approach control
    params = {
        "tengsim_version": __version__,
        **shape.params(),
        "lateral_unit": getattr(shape, "lateral_unit", "ℓ"),
        "tabor": tabor,
        "boundary": boundary,
        **{k: v for k, v in (getattr(kernel, "params", dict)() or {}).items() if k not in ("boundary", "coupling")},
        "solver": solver_obj.name,
        "tol": solver_obj.tol,
        "dx": grid.dx,
        "nx": grid.nx,
        "ny": grid.ny,
        **law.params(),
        "d_min": path.d_min,
        "d_max": path.d_max,
        "d_step": path.d_step,
        "refine_levels": path.refine_levels,
        "jump_h": path.jump_h,
        **path.extra_params(),  # adaptive steps or load control (none for a fixed-step D path)
        **(extra_params or {}),
    }
    if scaling is not None:
        for k, v in scaling.params().items():
            params.setdefault(k, v)
    if sink is not None and hasattr(sink, "begin"):
        sink.begin(dict(params))
    res = walk(shape.gap(grid), law, kernel, solver_obj, path, progress=progress, observers=observers, sink=sink)
    recorded = res.params  # what the path recorded (the pixel snap number)
    res.params = {**params, **recorded}
    if scaling is not None:
        res.add_physical(scaling)
    status.attach(res, law, kernel.coupling)  # per-row 'status' column, params['status'] (tengsim.status)
    if (getattr(kernel, "film", False) and getattr(kernel, "pinned_mean", False)
            and not res.table["in_law_range"].all()):
        res.params["warning"] = res.params.get("warning", "") + (
            "; the film is incompressible (poisson = 0.5), so its mean mode has no compliance either: give "
            "poisson < 0.5 (PDMS ≈ 0.49) and small D steps, or drive it by load")
    if throw:
        res.raise_for_status()
    return res


def simulate_pyramid(N: float, cell: float, tabor: float = 0.5, dx: float = 0.05,
                     d_min: float = -1.0, d_max: float = 4.0, d_step: float = 0.05,
                     boundary: str = "free", solver="fast", tol: float = 1e-6,
                     maps_at=(), progress=None, **path_kw):
    """The paper's pyramid unit cell (Eq. 11) with N = n/(2ε) and L̄ = ``cell``."""
    shape = Pyramid(N, cell)
    spec = PathSpec(d_min, d_max, d_step, maps_at=tuple(maps_at), **path_kw)
    return simulate(shape, tabor, dx, spec, boundary=boundary, solver=solver, tol=tol, progress=progress)


def run_contact(cfg: dict, progress=None, sink=None):
    """Plan and run a [contact] table; returns a ContactResult with the config in params.  ``sink``: as
    for :func:`simulate` (the config is not among the parameters it is given: a CLI run and a TOML run
    of the same settings spell it differently, and resume only cares about what is solved)."""
    plan = plan_contact(cfg)
    res = simulate(plan.shape, plan.tabor, plan.dx, plan.path, boundary=plan.boundary,
                   solver=plan.solver, tol=plan.tol, law=plan.law, progress=progress,
                   extra_params=plan.extra, observers=plan.observers, scaling=plan.scaling,
                   kernel_params=plan.kernel_params, check_memory_first=False,  # plan_contact checked it
                   sink=sink)
    res.params["config"] = {k: v for k, v in cfg.items() if k not in ("out", "plot")}
    return res
