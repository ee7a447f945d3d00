"""tengsim design / tengsim.design: a small pyramid design, converged, checked against a grid √2 finer; its files
(CF-1.10 NetCDF, CSV, report, figures in physical units); bad input refused in one line, nothing written; two
designs compared."""
import dataclasses
import math

import numpy as np
import pytest

from tengsim.run.plan import ContactPlan
from tengsim.cli.main import main
from tengsim.errors import TengsimError
from tengsim.design import plan_design, run_design, write_design
from tengsim.design.write import CHANGE_NA

SMALL = {"shape": "pyramid", "pitch": "1um", "base": "0.5um", "height": "0.2um", "E_star": "5MPa", "W": "20mJ/m2",
         "eps": "50nm", "p_max": "50kPa", "p_step": "5kPa", "boundary": "free"}
# the isolated cell (given): this strongly adhesive array, periodic (the default), snaps into full contact and its
# walk past p_max presses the law's wall (test_periodic_default_and_area_definition below runs the default)
CLI_SMALL = ["design", "pyramid", "--pitch", "1um", "--base", "0.5um", "--height", "0.2um", "--E-star", "5MPa",
             "--W", "20mJ/m2", "--eps", "50nm", "--p-max", "50kPa", "--p-step", "5kPa", "--boundary", "free", "--quiet"]


@pytest.fixture(scope="module")
def small():
    return run_design(plan_design(SMALL))


def test_plan_physical_defaults_and_tabor():
    p = plan_design(SMALL)
    assert p.pressures[0] == 0 and p.pressures[-1] == pytest.approx(50e3) and len(p.pressures) == 11
    assert (p.sigma, p.eps_r, p.T, p.gap) == (5.84e-6, 2.40, 400e-6, 0.1e-3)  # the paper's device
    assert p.eps == pytest.approx(50e-9) and p.tabor > 0


def test_small_design_ok_and_within_1pct_of_a_grid_sqrt2_finer(small):
    from tengsim.run.plan import plan_contact
    from tengsim.run.simulate import simulate
    from tengsim.design.curves import branch_curves
    from tengsim.continuation import PathSpec

    assert small.status == "ok"
    res = small.finest
    cplan = plan_contact(small.plan.contact_table)
    path = PathSpec(res.params["d_min"], res.params["d_max"], res.params["d_step"], adaptive=True)
    finer = simulate(ContactPlan(cplan.shape, cplan.tabor, res.grid.dx / math.sqrt(2), path, law=cplan.law, scaling=cplan.scaling, extra=cplan.extra, boundary=cplan.boundary))
    assert finer.grid.nx > res.grid.nx
    a = small.dataset["charged_area_fraction"].sel(branch="approach").values
    b = branch_curves(finer, small.plan)["approach"]["area"]
    assert np.all(np.isfinite(a)) and a[-1] > a[0] + 0.05  # the area grows with pressure
    assert np.max(np.abs(a - b) / np.maximum(np.abs(b), 0.01)) <= 0.01
    assert abs(res.pull_off_force - finer.pull_off_force) <= 0.01 * abs(finer.pull_off_force)


def test_dataset_contract_and_physics(small):
    ds = small.dataset
    assert list(ds["branch"].values) == ["approach", "retraction"]
    assert ds["pressure"].attrs["units"] == "Pa" and np.all(np.diff(ds["pressure"].values) > 0)
    for k in ("charged_area_fraction", "repulsive_area_fraction", "voc_eq12", "voc_eq17", "dvoc_dp"):
        assert ds[k].dims == ("branch", "applied_pressure")  # CF: a dimension 'pressure' is air pressure
    assert ds["pressure"].dims == ("applied_pressure",)
    for k in ("Conventions", "title", "shape", "shape_params", "E_star_Pa", "W_J_m2", "eps_m", "tabor", "sigma_C_m2",
              "eps_r", "thickness_m", "status", "grids", "tolerance", "charged_area_definition"):
        assert k in ds.attrs, k
    assert ds.attrs["Conventions"] == "CF-1.10" and ds.attrs["shape"] == "pyramid"
    assert ds.attrs["solver_tolerance_eps"] == pytest.approx(0.01 * ds.attrs["tolerance"])  # and stated
    A = ds["charged_area_fraction"].values
    eps0 = 8.8541878128e-12
    # Eq. 12 and Eq. 17 from A/S with the paper's σ, ε_r, T and rest gap
    assert np.allclose(ds["voc_eq12"].values, 5.84e-6 * A * 400e-6 / (2.40 * eps0), equal_nan=True)
    assert np.allclose(ds["voc_eq17"].values, 5.84e-6 * A * 0.1e-3 / eps0, equal_nan=True)
    # the charged area (gap below the LJ peak separation 3^(1/6)) holds the repulsive area (P > 0: gap below 1),
    # and never more than the cell
    R = ds["repulsive_area_fraction"].values
    ok = np.isfinite(A) & np.isfinite(R)
    assert np.all(A[ok] >= R[ok] - 1e-9) and np.nanmax(A) <= 1.0
    assert ds.attrs["boundary"] == "free" and ds.attrs["area_definition"] == "contact"


