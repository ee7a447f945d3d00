"""Plan once (issue 28 item 1): a [contact] table becomes one frozen, validated ContactPlan, read once per run;
everything downstream takes that plan (the refinement engine too, each grid a simulate run of it);
each check lives in one place; the shape answers its full-contact length."""
import dataclasses
import math

import pytest

from tengsim.cli.main import main
from tengsim.errors import TengsimError
from tengsim.registry import SHAPES
from tengsim.run import plan as plan_mod
from tengsim.run.plan import ContactPlan, ResolveSettings, plan_contact

PYR = ["contact", "pyramid", "--N", "0.946", "--cell", "3.78", "--tabor", "0.5", "--d-min", "-1", "--d-max", "0",
       "--d-step", "0.5", "--dx", "0.8", "--quiet"]
CFG = {"shape": "pyramid", "N": 0.946, "cell": 3.78, "tabor": 0.5, "d_min": -1.0, "d_max": 0.0, "d_step": 0.5,
       "dx": 0.5}


@pytest.fixture
def counted(monkeypatch):
    """plan_contact with a counter of its calls (every caller reaches it through the module)."""
    calls = []
    real = plan_mod.plan_contact

    def counting(cfg):
        calls.append(dict(cfg))
        return real(cfg)

    monkeypatch.setattr(plan_mod, "plan_contact", counting)
    return calls


@pytest.mark.parametrize("extra", [[], ["--resolve", "auto", "--resolve-tol", "0.2", "--max-pixels", str(9 * 9)]],
                         ids=["one grid", "resolve auto"])
def test_tengsim_contact_plans_once(tmp_path, counted, extra):
    out = tmp_path / "r.csv"
    assert main([*PYR, *extra, "--out", str(out)]) == 0
    assert out.is_file()
    assert len(counted) == 1, counted


def test_tengsim_run_of_a_toml_contact_table_plans_once(tmp_path, counted):
    out = tmp_path / "r.csv"
    cfg = tmp_path / "run.toml"
    cfg.write_text("[contact]\n" + "".join(f"{k} = {v!r}\n" for k, v in CFG.items()).replace("'", '"')
                   + f'out = "{out}"\n')
    assert main(["run", str(cfg), "--quiet"]) == 0
    assert out.is_file() and len(counted) == 1, counted


def test_the_api_helper_plans_a_table_once_and_takes_a_plan_as_is(counted):
    from tengsim.run.simulate import simulate as run_contact

    res = run_contact(dict(CFG))
    assert len(counted) == 1 and res.params["config"] == CFG
    p = plan_contact(dict(CFG))
    counted.clear()
    again = run_contact(p)
    assert counted == [] and list(again.table["F"]) == list(res.table["F"])


def test_the_plan_is_frozen_and_its_resolve_settings_typed():
    p = plan_contact({**CFG, "resolve": "auto", "resolve_tol": 0.05, "max_pixels": 400})
    assert p.resolve == ResolveSettings(rel_tol=0.05, max_pixels=400, dx=0.5)
    assert plan_contact(dict(CFG)).resolve is None
    with pytest.raises(dataclasses.FrozenInstanceError):
        p.tabor = 1.0
    with pytest.raises(dataclasses.FrozenInstanceError):
        p.resolve.rel_tol = 0.5
    assert p.grid == p.shape.grid(0.5) and p.dx == 0.5  # the grid is built once, in the plan
    assert p.coupling == pytest.approx(0.5**1.5)
    assert "out" not in plan_contact({**CFG, "out": "x.csv"}).config


@pytest.mark.parametrize("kw, words", [
    ({"rel_tol": 0.0}, "resolve_tol must be > 0 and < 0.5, got 0.0"),
    ({"rel_tol": True}, "resolve_tol must be > 0 and < 0.5, got True"),
    ({"max_pixels": 8}, "max_pixels must be >= 9"),
    ({"max_pixels": 10.5}, "max_pixels must be >= 9"),
    ({"dx": -1.0}, "dx must be finite and > 0, got -1.0"),
])
def test_resolve_settings_check_themselves(kw, words):
    with pytest.raises(TengsimError, match=words):
        ResolveSettings(**kw)


