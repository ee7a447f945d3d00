"""The refinement plan (issue 49 item 1): built once by plan_refinement, frozen and checked at construction;
preflight, estimate and refine take it; a design is preflighted once."""
import dataclasses

import pytest

from tengsim.design import plan_design
from tengsim.errors import TengsimError
from tengsim.run import refine as _refine

SMALL = {"shape": "pyramid", "pitch": "1um", "base": "0.5um", "height": "0.2um", "E_star": "5MPa", "W": "20mJ/m2",
         "eps": "50nm", "p_max": "50kPa", "p_step": "5kPa", "boundary": "free"}


def test_plan_holds_the_refinements_numbers_and_is_frozen():
    plan = plan_design(SMALL)
    r = _refine.plan_refinement(plan.contact_plan, plan)
    assert r.dx == _refine.first_dx(plan.contact_plan, plan) and r.grids[0] == plan.contact_plan.shape.grid(r.dx)
    assert r.p_max == plan.pressures[-1] and r.rel_tol == plan.rel_tol and r.solver_tol == plan.contact_plan.solver_tol
    assert r.finest.nx >= r.grids[0].nx and r.memory_bytes > 0 and r.shortest_s > 0
    with pytest.raises(dataclasses.FrozenInstanceError):
        r.rel_tol = 0.5
    with pytest.raises(TengsimError, match="increasing"):
        dataclasses.replace(r, pressures=(2e3, 1e3))
    with pytest.raises(TengsimError, match="dx"):
        dataclasses.replace(r, dx=-1.0)
    _refine.preflight(r)  # within every bound
    with pytest.raises(TengsimError, match="max_pixels = 4"):
        _refine.preflight(dataclasses.replace(r, max_pixels=4))
    with pytest.raises(TengsimError, match="over the budget"):
        _refine.preflight(dataclasses.replace(r, budget_s=1e-9))


def test_estimate_is_the_budgets_for_the_plans_grids():
    from tengsim.run import budget

    plan = plan_design(SMALL)
    r = _refine.plan_refinement(plan.contact_plan, plan)
    est = _refine.estimate(r, 25.0)
    want = budget.estimate(plan, r.cplan, r.grids, 25.0, budget.run_cost(r.cplan, 25.0), r.memory_bytes)
    assert est.grids == want.grids and est.seconds == want.seconds and est.memory_bytes == r.memory_bytes


def test_design_checked_once_given_its_checked_plan(monkeypatch):
    """run_design given the plan design.run.preflight checked does not check it again (the CLI's path)."""
    from tengsim.design import run as _run

    plan = plan_design(SMALL)
    checked = _run.preflight(plan)
    calls = []
    monkeypatch.setattr(_refine, "preflight", lambda p: calls.append(p))
    monkeypatch.setattr(_refine, "refine", lambda p, hooks: (_ for _ in ()).throw(RuntimeError(p)))
    with pytest.raises(RuntimeError) as given:
        _run.run_design(plan, refinement=checked)
    assert given.value.args[0] is checked and calls == []
    assert checked.observe is not None and checked.maps_at == _run.map_pressures(plan)  # what the design judges
    with pytest.raises(RuntimeError) as planned:
        _run.run_design(plan)
    assert calls == [planned.value.args[0]] and planned.value.args[0].dx == checked.dx