def test_files_cf_report_and_labels(small, tmp_path):
    runner = pytest.importorskip("compliance_checker.runner")
    from tengsim.design.plots import design_figure

    paths = write_design(small, tmp_path / "d1")
    names = {p.name for p in paths}
    assert {"design.nc", "design.csv", "report.md", "design.png"} <= names
    cs = runner.CheckSuite()
    cs.load_all_available_checkers()
    results, errors = cs.run_all(cs.load_dataset(str(tmp_path / "d1" / "design.nc")), ["cf:1.10"], skip_checks=[])["cf:1.10"]
    failed = [(r.name, r.msgs) for r in results if r.value[0] < r.value[1] and r.weight >= 2]
    assert not failed and not errors, (failed, errors)
    text = (tmp_path / "d1" / "report.md").read_text()
    assert "Status: ok" in text and small.summary["grids"] in text and "tolerance 1 %" in text
    assert "![design.png](design.png)" in text
    fig = design_figure(small)
    labels = [a.get_xlabel() for a in fig.axes] + [a.get_ylabel() for a in fig.axes]
    assert all("(kPa)" in x for x in labels[:3])
    assert any("(V)" in y for y in labels) and any("V/kPa" in y for y in labels)
    assert "pyramid" in fig._suptitle.get_text() and "µm" in fig._suptitle.get_text()
    assert "X (dimensionless)" not in " ".join(labels)
    from tengsim.design.plots import maps_figure

    titles = [a.get_title() for a in maps_figure(small).axes if a.get_title()]
    assert titles and all("kPa" in t and "asked" in t for t in titles)
    assert all(a.get_xlabel() == "x (µm)" for a in maps_figure(small).axes if a.get_title())


