"""One call for a viscoelastic run of a shape: its kernels, solver and law built by name, the history driven
(:func:`simulate_history`), or one period's history repeated to its periodic steady state
(:func:`simulate_periodic`, :mod:`tengsim.visco.periodic`)."""
from __future__ import annotations

from tengsim.kernels import make_kernel
from tengsim.laws import Law
from tengsim.plugins import LAWS  # the registries filled
from tengsim.relaxation import Prony
from tengsim.solvers import SOLVER_TOL, make_solver
from tengsim.visco.drive import TimeDrive
from tengsim.visco.history import History
from tengsim.visco.periodic import MAX_PERIODS, PLAIN, TOL, PeriodicCycles, periodic_cycles


def build_drive(shape, tabor: float, dx: float, material: Prony, boundary: str = "free", law: Law | str | None = None,
                solver="fast", tol: float = SOLVER_TOL, kernel_params: dict | None = None, E_ref: float | None = None,
                jump_h: float = 0.3, dt_min: float | None = None, maps_at=(), grid=None, **drive_kw):
    """(TimeDrive, params): the drive of ``shape`` with Tabor's μ = ``tabor`` at the reference modulus ``E_ref``
    (Pa, default the material's E∞: the static run's μ is the relaxed solid's), and the shape's and grid's
    parameters a result records."""
    grid = grid if grid is not None else shape.grid(dx)
    law_obj = LAWS.get(law or "lj93")() if not isinstance(law, Law) else law
    solver_obj = make_solver(solver, tol=tol) if isinstance(solver, str) else solver
    kp = dict(kernel_params or {})
    drive = TimeDrive(shape.gap(grid), law_obj, lambda kappa: make_kernel(boundary, grid, kappa, **kp),
                      float(tabor) ** 1.5, solver_obj, material, E_ref=E_ref, jump_h=jump_h, dt_min=dt_min,
                      maps_at=maps_at, **drive_kw)
    extra = {**shape.params(), "tabor": tabor, "boundary": boundary, "dx": grid.dx, "nx": grid.nx, "ny": grid.ny}
    return drive, extra


def _with(res, extra):
    return type(res)(res.t, res.columns, res.jump, res.converged, {**extra, **res.params}, res.maps)


def simulate_history(shape, tabor: float, dx: float, material: Prony, history: History, steps, **kw):
    """The viscoelastic run of ``history`` (:class:`tengsim.visco.History`) on ``shape`` (:func:`build_drive`'s
    keywords).  ``steps``: the time-step control.  Returns a :class:`tengsim.visco.TimeResult`."""
    drive, extra = build_drive(shape, tabor, dx, material, **kw)
    return _with(drive.run(history, steps), extra)


def simulate_periodic(shape, tabor: float, dx: float, material: Prony, history: History, steps,
                      cycle_tol: float = TOL, max_periods: int = MAX_PERIODS, plain: int = PLAIN, progress=None,
                      **kw) -> PeriodicCycles:
    """``history`` (one period) repeated on ``shape`` until its cycle repeats to ``cycle_tol`` of its largest A/S
    (:func:`tengsim.visco.periodic.periodic_cycles`; :func:`build_drive`'s keywords)."""
    drive, extra = build_drive(shape, tabor, dx, material, **kw)
    pc = periodic_cycles(drive, history, steps, tol=cycle_tol, max_periods=max_periods, plain=plain,
                         progress=progress)
    return PeriodicCycles(tuple(_with(r, extra) for r in pc.periods), _with(pc.steady, extra), pc.change, pc.tol,
                          pc.converged, pc.evaluations)