def test_a_plan_refuses_a_bad_tabor_and_a_scaling_of_another_mu():
    p = plan_contact(dict(CFG))
    for bad in (0.0, -1.0):
        with pytest.raises(TengsimError, match="tabor must be finite and > 0"):
            dataclasses.replace(p, tabor=bad)
    phys = plan_contact({"shape": "pyramid", "pitch": "10um", "base": "5um", "height": "1um", "E_star": "1MPa",
                         "W": 0.05, "tabor": 2.0, "dx": 0.2})
    with pytest.raises(TengsimError, match="does not match the scaling"):
        dataclasses.replace(phys, tabor=1.0)


REQUIRED = {"pyramid": {"N": 0.946, "cell": 3.78}, "array": {"pattern": "cube", "K": 2}}
"""Values for the shapes whose fields have no defaults (a topography needs a file: skipped)."""


def _built_in(name):
    """A registered shape made with its defaults (and REQUIRED), or None where it cannot be."""
    try:
        return SHAPES.get(name)(**REQUIRED.get(name, {}))
    except (TypeError, TengsimError, ValueError):
        return None


@pytest.mark.parametrize("name", SHAPES.names())
def test_every_registered_shape_answers_its_full_contact_length(name):
    """The shape's own answer; the study's, from a result's parameters, is the same."""
    from tengsim.run.area import full_length

    shape = _built_in(name)
    if shape is None:
        pytest.skip(f"{name} has required fields")
    own = float(getattr(shape, "full_contact_length", lambda: math.nan)())
    from_params = full_length({**shape.params(), "config": {"shape": name}})
    assert (math.isnan(own) and math.isnan(from_params)) or own == pytest.approx(from_params)


def test_full_contact_lengths_of_the_built_in_shapes():
    from tengsim.shapes import Array, Cone, Cube, Hemisphere, Line, Pyramid

    assert Pyramid(0.946, 3.78).full_contact_length() == pytest.approx(1.892)
    assert Hemisphere(2.0, 8.0).full_contact_length() == pytest.approx(4.0)
    assert Cone(0.5, 8.0, 1.0).full_contact_length() == pytest.approx(4.0)  # 2 height / slope
    assert math.isnan(Cone(0.5, 8.0).full_contact_length())  # uncapped: none
    assert Cube(1.0, 1.0, 4.0).full_contact_length() == pytest.approx(4.0)  # the cell: the plate on the land
    assert Line(1.0, 1.0, 4.0).full_contact_length() == pytest.approx(4.0)
    assert Array("pyramid", K=2, N=0.946, cell=3.78).full_contact_length() == pytest.approx(1.892)


def test_contact_plan_is_the_type_simulate_runs():
    from tengsim.run.simulate import simulate

    p = plan_contact(dict(CFG))
    a = simulate(p)
    b = simulate(ContactPlan(p.shape, p.tabor, p.dx, p.path))
    assert list(a.table["F"]) == list(b.table["F"]) and isinstance(p, ContactPlan)


def test_shapes_answer_their_contact_family():
    """The charged area's family comes from the shape class (no list of names in run.area): the built-in
    shapes as docs/design.md tabulates them, by registered name and by class name (a result's 'shape'
    parameter), and an unregistered name falls back to the square patch."""
    from tengsim.plugins import SHAPES
    from tengsim.run.area import family

    expect = {"pyramid": "square", "cube": "square", "cone": "disc", "hemisphere": "disc", "sphere": "disc",
              "flat_punch": "disc", "line": "line", "sinusoid": "line"}
    for name, fam in expect.items():
        assert family({"shape": name}) == fam, name
        assert family({"shape": SHAPES.get(name).__name__}) == fam, name
    assert family({"shape": "no-such-shape"}) == "square"
    for name in SHAPES.names():
        assert family({"shape": name}) in ("square", "disc", "line")


@pytest.fixture
def spied(monkeypatch):
    """The plans the refinement engine (resolve._refine_grids) and the one-grid run (simulate) are given; both
    still run (every caller reaches them through their modules)."""
    from tengsim.run import resolve, simulate

    seen = {"resolve": [], "grids": []}
    real_resolve, real_grid = resolve._refine_grids, simulate._one_grid

    def resolving(plan, how=resolve.Refining(), progress=None):
        seen["resolve"].append(plan)
        seen.setdefault("settings", []).append(how.settings or plan.resolve)  # a pass's settings
        return real_resolve(plan, how, progress)

    def one_grid(plan, **kw):
        seen["grids"].append(plan)
        return real_grid(plan, **kw)

    monkeypatch.setattr(resolve, "_refine_grids", resolving)
    monkeypatch.setattr(simulate, "_one_grid", one_grid)
    return seen


