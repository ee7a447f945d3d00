"""One grid's contact run: shape, law, kernel, solver and path of a plan composed and walked (:func:`simulate`)."""
from __future__ import annotations

from dataclasses import is_dataclass, replace

from tengsim import status
from tengsim._version import __version__
from tengsim.run.plan import ContactPlan, as_plan, chosen_solver
from tengsim.errors import TengsimError
from tengsim.grid import Mirror
from tengsim.kernels import make_kernel
from tengsim.kernels.distributed import SlabPeriodicKernel, check_split
from tengsim.kernels.mirror import MirrorKernel, choose_symmetry
from tengsim.continuation import LoadPathSpec, run_load_path, run_path
from tengsim.run.memory import MAP_WORK, check_memory
from tengsim.solvers import make_solver
from tengsim.solvers.mirror import MirrorSolver
from tengsim.solvers.distributed import SlabSolver
from tengsim import parallel

MONITOR_MIN_POINTS = 1024**2  # grids from this size on report progress inside each solve
#: full-grid arrays a block run still holds beside the block's workspace (U0, g0, the unfolded H and P the
#: path keeps, its zero start; measured ~10, docs/benchmarks.md "Symmetry-reduced kernels"), for the memory check
MIRROR_FULL_ARRAYS = 12


def simulate(plan, progress=None, sink=None, throw: bool = False):
    """The approach–retraction run of ``plan`` on one grid (paper Eq. 9): a :class:`tengsim.run.plan.ContactPlan`
    (build one from API objects: ``ContactPlan(shape, tabor, dx, path, boundary=..., solver=..., law=...)``) or a
    [contact] table, planned here once (:func:`tengsim.run.plan.plan_contact`; the table kept in
    ``params['config']``).  The run layer's first entry point; a refinement is :func:`tengsim.run.resolve.resolve`,
    a refinement to a pressure :func:`tengsim.run.refine.refine` (docs/extending.md, "The run layer").

    ``progress`` (a :class:`tengsim.progress.Progress`-like object or None) is called per path row; ``sink`` (a
    callable or None) receives each equilibrium as it is recorded, ``sink(row, maps)``
    (:class:`tengsim.continuation.Recorder`); if it has a ``begin(params)`` method, that is called first, before
    any solve, with the run's parameters known then (all but the recorded pixel snap number and the status):
    :class:`tengsim.results.RowStream` writes them as its header, or refuses a file to resume that another run
    wrote.  Returns a ContactResult whose ``status`` (and per-row ``status`` column) says ok / not_converged /
    out_of_law_range / under_resolved (:mod:`tengsim.status`); with ``throw=True`` a status other than 'ok' raises
    :class:`tengsim.status.ResultStatusError`, which carries the result.  The grid's memory is checked once, before
    anything is built.  A plan that asks for a refinement (``plan.resolve`` set) is refused in one line: a
    refinement gives each of its grids to this function with ``resolve=None``.

    ``plan.symmetry``: 'auto' solves on the irreducible quarter (or half) of the cell when the shape declares
    mirrors its gap has on the grid, the kernel is 'free' or 'periodic' and the solver 'fast' or 'vsr'
    (:func:`choose_symmetry`; the same answer, to round-off); 'off' the full grid.  ``params['symmetry']``
    says what was used ('x+y', 'x', 'y', 'off' or 'none (why)'), ``block_nx``, ``block_ny`` the block.
    """
    return _one_grid(as_plan(plan), progress, sink, throw)


