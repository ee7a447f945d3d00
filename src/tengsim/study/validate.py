"""A study checked before anything is computed or written: every distinct point planned (no solving),
the invalid ones named, a study-wide error raised once, the valid ones ordered longest first."""
from __future__ import annotations

from tengsim.errors import ConfigValueError, TengsimError


def estimated_cost(plan) -> float:
    """Relative cost of a planned point: pixels × log2(pixels) (one convolution) × path rows.

    Only orders the submissions (the longest first, so that a short point, not a long one, ends a
    sweep); an estimate that fails gives 1.  The path rows count one per step of each branch."""
    import math

    try:
        g = plan.shape.grid(plan.dx)
        npix = g.nx * g.ny * (1 if plan.boundary == "periodic" else 4)
        spec = plan.path
        if hasattr(spec, "f_step"):
            rows = 2 * (spec.f_max - spec.f_min) / spec.f_step
        else:
            rows = 2 * (spec.d_max - spec.d_min) / spec.d_step
        return float(npix * math.log2(max(npix, 2)) * max(rows, 1.0))
    except Exception:  # noqa: BLE001 - an estimate only
        return 1.0


def _solver_error(name: str, seen: dict) -> str | None:
    """The one-line error of building solver ``name`` on this machine (a 'gpu' where JAX finds none), or None;
    each name tried once (``seen``)."""
    if name not in seen:
        from tengsim.solvers import make_solver

        try:
            make_solver(name)
            seen[name] = None
        except TengsimError as exc:
            seen[name] = str(exc)
    return seen[name]


def validate(study, local: bool = False) -> tuple[dict, dict]:
    """Plan every distinct point (no solving).  Returns ({id: contact table} of the valid points,
    {id: message} of the invalid ones), the valid ones longest first (:func:`estimated_cost`).
    An error that every point shares is an error in the study file: raised as one TengsimError
    before anything is written.  ``local`` (the points run on this machine): a point whose solver this
    machine cannot build (a GPU it lacks) is invalid too, so a sweep of such points alone is refused."""
    from tengsim.run.plan import plan_contact
    from tengsim.study.observe import device_values

    valid, invalid, first, cost, solvers = {}, {}, None, {}, {}
    for p in study.points:
        device_values(p.tables["device"])  # a bad device value is a study error
        pid = p.id
        if pid in valid or pid in invalid:
            continue
        try:
            plan = plan_contact(dict(p.contact))
        except ConfigValueError as exc:  # a malformed value in the file: the whole study is refused
            where = ", ".join(f"{k} = {v!r}" for k, v in p.axes.items())
            raise TengsimError(f"{study.source or 'study'}: {exc}" + (f" (at {where})" if where else "")) from None
        except TengsimError as exc:
            invalid[pid] = str(exc)
            if first is None:
                first = (p, str(exc))
            continue
        bad = _solver_error(plan.solver, solvers) if local else None
        if bad is not None:
            invalid[pid] = bad
            if first is None:
                first = (p, bad)
            continue
        valid[pid] = p.contact
        cost[pid] = estimated_cost(plan)
    if not valid:
        if first is None:
            raise TengsimError(f"{study.source or 'study'}: no points")
        p, msg = first
        where = ", ".join(f"{k} = {v!r}" for k, v in p.axes.items())
        raise TengsimError(f"{study.source or 'study'}: {msg}" + (f" (at {where})" if where and len(invalid) == 1
                                                                  else ""))
    order = sorted(valid, key=lambda pid: -cost[pid])  # stable: equal estimates keep the study's order
    return {pid: valid[pid] for pid in order}, invalid