@pytest.mark.parametrize("bad, words", [
    (["--pitch", "-1um"], "pitch"),
    (["--pitch", "10uu"], "10uu"),
    (["--p-max", "0kPa"], "p_max"),
    (["--eps", ""], "eps"),
    (["--dx", "0.25nm"], "--dx"),  # a 4000² grid: expected over the 10 min budget
])
def test_bad_input_one_line_exit_2_nothing_written(tmp_path, capsys, bad, words):
    argv = list(CLI_SMALL)
    if bad[0] not in argv:
        argv += bad
    i = argv.index(bad[0])
    argv[i + 1] = bad[1]
    if bad[1] == "":
        del argv[i:i + 2]
    out = tmp_path / "never"
    assert main([*argv, "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and words in err, err
    assert not out.exists()


def test_unknown_shape_refused(tmp_path, capsys):
    out = tmp_path / "never"
    assert main(["design", "pyramidd", "--eps", "50nm", "--p-max", "1kPa", "--out", str(out)]) == 2
    assert "pyramidd" in capsys.readouterr().err and not out.exists()


def test_comparison_of_two_designs_one_table_one_figure(tmp_path):
    a, b = tmp_path / "a.toml", tmp_path / "b.toml"
    common = 'E_star = "5MPa"\nW = "20mJ/m2"\neps = "50nm"\np_max = "20kPa"\np_step = "10kPa"\ntol = 0.05\nmaps = false\n'
    a.write_text('[design]\nname = "pyramid A"\nshape = "pyramid"\npitch = "1um"\nbase = "0.5um"\nheight = "0.2um"\n'
                 + common)
    b.write_text('[design]\nname = "cone B"\nshape = "cone"\npitch = "1um"\nslope = 0.8\nheight = "0.2um"\n' + common)
    out = tmp_path / "cmp"
    assert main(["design", str(a), str(b), "--out", str(out), "--quiet"]) == 0
    rows = [r for r in (out / "compare.csv").read_text().splitlines() if not r.startswith("#")]
    assert len(rows) == 3
    head = rows[0].split(",")
    body = [dict(zip(head, r.split(","))) for r in rows[1:]]
    assert {b["design"] for b in body} == {"pyramid A", "cone B"} and [b["rank"] for b in body] == ["1", "2"]
    assert float(body[0]["area_at_p_max"]) >= float(body[1]["area_at_p_max"])  # ranked by the charged area
    assert (out / "compare.png").stat().st_size > 0
    assert (out / "pyramid_A" / "design.nc").exists() and (out / "cone_B" / "design.nc").exists()


def test_shipped_design_examples_plan():
    """examples/own_design/*.toml (the README's comparisons) are valid designs: the issue's pyramid and cone, and the
    cube, grating and hemisphere arrays (docs/own_design.md), periodic by default."""
    from pathlib import Path

    from tengsim.design import read_design

    files = sorted((Path(__file__).parent.parent / "examples" / "own_design").glob("*.toml"))
    plans = [plan_design(read_design(str(f))) for f in files]
    assert {p.shape for p in plans} == {"pyramid", "cone", "cube", "line", "hemisphere"}
    for p in plans:
        pitch = 10e-6 if p.shape in ("pyramid", "cone") else 20e-6
        assert p.shape_params["pitch_m"] == pytest.approx(pitch) and p.eps == pytest.approx(200e-9)
        assert p.boundary == "periodic" and not p.boundary_given and p.area == "contact"


def test_help_per_shape_is_short(capsys):
    assert main(["design", "cone", "--help"]) == 0
    text = capsys.readouterr().out
    assert len(text.splitlines()) <= 100 and "--slope" in text and "--base" not in text and "--eps" in text
    assert main(["design", "--help"]) == 0
    assert "tengsim design SHAPE --help" in capsys.readouterr().out


def test_refinement_message_in_the_users_units():
    from tengsim.design.curves import physical_message

    msg = physical_message("stopped by max_pixels = 9 at dx = 0.1 (3×3; next 5×5); A_S_app_5000Pa changed 2% between "
                           "the last two grids, dx ≈ 0.05 needed", 200e-9)
    assert "dx = 20 nm" in msg and "dx ≈ 10 nm" in msg and "A/S at 5 kPa (approach)" in msg
    # a physical run's refinement writes its lengths with their unit already: not converted a second time
    msg = physical_message("at dx = 22 nm (455×455; next 675×675); dx ≈ 10.7 nm needed, dx below 1.2 µm", 143e-9)
    assert "dx = 22 nm (" in msg and "dx ≈ 10.7 nm needed" in msg and "dx below 1.2 µm" in msg


def test_first_grid_is_the_default_refinements_first_fine_enough_one():
    """The first grid: the refinement from the default start (the cell over 9 pixels, …) less its grids coarser
    than the process zone over START_ZONE_PIXELS, which cannot be the last (issue 29: 33² … 117² were thrown away
    for the issue's pyramid)."""
    from tengsim import status
    from tengsim.run.plan import plan_contact
    from tengsim.run.refine import START_ZONE_PIXELS, first_dx
    from tengsim.run.grids import default_dx, refinement_grids

    from tengsim.design import read_design
    from pathlib import Path

    plan = plan_design(read_design(str(Path(__file__).parent.parent / "examples" / "own_design" / "pyramid.toml")))
    cp = plan_contact(plan.contact_table)
    zone = status.process_zone_estimate(cp.law, cp.tabor**1.5)
    dx0 = default_dx(cp.shape, cp.law, cp.tabor**1.5, cp.boundary)
    seq = refinement_grids(cp.shape, dx0)
    dx = first_dx(cp, plan)
    k = [g.nx for g in seq].index(cp.shape.grid(dx).nx)
    assert k > 0 and seq[k].dx <= zone / START_ZONE_PIXELS < seq[k - 1].dx
    assert [g.nx for g in seq[k:k + 3]] == [245, 385, 585]  # the last grids the pyramid converged on before
    given = plan_design(dict(read_design(str(Path(__file__).parent.parent / "examples" / "own_design" / "pyramid.toml")),
                             dx="100nm"))
    assert first_dx(cp, given) * cp.scaling.lateral == pytest.approx(100e-9)  # a dx given is the first grid's


def test_maps_kept_during_the_finest_walk(small):
    """The finest grid's own walk keeps the maps (no second walk), at the D where the grid before reached the
    asked pressures: each map's nominal pressure is the one the finest grid's own depth for that pressure gives
    (what a second walk kept, :func:`tengsim.design.run.map_depths`; after a snap, the state the load reaches)
    to within 2 % of p_max."""
    from tengsim.design.walk import map_depths

    res = small.finest
    assert small.maps is res
    maps = sorted((m for m in res.maps if m["branch"] == "approach"), key=lambda m: m["D"])
    asked = dict(small.summary["map_pressures_asked"])
    assert len(maps) == len(asked) == 3
    a = res.branch("approach")
    D, P = np.asarray(a["D"], float), np.asarray(a["pressure_Pa"], float)
    own = sorted(map_depths(res, small.plan).items(), key=lambda kv: kv[1])
    for m, (d_own, p_asked) in zip(maps, own):
        assert asked[round(float(m["D"]), 9)] == p_asked
        i = int(np.argmin(np.abs(D - m["D"])))
        assert abs(D[i] - m["D"]) < 1e-9
        j = int(np.argmin(np.abs(D - d_own)))
        p_own = P[j] if abs(D[j] - d_own) < 1e-9 else np.interp(d_own, D, P)
        assert abs(P[i] - p_own) <= 0.02 * small.plan.pressures[-1], (P[i], p_own, p_asked)


def test_retraction_convergence_recorded_per_grid(small, tmp_path):
    """design.nc records the refinement, grid by grid: A/S on both branches, the pull-off force, the hysteresis;
    the change of each between the last two grids is an attribute and a row of the report (issue 29)."""
    ds = small.dataset
    tab = small.finest.params["resolution"]
    n = ds.sizes["refinement_grid"]
    assert n == len(tab["dx"]) >= 2 and list(ds["grid_pixels"].values) == list(tab["nx"])
    by = ds["charged_area_fraction_by_grid"]
    assert by.dims == ("refinement_grid", "branch", "applied_pressure")
    # the finest grid's entries are the design's own numbers
    np.testing.assert_allclose(by.values[-1], ds["charged_area_fraction"].values, rtol=1e-12, equal_nan=True)
    assert float(ds["pull_off_force_by_grid"][-1]) == pytest.approx(small.summary["pull_off_N"], rel=1e-12)
    assert float(ds["hysteresis_by_grid"][-1]) == pytest.approx(small.summary["hysteresis_J_m2"], rel=1e-12)
    ret = by.sel(branch="retraction").values
    both = np.isfinite(ret[-1]) & np.isfinite(ret[-2])
    change = np.max(np.abs(ret[-1] - ret[-2])[both] / np.maximum(np.abs(ret[-1][both]), 0.01))
    assert ds.attrs["change_charged_area_A_S_on_the_retraction"] == pytest.approx(change, rel=1e-9)
    h = ds["hysteresis_by_grid"].values
    assert np.all(np.isfinite(h)) and np.all(h >= 0)  # never a negative energy (tests/test_hysteresis.py)
    if h[-1] != 0:
        assert ds.attrs["change_hysteresis_energy"] == pytest.approx(abs(h[-1] - h[-2]) / abs(h[-1]), rel=1e-9)
    else:  # this pyramid has no jump: 0 within its uncertainty; 0 on both grids is no change
        assert ds.attrs["change_hysteresis_energy"] == (0.0 if h[-2] == 0 else CHANGE_NA)
    write_design(small, tmp_path / "d", figures=False)
    text = (tmp_path / "d" / "report.md").read_text()
    assert "hysteresis energy (recorded, not judged)" in text and "on the retraction" in text


def test_hysteresis_of_a_design_without_jumps_is_zero_within_its_stated_bound(small, tmp_path):
    """The small pyramid has no jump: its loop energy is 0 within the stated uncertainty (the rule before gave
    −6.3e-6 J/m², the approach's extra rows against the retraction's coarser ones), the bound in design.nc, the
    CSV header and the report beside it."""
    import json

    res = small.finest
    assert res.jumps == []
    s = small.summary
    e = res.loop_energy
    k = res.scaling.work(1.0) / res.scaling.cell_area
    assert s["hysteresis_J_m2"] == 0.0 and s["hysteresis_bound_J_m2"] == pytest.approx(k * e.bound, rel=1e-12)
    assert abs(k * e.estimate) <= s["hysteresis_bound_J_m2"] and 0 < s["hysteresis_bound_J_m2"] < 1e-4
    ds = small.dataset
    assert ds.attrs["hysteresis_J_m2"] == 0.0 and ds.attrs["hysteresis_bound_J_m2"] == s["hysteresis_bound_J_m2"]
    write_design(small, tmp_path / "h", figures=False)
    head = dict(line[2:].split(": ", 1) for line in (tmp_path / "h" / "design.csv").read_text().splitlines()
                if line.startswith("# "))
    assert json.loads(head["hysteresis_J_m2"]) == 0.0
    assert json.loads(head["hysteresis_bound_J_m2"]) == pytest.approx(s["hysteresis_bound_J_m2"], rel=1e-12)
    report = (tmp_path / "h" / "report.md").read_text()
    assert "| hysteresis uncertainty" in report and "-" not in report.split("| hysteresis: energy lost")[1][:120]


def test_a_killed_design_resumes_from_its_kept_grids(tmp_path, small):
    """Each finished grid is kept in the file ``keep`` (issue 30: every long-running command keeps what it
    finished): a run of the same design takes them back and computes no grid again, giving the same numbers."""
    keep = tmp_path / "out" / ".design-0.resolve.nc"
    first = run_design(plan_design(SMALL), keep=keep)
    assert keep.is_file()  # left as a killed run would leave it (the CLI removes it once the files are written)
    lines = []

    class Say:
        def say(self, text):
            lines.append(text)

    again = run_design(plan_design(SMALL), progress=Say(), keep=keep)
    assert any(ln.startswith("taking back ") for ln in lines), lines
    assert again.summary["grids"] == first.summary["grids"] == small.summary["grids"]
    a, b = first.dataset["charged_area_fraction"].values, again.dataset["charged_area_fraction"].values
    assert np.array_equal(np.isnan(a), np.isnan(b)) and np.allclose(a[~np.isnan(a)], b[~np.isnan(b)], rtol=0, atol=0)
    other = dict(SMALL, p_max="21kPa")  # another design: its grids are not taken, and that is said
    lines.clear()
    run_design(plan_design(other), progress=Say(), keep=keep)
    assert any("holds grids of another design" in ln for ln in lines), lines


def test_a_design_killed_after_its_first_grid_resumes_to_the_same_numbers_and_maps(tmp_path, small):
    """Killed between two grids, the rerun takes the first back and walks the next on the path the first gives (its
    end and the maps' depths): the same numbers as the run never killed, to the bit, and its maps (a grid taken back
    has no scaling: its path was walked to d_max and the maps were lost)."""

    class Killed(Exception):
        pass

    class Kill:
        def say(self, text):
            if text.startswith("grid 1 ("):
                raise Killed

    keep = tmp_path / ".design-0.resolve.nc"
    with pytest.raises(Killed):
        run_design(plan_design(SMALL), progress=Kill(), keep=keep)
    again = run_design(plan_design(SMALL), keep=keep)
    assert again.summary["grids"] == small.summary["grids"]
    a, b = small.dataset["charged_area_fraction"].values, again.dataset["charged_area_fraction"].values
    assert np.array_equal(np.isnan(a), np.isnan(b)) and np.array_equal(a[~np.isnan(a)], b[~np.isnan(b)])
    assert (small.maps is None) == (again.maps is None) and again.summary["map_pressures_asked"] == \
        small.summary["map_pressures_asked"]


def test_cli_removes_the_kept_grids_once_written(tmp_path):
    out = tmp_path / "d"
    assert main([*CLI_SMALL, "--out", str(out)]) == 0
    assert (out / "design.nc").is_file() and not list(out.glob(".design-*.resolve.nc"))


def test_budget_cap_is_the_last_refinement_grid_the_budget_pays_for():
    """The default max_pixels is the largest grid of the refinement's own sequence whose cost, with the grids before
    it, fits the budget: the next grid of that sequence does not; the example pyramid refines to 585² from its 245²
    first grid within the default 10 min."""
    from pathlib import Path

    from tengsim.design import read_design
    from tengsim.run.budget import budget_pixels, run_cost
    from tengsim.run.refine import first_dx
    from tengsim.run.reach import height_eps
    from tengsim.run.grids import GridSequence, refinement_grids

    plan = plan_design(read_design(str(Path(__file__).parent.parent / "examples" / "own_design" / "pyramid.toml")))
    cp = plan.contact_plan
    dx = first_dx(cp, plan)
    d_max = 1.2 * height_eps(cp, dx) + 2.0
    cost = run_cost(cp, d_max)
    cap = budget_pixels(plan, cp.shape, GridSequence(cp.shape, dx), cost)
    assert cap >= 585 * 585
    seq = refinement_grids(cp.shape, dx, 12)
    below = [g for g in seq if g.nx * g.ny <= cap]
    assert below[-1].nx * below[-1].ny == cap  # the cap is a grid of the sequence
    secs = sum(cost.grid_seconds(cp.shape, g) for g in below)
    assert secs <= plan.budget_s  # the grids up to the cap fit the budget
    nxt = seq[len(below)]
    assert secs + cost.grid_seconds(cp.shape, nxt) > plan.budget_s  # and the next one does not


def test_estimate_uses_the_backends_cost_and_names_it(monkeypatch):
    """The design's expected time is the CPU model's where JAX sees no GPU and the GPU model's (a floor per
    iteration plus a per-point term) where it does, and its line names the backend assumed; on the GPU the
    same design is expected faster at these sizes (the GPU solves the whole grid, the CPU a mirrored quarter)."""
    from pathlib import Path

    from tengsim.design import read_design
    from tengsim.run import budget as _budget, refine as _refine
    from tengsim.resources import CPU_COST, GPU_COST
    from tengsim.run.plan import chosen_solver as plan_chosen, plan_contact
    from tengsim.solvers import choice

    plan = plan_design(read_design(str(Path(__file__).parent.parent / "examples" / "own_design" / "pyramid.toml")))
    cp = plan_contact(plan.contact_table)
    assert cp.solver == "auto"  # the plan stays pure: chosen on each grid solved
    assert plan_chosen(cp)[0] == "fast" and "no GPU" in plan_chosen(cp)[1]  # on this machine
    from tengsim.run.grids import GridSequence

    dx = _refine.first_dx(cp, plan)
    seq = GridSequence(cp.shape, dx)
    cpu = _budget.estimate(plan, cp, seq, 25.0, _budget.run_cost(cp, 25.0))
    assert cpu.backend == CPU_COST.backend and "CPU" in cpu.lines()[1]
    monkeypatch.setattr(choice, "gpu_visible", lambda: True)
    cp_gpu = dataclasses.replace(cp, solver="gpu")
    gpu = _budget.estimate(plan, cp_gpu, seq, 25.0, _budget.run_cost(cp_gpu, 25.0))
    assert gpu.backend == GPU_COST.backend and "GPU" in gpu.lines()[1]
    g = cp.shape.grid(dx)
    rows_its = gpu.cost.rows * gpu.cost.iterations
    per_iteration = GPU_COST.floor + GPU_COST.per_point * g.nx * g.ny
    assert gpu.cost.grid_seconds(cp.shape, g) == pytest.approx(rows_its * per_iteration)
    assert gpu.seconds < cpu.seconds
    assert (_budget.budget_pixels(plan, cp.shape, seq, _budget.run_cost(cp_gpu, 25.0))
            > _budget.budget_pixels(plan, cp.shape, seq, _budget.run_cost(dataclasses.replace(cp, solver="fast"), 25.0)))


def test_auto_picks_the_gpu_where_jax_sees_one(monkeypatch):
    from tengsim.run import choice as run_choice
    from tengsim.solvers import choice

    assert run_choice.choose("fast") == ("fast", "")
    monkeypatch.setattr(choice, "gpu_visible", lambda: False)
    assert run_choice.choose("auto")[0] == "fast" and "no GPU" in run_choice.choose("auto")[1]
    with pytest.raises(TengsimError, match="no GPU"):
        run_choice.choose("gpu")
    monkeypatch.setattr(choice, "gpu_visible", lambda: True)
    assert run_choice.choose("auto")[0] == "gpu"


def test_solver_gpu_without_a_gpu_one_line_exit_2_nothing_written(tmp_path, capsys):
    from tengsim.solvers.choice import gpu_visible

    if gpu_visible():
        pytest.skip("this machine has a GPU")
    out = tmp_path / "never"
    assert main([*CLI_SMALL, "--solver", "gpu", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "gpu" in err and "no GPU" in err, err
    assert not out.exists()


def test_report_table_cells_hold_no_pipe():
    """Every label of the report's tables is one Markdown cell: no '|' inside a label would split its row."""
    from tengsim.design import report

    for entry in vars(report).values():
        if isinstance(entry, (list, tuple)):
            for row in entry:
                if isinstance(row, tuple) and len(row) >= 2 and isinstance(row[1], str):
                    assert "|" not in row[1], row


def test_the_designs_solver_tolerance_moves_its_numbers_far_less_than_tol():
    """A design solves each equilibrium to max|r| <= 0.01 × tol (design.run.SOLVER_TOL_PER_TOL), not a contact
    run's 1e-6: on the small pyramid's first grid, A/S on both branches at every asked pressure, the pull-off
    force and the hysteresis move by less than tol/20 against the 1e-6 solve (measured 2e-4 for A/S)."""
    import dataclasses

    from tengsim.design import plan as _dplan, walk as _walk
    from tengsim.design.curves import branch_curves
    from tengsim.run.refine import find_range, plan_refinement
    from tengsim.run.plan import plan_contact

    plan = plan_design(SMALL)
    assert _dplan.solver_tol(plan) == pytest.approx(1e-4)
    out = []
    for tol in (_dplan.solver_tol(plan), 1e-6):
        cplan = dataclasses.replace(plan_contact(plan.contact_table), solver_tol=tol)
        refinement = plan_refinement(cplan, plan)
        res = _walk._simulate(cplan, refinement.dx, find_range(refinement)[0])
        assert res.params["tol"] == tol and res.status == "ok"
        c = branch_curves(res, plan)
        out.append((np.concatenate([c["approach"]["area"], c["retraction"]["area"]]), res.pull_off_force,
                    res.hysteresis))
    (a, f, h), (a0, f0, h0) = out
    assert np.max(np.abs(a - a0) / np.maximum(np.abs(a0), 0.01)) < plan.rel_tol / 20
    assert abs(f - f0) < plan.rel_tol / 20 * abs(f0) and abs(h - h0) <= plan.rel_tol / 20 * abs(h0) + 1e-12


def test_estimate_on_a_busy_machine_says_the_longer_time(monkeypatch):
    """On a machine busier than its cores (load / cores >= 1.25) the estimate's line adds the time at that
    load, the idle estimate × load / cores; an idle machine's line says nothing of it; the GPU's never."""
    import os

    from tengsim.run import budget as de

    monkeypatch.setattr(os, "getloadavg", lambda: (5.0, 4.0, 3.0))
    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: {0, 1})
    assert de.machine_busy() == (2.5, 5.0, 2)
    est = de.Estimate(((64, 64, 1e-7),), 1000, 120.0, 10.0, "CPU", None, 60.0, de.machine_busy())
    assert "busy (load 5.0 on 2 cores): expect about 5.0 min" in est.lines()[1]
    monkeypatch.setattr(os, "getloadavg", lambda: (1.5, 1.0, 1.0))
    assert de.machine_busy() == (1.0, 1.5, 2)
    assert "busy" not in de.Estimate(((64, 64, 1e-7),), 1000, 120.0, 10.0, "CPU", None, 60.0,
                                     de.machine_busy()).lines()[1]


def test_approach_only_design_gives_the_full_designs_approach_and_says_the_rest_is_not_solved(small, tmp_path):
    """``retraction = false``: the approach alone is walked on each grid (no retraction rows, half the estimated
    rows); the approach's A/S equals the full design's on the same grids to 1e-12; every number of the retraction
    (pull-off, hysteresis, A/S on the retraction, the sensor's hysteresis) is n/a with the reason, never a 0."""
    from tengsim.design.curves import NOT_RETRACTED
    from tengsim.run.budget import run_cost

    plan = plan_design({**SMALL, "retraction": "false"})
    assert plan.retraction is False and plan_design(SMALL).retraction is True
    one = run_design(plan)
    assert one.status == "ok"
    assert set(np.asarray(one.finest.table["branch"]).astype(str)) == {"approach"}
    if one.summary["grids"] == small.summary["grids"]:  # the same grids: the same approach, bit for bit
        np.testing.assert_allclose(one.dataset["charged_area_fraction"].sel(branch="approach").values,
                                   small.dataset["charged_area_fraction"].sel(branch="approach").values,
                                   rtol=1e-12, equal_nan=True)
    else:  # a refinement judging fewer numbers may stop a grid earlier: within the tolerance
        np.testing.assert_allclose(one.summary["area_at_p_max"], small.summary["area_at_p_max"], rtol=2 * small.plan.rel_tol)
    assert np.all(np.isnan(one.dataset["charged_area_fraction"].sel(branch="retraction").values))
    for k in ("pull_off_N", "pull_off_Pa", "hysteresis_J_m2", "area_hysteresis", "voc_hysteresis_V"):
        assert math.isnan(one.summary[k]) and one.summary["reasons"][k] == NOT_RETRACTED, k
    assert math.isfinite(small.summary["hysteresis_J_m2"])  # the full design has it
    assert one.dataset.attrs["branches_solved"] == "approach"
    cp = plan.contact_plan
    assert run_cost(cp, 20.0, retract=False).rows == pytest.approx(0.5 * run_cost(cp, 20.0).rows)
    write_design(one, tmp_path / "d", figures=False)
    text = (tmp_path / "d" / "report.md").read_text()
    assert "(the approach only)" in text and NOT_RETRACTED in text and "| 0 J/m² |" not in text


def test_auto_keeps_the_cpu_below_the_gpus_break_even(monkeypatch):
    """On a GPU machine ``auto`` keeps the NumPy solver for a grid under the cost models' break-even (measured on an
    H200: the tiny-pyramid calibration ran slower on the GPU than on 2 CPU cores, docs/benchmarks.md) and says so."""
    from tengsim.resources import CPU_COST, GPU_COST, gpu_break_even_points
    from tengsim.run import budget as _budget
    from tengsim.run.plan import chosen_solver, plan_contact
    from tengsim.run import choice as run_choice
    from tengsim.solvers import choice

    even = gpu_break_even_points()
    assert even == pytest.approx(GPU_COST.floor / (CPU_COST.per_point - GPU_COST.per_point))
    assert CPU_COST.iteration_seconds(even) == pytest.approx(GPU_COST.iteration_seconds(even))
    monkeypatch.setattr(choice, "gpu_visible", lambda: True)
    small, why = run_choice.choose("auto", points=81 * 81)
    assert small == "fast" and "break-even" in why and "6561" in why
    assert run_choice.choose("auto", points=351 * 351)[0] == "gpu"
    assert run_choice.choose("gpu", points=9)[0] == "gpu"  # asked by name: taken as asked
    tiny = plan_contact({"shape": "pyramid", "N": 0.946, "cell": 3.78, "tabor": 0.5, "dx": 0.1, "d_max": 1.0,
                         "d_step": 0.2})
    assert tiny.solver == "auto" and chosen_solver(tiny)[0] == "fast" and "break-even" in chosen_solver(tiny)[1]
    fine = dataclasses.replace(tiny, dx=0.01, grid=None)  # a finer grid of the same plan chooses again, on its own
    assert fine.solver == "auto" and chosen_solver(fine)[0] == "gpu"
    assert _budget.on_gpu(tiny) is False and _budget.on_gpu(tiny, fine.grid) is True