def _one_grid(plan: ContactPlan, progress=None, sink=None, throw: bool = False):
    """:func:`simulate` of a :class:`tengsim.run.plan.ContactPlan` (never a table: the run layer's own callers hold
    planned values, so nothing is parsed again under a refinement)."""
    if plan.resolve is not None:  # refinement is the layer above's: never run one grid silently instead
        raise TengsimError("this plan asks for a refinement (resolve = 'auto'): run it with tengsim.resolve, "
                           "not tengsim.simulate (one grid)")
    shape, tabor, path, grid, boundary, law = plan.shape, plan.tabor, plan.path, plan.grid, plan.boundary, plan.law
    solver, symmetry = chosen_solver(plan)[0], plan.symmetry  # 'auto' chosen on this grid (the caller says why)
    solver_obj = make_solver(solver, tol=plan.solver_tol) if isinstance(solver, str) else solver
    if isinstance(solver_obj, MirrorSolver):
        solver_obj = solver_obj.inner
    U0 = shape.gap(grid)
    comm = parallel.world()  # mpiexec -n N: the periodic kernel split in slabs over the N processes
    if comm is not None:
        check_split(comm, boundary, solver_obj, grid)
        symmetry = "off"
    axes, sym_label = choose_symmetry(shape, U0, grid, boundary, solver_obj, symmetry)
    if comm is not None:
        sym_label = "off (MPI run: the slabs hold the full grid)"
    mirror = Mirror(grid, axes) if axes else None
    bnx, bny = mirror.reduced_shape if mirror else (grid.nx, grid.ny)
    if (hasattr(progress, "monitor") and grid.nx * grid.ny >= MONITOR_MIN_POINTS and is_dataclass(solver_obj)
            and getattr(solver_obj, "monitor", 0) is None):  # long solves report as they go
        solver_obj = replace(solver_obj, monitor=progress.monitor(), monitor_every=10)
    if comm is not None:  # the solver on this rank's slab, or on the mirror's block (small objects: nothing allocated)
        solver_obj = SlabSolver(solver_obj)
    elif mirror is not None:
        solver_obj = MirrorSolver(solver_obj)
    # the run's pieces chosen, the memory is checked right before the first large allocation it guards: the kernel
    full_arrays = MAP_WORK * 2 * len(path.maps_at) + (MIRROR_FULL_ARRAYS if mirror else 0)  # one clear error,
    check_memory(bnx, bny, boundary, getattr(solver_obj, "name", ""), getattr(solver_obj, "memory", 10),
                 maps=-(-full_arrays * grid.nx * grid.ny // (MAP_WORK * bnx * bny)))  # needed vs available
    if comm is not None:
        kernel = SlabPeriodicKernel(grid, plan.coupling, comm, **plan.kernel_params)
    elif mirror is None:
        kernel = make_kernel(boundary, grid, plan.coupling, **plan.kernel_params)
    else:
        kernel = MirrorKernel(boundary, grid, plan.coupling, mirror, **plan.kernel_params)
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
        "symmetry": sym_label,
        **({"mpi_processes": comm.Get_size()} if comm is not None else {}),
        **({"block_nx": bnx, "block_ny": bny} if mirror is not None else {}),
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
        **plan.extra,
    }
    if plan.scaling is not None:
        for k, v in plan.scaling.params().items():
            params.setdefault(k, v)
    if sink is not None and hasattr(sink, "begin"):
        sink.begin(dict(params))
    res = walk(U0, law, kernel, solver_obj, path, progress=progress, observers=plan.observers, sink=sink)
    res = replace(res, params={**params, **res.params})  # and what the path recorded (the pixel snap number)
    if plan.scaling is not None:
        res = res.with_physical(plan.scaling)
    res = status.attach(res, law, kernel.coupling)  # per-row 'status' column, params['status'] (tengsim.status)
    if (getattr(kernel, "film", False) and getattr(kernel, "pinned_mean", False)
            and not res.table["in_law_range"].all()):
        res = replace(res, params={**res.params, "warning": res.params.get("warning", "") + (
            "; the film is incompressible (poisson = 0.5), so its mean mode has no compliance either: give "
            "poisson < 0.5 (PDMS ≈ 0.49) and small D steps, or drive it by load")})
    if plan.config:
        res = replace(res, params={**res.params, "config": dict(plan.config)})
    if throw:
        res.raise_for_status()
    return res
