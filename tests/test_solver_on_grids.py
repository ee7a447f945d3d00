"""Issue 49 item 2: the solver and the memory are chosen on the grids solved, the plan stays pure.

'auto' stays 'auto' in a ContactPlan; each grid a run solves chooses on its own points (a GPU above its
break-even where JAX sees one), and the memory is checked on a grid that is solved, not on the plan's default
grid of a refinement that starts elsewhere."""
import dataclasses

import pytest

from tengsim.run.plan import chosen_solver, plan_contact
from tengsim.run import choice as run_choice
from tengsim.solvers import choice

TINY = {"shape": "pyramid", "N": 0.946, "cell": 3.78, "tabor": 0.5, "dx": 0.1, "d_max": 1.0, "d_step": 0.2}


def test_a_plan_keeps_auto_and_each_grid_chooses(monkeypatch):
    plan = plan_contact(TINY)
    assert plan.solver == "auto"
    assert chosen_solver(plan) == ("fast", run_choice.choose("auto", points=plan.grid.nx * plan.grid.ny)[1])
    monkeypatch.setattr(choice, "gpu_visible", lambda: True)
    coarse, fine = plan.grid, dataclasses.replace(plan, dx=0.01, grid=None).grid
    assert chosen_solver(plan, coarse)[0] == "fast" and chosen_solver(plan, fine)[0] == "gpu"
    assert chosen_solver(dataclasses.replace(plan, solver="fast"), fine) == ("fast", "")  # asked by name: kept


def test_a_refinement_says_both_choices(monkeypatch):
    from tengsim.run.refine import said_solver

    plan = plan_contact(TINY)
    fine = dataclasses.replace(plan, dx=0.01, grid=None).grid
    lines = []
    said_solver(plan, plan.grid, fine, lines.append)  # no GPU here: one line, the CPU's
    assert len(lines) == 1 and "no GPU" in lines[0]
    monkeypatch.setattr(choice, "gpu_visible", lambda: True)
    lines.clear()
    said_solver(plan, plan.grid, fine, lines.append)
    assert len(lines) == 1 and "break-even" in lines[0] and f"from {fine.nx}×{fine.ny} on: solver: gpu" in lines[0]
    lines.clear()
    said_solver(dataclasses.replace(plan, solver="fast"), plan.grid, fine, lines.append)
    assert lines == []


def test_the_memory_is_checked_on_the_grid_solved(monkeypatch):
    from tengsim.run import memory

    checked = []
    monkeypatch.setattr(memory, "check_memory", lambda nx, ny, *a, **k: checked.append((nx, ny)))
    plan = plan_contact(TINY)  # one grid: the plan's grid is the one solved, checked now
    assert checked == [(plan.grid.nx, plan.grid.ny)]
    checked.clear()
    plan_contact({**TINY, "resolve": "auto"})  # a refinement: its own grids are checked as it reaches them
    assert checked == []


def test_gpu_by_name_without_one_is_refused_at_the_edge(monkeypatch):
    from tengsim.errors import SolverUnavailable

    monkeypatch.setattr(choice, "gpu_visible", lambda: False)
    with pytest.raises(SolverUnavailable, match="JAX sees no GPU"):
        plan_contact({**TINY, "solver": "gpu"})