def _refined_by_the_plan(seen, res, tol):
    """Refinements of a ContactPlan whose settings are the run's, each of their grids a simulate run."""
    assert seen["resolve"] and all(isinstance(p, ContactPlan) for p in seen["resolve"])
    assert all(isinstance(r, ResolveSettings) and r.rel_tol == tol for r in seen["settings"])
    assert all(isinstance(p, ContactPlan) for p in seen["grids"])
    ran = [p.grid.dx for p in seen["grids"]]
    grids = res.params["resolve_grids"]
    assert len(grids) >= 2  # the refinement's grids are the last simulate runs, in order
    assert ran[-len(grids):] == pytest.approx(grids, rel=1e-12)


def test_a_resolve_auto_run_plans_once_and_refines_that_plan(tmp_path, counted, spied):
    from tengsim.results.read import load_result

    out = tmp_path / "r.csv"
    assert main([*PYR, "--resolve", "auto", "--resolve-tol", "0.2", "--max-pixels", str(9 * 9),
                 "--out", str(out)]) == 0
    assert len(counted) == 1, counted
    _refined_by_the_plan(spied, load_result(out)[1], 0.2)
    assert len(spied["resolve"]) == 1
    assert all(p.shape is spied["resolve"][0].shape for p in spied["grids"])  # the one plan's pieces, not rebuilt


def test_a_design_plans_once_and_refines_that_plan(counted, spied):
    from tengsim.design import plan_design, run_design

    small = {"shape": "pyramid", "pitch": "1um", "base": "0.5um", "height": "0.2um", "E_star": "5MPa",
             "W": "20mJ/m2", "eps": "50nm", "p_max": "20kPa", "p_step": "10kPa", "tol": 0.05, "maps": False}
    res = run_design(plan_design(small))  # a refinement per D range tried (the last reaches p_max)
    assert len(counted) == 1, counted
    _refined_by_the_plan(spied, res.finest, 0.05)
    assert spied["grids"][-1].path.d_max == res.finest.params["d_max"]
    assert all(p is spied["resolve"][0] for p in spied["resolve"])  # every pass refines the design's one plan


def test_a_design_builds_a_contact_plan_once_per_grid_and_per_refinement_pass(monkeypatch):
    """A design runs the ContactPlan plan_design built (with the design's solver and its tolerance): it builds one
    per grid it solves (the coarse pre-run and each grid of each refinement pass, whose settings are passed, not
    planned), no other."""
    from tengsim.design import plan_design, run_design
    from tengsim.design.plan import solver_tol
    from tengsim.run import resolve
    from tengsim.run import simulate as sim

    plan = plan_design({"shape": "pyramid", "pitch": "1um", "base": "0.5um", "height": "0.2um", "E_star": "5MPa",
                        "W": "20mJ/m2", "eps": "50nm", "p_max": "20kPa", "p_step": "10kPa", "tol": 0.05,
                        "maps": False})
    assert isinstance(plan.contact_plan, ContactPlan) and plan.contact_plan.solver_tol == solver_tol(plan)
    built, grids, passes = [], [], []
    real_post, real_run, real_resolve = ContactPlan.__post_init__, sim._one_grid, resolve._refine_grids
    monkeypatch.setattr(ContactPlan, "__post_init__", lambda self: (built.append(1), real_post(self))[1])
    monkeypatch.setattr(sim, "_one_grid", lambda p, **kw: (grids.append(p.grid.nx), real_run(p, **kw))[1])
    monkeypatch.setattr(resolve, "_refine_grids", lambda p, *a: (passes.append(1), real_resolve(p, *a))[1])
    res = run_design(plan)
    assert res.status == "ok" and len(grids) >= 3 and passes
    assert len(built) <= len(grids), (len(built), grids, len(passes))  # at most one per grid solved
