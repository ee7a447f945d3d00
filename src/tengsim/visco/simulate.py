"""One call for a viscoelastic run of a shape: its kernels, solver and law built by name, the history driven."""
from __future__ import annotations

from tengsim import plugins  # noqa: F401  (the registries filled)
from tengsim.kernels import make_kernel
from tengsim.laws import Law
from tengsim.registry import LAWS
from tengsim.relaxation import Prony
from tengsim.solvers import make_solver
from tengsim.visco.drive import TimeDrive
from tengsim.visco.history import History


def simulate_history(shape, tabor: float, dx: float, material: Prony, history: History, steps,
                     boundary: str = "free", law: Law | str | None = None, solver="fast", tol: float = 1e-6,
                     kernel_params: dict | None = None, E_ref: float | None = None, jump_h: float = 0.3,
                     dt_min: float | None = None, maps_at=(), grid=None, **drive_kw):
    """The viscoelastic run of ``history`` (:class:`tengsim.visco.History`) on ``shape`` with Tabor's μ =
    ``tabor`` at the reference modulus ``E_ref`` (Pa, default the material's E∞: the static run's μ is the
    relaxed solid's).  ``steps``: the time-step control.  Returns a :class:`tengsim.visco.TimeResult`."""
    grid = grid if grid is not None else shape.grid(dx)
    law_obj = LAWS.get(law or "lj93")() if not isinstance(law, Law) else law
    solver_obj = make_solver(solver, tol=tol) if isinstance(solver, str) else solver
    kp = dict(kernel_params or {})
    drive = TimeDrive(shape.gap(grid), law_obj, lambda kappa: make_kernel(boundary, grid, kappa, **kp),
                      float(tabor) ** 1.5, solver_obj, material, E_ref=E_ref, jump_h=jump_h, dt_min=dt_min,
                      maps_at=maps_at, **drive_kw)
    res = drive.run(history, steps)
    extra = {**shape.params(), "tabor": tabor, "boundary": boundary, "dx": grid.dx, "nx": grid.nx, "ny": grid.ny}
    return type(res)(res.t, res.columns, res.jump, res.converged, {**extra, **res.params}, res.maps)
