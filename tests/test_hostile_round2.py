"""A second hostile round on the newer surfaces (design, device --area-from, resume): each defect it found,
shown fixed by a test named after it (docs/faults.md, "The second round").

The design runs here are refused before anything is solved, or are the tiny design ``S`` (a 1 µm pyramid to
5 % on grids up to 77², a few seconds); the device runs read a synthetic design result (no solving).
"""
from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from tengsim.cli.main import main

S = ["pyramid", "--pitch", "1um", "--base", "0.5um", "--height", "0.2um", "--E-star", "5MPa", "--W", "20mJ/m2",
     "--eps", "50nm", "--p-max", "20kPa", "--p-step", "10kPa", "--tol", "0.05", "--maps", "false"]
S_TOML = """[design]
shape = "pyramid"
pitch = "1um"
base = "0.5um"
height = "0.2um"
E_star = "5MPa"
W = "20mJ/m2"
eps = "50nm"
p_max = "20kPa"
p_step = "10kPa"
tol = 0.05
maps = false
"""
SRC = str(Path(__import__("tengsim").__file__).resolve().parents[1])


def refused(capsys, argv, folder: Path, *, contains: str = "") -> str:
    """Run ``argv``: exit 2, one line 'tengsim: error: ...' (containing ``contains``), nothing written in
    ``folder``; returns the line."""
    before = sorted(os.listdir(folder))
    rc = main([str(a) for a in argv])
    err = capsys.readouterr().err.strip()
    assert rc == 2, err[-800:]
    lines = err.splitlines()
    assert lines and lines[-1].startswith("tengsim: error:"), err[-800:]
    assert "Traceback" not in err and "internal error" not in err
    assert len(lines[-1]) < 1200
    assert contains in lines[-1], lines[-1]
    assert sorted(os.listdir(folder)) == before, set(os.listdir(folder)) ^ set(before)
    return lines[-1]


def design_nc(path: Path, status: str = "ok", pressure=None, area=None) -> Path:
    """A synthetic design result (the variables the device reads): A/S rising with pressure."""
    import xarray as xr

    p = np.array([0.0, 5e3, 1e4, 2e4]) if pressure is None else pressure
    a = np.array([[0.01, 0.05, 0.1, 0.2], [0.02, 0.06, 0.1, 0.2]]) if area is None else area
    ds = xr.Dataset({"charged_area_fraction": (("branch", "applied_pressure"), a)},
                    coords={"branch": ["approach", "retraction"], "pressure": ("applied_pressure", p)})
    ds["pressure"].attrs["units"] = "Pa"
    ds.attrs["status"] = status
    path.parent.mkdir(parents=True, exist_ok=True)
    ds.to_netcdf(path, engine="h5netcdf")
    return path


@pytest.fixture
def here(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    return tmp_path


# ---- data destroyed ------------------------------------------------------------------------------------

@pytest.mark.parametrize("kind", ["nc", "folder"])
def test_device_out_equal_to_its_area_input_is_refused_and_the_input_kept(here, capsys, kind):
    src = design_nc(here / "d1" / "design.nc")
    before = src.read_bytes()
    area = "d1" if kind == "folder" else "d1/design.nc"
    refused(capsys, ["device", "fig7", "--area-from", area, "--out", "d1/design.nc"], here / "d1",
            contains="also an input")
    assert src.read_bytes() == before


def test_device_area_in_the_config_equal_to_the_output_is_refused_by_run_and_sweep(here, capsys):
    src = design_nc(here / "a.nc")
    before = src.read_bytes()
    (here / "r.toml").write_text('[device]\narea = "a.nc"\n[run]\ncase = "fig7"\nout = "a.nc"\n')
    refused(capsys, ["run", "r.toml"], here, contains="also an input")
    (here / "s.toml").write_text('[device]\narea = "a.csv"\n')
    (here / "a.csv").write_text("x")
    refused(capsys, ["device", "sweep", "--config", "s.toml", "--out", "a.csv", "--points", "2"], here)
    assert src.read_bytes() == before and (here / "a.csv").read_text() == "x"


def test_the_json_sidecar_never_overwrites_the_json_config(here, capsys):
    (here / "dev.json").write_text('{"device": {}}')
    refused(capsys, ["device", "fig7", "--config", "dev.json", "--out", "dev.csv"], here, contains="sidecar")
    assert (here / "dev.json").read_text() == '{"device": {}}'


def test_comparison_folder_names_stay_inside_out_and_off_reserved_names():
    from types import SimpleNamespace

    from tengsim.cli.design import RESERVED, _folders

    from tengsim.errors import TengsimError

    for reserved in ("compare.csv", "Compare.PNG"):
        with pytest.raises(TengsimError, match="comparison's own file"):
            _folders([SimpleNamespace(name="a"), SimpleNamespace(name=reserved)])
    names = ["..", ".", "compare.csv_", "compare", "../../etc", "", "a" * 300, ".hidden", "a/b", "a"]
    got = _folders([SimpleNamespace(name=n) for n in names])
    assert len(set(got)) == len(got)
    out = Path("/tmp/out").resolve()
    for g in got:
        assert g not in (".", "..", "") and not g.startswith(".") and "/" not in g and len(g) <= 64
        assert g.lower() not in RESERVED
        assert (out / g).resolve().parent == out


def test_a_comparison_with_a_design_that_cannot_run_here_is_refused_before_any_is_computed(here, capsys):
    (here / "a.toml").write_text(S_TOML)
    (here / "g.toml").write_text(S_TOML + 'solver = "vsr"\nname = "' + "x" * 300 + '"\n')
    refused(capsys, ["design", "a.toml", "g.toml", "--out", "cmp"], here, contains="g.toml")


def test_a_topography_file_named_as_a_design_output_is_not_overwritten(here, capsys):
    h = np.outer(np.hanning(16), np.hanning(16)) * 0.2
    np.savetxt(here / "design.csv", h)
    before = (here / "design.csv").read_bytes()
    refused(capsys, ["design", "topography", "--file", "design.csv", "--physical-size", "1um", "--unit", "um",
                     *S[7:], "--out", "."], here, contains="design.csv")
    assert (here / "design.csv").read_bytes() == before


# ---- crashes and hangs -----------------------------------------------------------------------------------

@pytest.mark.parametrize("text", ["design = 5\n", 'design = "abc"\n', '[[design]]\nshape = "pyramid"\n',
                                  "a = " + "[" * 600 + "]" * 600 + "\n", S_TOML + "[other]\nx = 1\n"])
def test_design_toml_structure_is_one_line_exit_2(here, capsys, text):
    (here / "d.toml").write_text(text)
    refused(capsys, ["design", "d.toml", "--out", "o"], here)


def test_a_toml_nested_600_deep_is_one_line_for_every_command(here, capsys):
    (here / "deep.toml").write_text("[a]\nb = " + "[" * 600 + "]" * 600 + "\n")
    refused(capsys, ["run", "deep.toml"], here, contains="nested too deeply")
    refused(capsys, ["device", "fig7", "--config", "deep.toml", "--out", "o.csv"], here, contains="nested")
    (here / "deep.json").write_text('{"a": ' + "[" * 3000 + "]" * 3000 + "}")
    refused(capsys, ["device", "fig7", "--config", "deep.json", "--out", "o.csv"], here, contains="nested")


def test_design_shape_text_of_a_pair_of_sizes_does_not_crash():
    from tengsim.design.plan import DesignPlan

    p = DesignPlan("", "topography", {}, {"physical_size_m": (1e-6, 2e-6), "file": "h.txt"}, (), 0, 0, 0, 0, 0,
                   None, None, 0, 0, 0, 0, 0, 0)
    assert p.shape_text() == "physical_size 1 µm × 2 µm, file h.txt"


@pytest.mark.parametrize("make", ["text_pressure", "area_3d", "random_csv", "text_csv"])
def test_area_from_files_that_are_not_area_tables_are_one_line(here, capsys, make):
    if make == "text_pressure":
        f = design_nc(here / "x.nc", pressure=np.array(["a", "b", "c", "d"]))
    elif make == "area_3d":
        import xarray as xr

        f = here / "x.nc"

        ds = xr.Dataset({"charged_area_fraction": (("branch", "applied_pressure", "z"),
                                                   np.random.default_rng(0).random((2, 4, 3)))},
                        coords={"branch": ["approach", "retraction"],
                                "pressure": ("applied_pressure", [0.0, 1.0, 2.0, 3.0])})
        ds.to_netcdf(f, engine="h5netcdf")
    elif make == "random_csv":
        f = here / "x.csv"
        f.write_bytes(np.random.default_rng(1).bytes(3000))
    else:  # a physical contact result (a coarse 4-row path) with text in one pressure_Pa cell
        import csv
        import io

        assert main(["contact", "pyramid", "--pitch", "1um", "--base", "0.5um", "--height", "0.2um", "--E-star",
                     "5MPa", "--W", "20mJ/m2", "--eps", "50nm", "--d-min", "0", "--d-max", "3", "--d-step", "1",
                     "--dx", "100nm", "--out", "c.csv", "--quiet"]) == 0
        capsys.readouterr()
        lines = (here / "c.csv").read_text(encoding="utf-8").splitlines(keepends=True)
        rows = list(csv.reader([ln for ln in lines if not ln.startswith("#")]))
        rows[2][rows[0].index("pressure_Pa")] = "abc"
        buf = io.StringIO()
        csv.writer(buf, lineterminator="\n").writerows(rows)
        f = here / "x.csv"
        f.write_text("".join(ln for ln in lines if ln.startswith("#")) + buf.getvalue(), encoding="utf-8")
    refused(capsys, ["device", "fig7", "--area-from", f.name, "--out", "o.csv"], here)


def test_a_grid_far_too_fine_is_refused_before_any_array(here, capsys):
    t0 = time.perf_counter()
    refused(capsys, ["design", *S, "--dx", "0.02nm", "--out", "o"], here, contains="memory")
    assert time.perf_counter() - t0 < 10


@pytest.mark.parametrize("T", ["1e-30m", "1e-15m"])
def test_a_film_far_thinner_than_its_pixel_is_refused_at_once(here, capsys, T):
    t0 = time.perf_counter()
    refused(capsys, ["design", *S, "--thickness", T, "--out", "o"], here, contains="film thickness")
    refused(capsys, ["contact", "pyramid", "--pitch", "1um", "--base", "0.5um", "--height", "0.2um", "--E-star",
                     "5MPa", "--W", "20mJ/m2", "--eps", "50nm", "--thickness", T, "--out", "o.csv"], here)
    assert time.perf_counter() - t0 < 10


def test_the_film_correction_refuses_an_unbounded_subdivision():
    from tengsim.errors import TengsimError
    from tengsim.kernels.film import film_pixel_correction

    with pytest.raises(TengsimError, match="film thickness"):
        film_pixel_correction(np.zeros(1), np.zeros(1), 1.0, 1.0, 1e-15, 0.3, "bonded")


def test_device_sweep_points_are_bounded(here, capsys):
    refused(capsys, ["device", "sweep", "--points", "1e15", "--out", "o.csv"], here, contains="at most")


def test_text_is_written_as_utf8_whatever_the_locale(tmp_path):
    env = {**os.environ, "PYTHONPATH": SRC, "LC_ALL": "C", "LANG": "C", "PYTHONUTF8": "0",
           "PYTHONIOENCODING": ""}
    code = ("import sys; from tengsim.io import write_text; write_text(sys.argv[1], 'pitch 1 \\u00b5m, "
            "\\u03c3, \\u00d7');"
            "from tengsim.cli.main import main; sys.exit(main(['design', '--help']))")
    p = subprocess.run([sys.executable, "-c", code, str(tmp_path / "r.md")], capture_output=True, text=True,
                       env=env, timeout=120)
    assert p.returncode == 0, p.stderr[-800:]
    assert (tmp_path / "r.md").read_text(encoding="utf-8") == "pitch 1 µm, σ, ×"


def test_tol_has_a_floor_and_the_budget_stops_a_run_cleanly(here, capsys):
    refused(capsys, ["design", *S, "--tol", "1e-14", "--budget", "10", "--out", "o"], here, contains="tol")
    from types import SimpleNamespace

    from tengsim.run.budget import BudgetSpent, deadline

    plan = SimpleNamespace(budget_s=1.0, name="d")
    seen = []
    call = deadline(lambda *a: seen.append(a), plan, None, time.monotonic())
    call("approach", 0.0, 1, 2)
    assert seen
    late = deadline(None, plan, None, time.monotonic() - 5.0)
    with pytest.raises(BudgetSpent, match="stopped at the budget.*larger --budget"):
        late("approach", 0.0, 1, 2)


# ---- silently wrong ------------------------------------------------------------------------------------

def test_a_space_inside_a_number_is_refused(here, capsys):
    from tengsim.units import parse_quantity

    assert parse_quantity("20 kPa") == 20e3 and parse_quantity("20 mJ / m2") == pytest.approx(0.02)
    refused(capsys, ["design", *S, "--p-max", "2 0kPa", "--out", "o"], here, contains="space inside a number")
    for bad in ("1 000Pa", "- 5kPa", "2 .5kPa"):
        with pytest.raises(Exception, match="space inside"):
            parse_quantity(bad)


@pytest.mark.parametrize("key,value", [("--eps-r", "1e100"), ("--T", "1e-100m"), ("--sigma", "1e3"),
                                       ("--gap", "1e9m")])
def test_device_inputs_of_a_design_have_physical_bounds(here, capsys, key, value):
    refused(capsys, ["design", *S, key, value, "--out", "o"], here, contains="outside")


def test_a_design_checkpoint_belongs_to_the_input_files_content(here):
    from tengsim.design import plan_design
    from tengsim.design.keep import identity

    h = np.outer(np.hanning(16), np.hanning(16)) * 0.2
    np.savetxt(here / "h.txt", h)
    table = {"shape": "topography", "file": "h.txt", "physical_size": "1um", "unit": "um", "E_star": "5MPa",
             "W": "20mJ/m2", "eps": "50nm", "p_max": "20kPa", "tol": 0.05}
    a = identity(plan_design(table))
    assert identity(plan_design(table)) == a  # the same input: the same grids
    assert identity(plan_design({**table, "budget": 1200})) == a  # a larger budget goes on from them
    np.savetxt(here / "h.txt", h * 1.5)
    assert identity(plan_design(table)) != a  # the same name, another surface: not the same grids


def test_a_design_resumes_on_its_second_pass_path(here):
    from tengsim.design.keep import checkpoint, kept_path
    from tengsim.run.checkpoint import Checkpoint

    keep = here / ".design-0.resolve.nc"
    said = []
    progress = type("P", (), {"say": lambda self, t: said.append(t)})()
    ck, found = checkpoint(keep, "abc", 7.5, progress)
    assert found is None and not said
    assert kept_path(keep, "abc") is None  # nothing kept yet
    # a kept grid of the same design on a longer path (its second pass): found, and no "another design" line
    orig = Checkpoint.stored_digest
    try:
        Checkpoint.stored_digest = lambda self: "abc@11.0"
        assert kept_path(keep, "abc") == 11.0 and kept_path(keep, "xyz") is None
    finally:
        Checkpoint.stored_digest = orig


def test_an_unconverged_design_used_by_the_device_gets_a_warning(here, capsys):
    design_nc(here / "d" / "design.nc", status="not converged")
    rc = main(["device", "fig7", "--area-from", "d", "--out", "o.csv", "--cycles", "1", "--dt", "1ms", "--quiet"])
    err = capsys.readouterr().err
    assert rc == 0, err[-800:]
    assert "warning" in err and "not converged" in err


# ---- refusals that still wrote, races, messages ----------------------------------------------------------

def test_max_pixels_below_the_first_grid_is_refused_before_anything_is_created(here, capsys):
    refused(capsys, ["design", *S, "--max-pixels", "1e3", "--out", "o/p"], here, contains="max_pixels")
    assert not (here / "o").exists()


def test_a_design_out_is_locked_against_a_second_run(here, capsys):
    from tengsim.outfolder import folder_lock

    with folder_lock(here / "o"):
        line = refused(capsys, ["design", *S, "--out", "o"], here / "o", contains="in use")
    assert "another tengsim run" in line
    assert not (here / "o").exists()  # made for the lock, empty: removed again


def test_figures_are_written_atomically(tmp_path, monkeypatch):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from tengsim.io import save_figure

    fig = plt.figure()
    target = tmp_path / "f.png"

    def full(self, *a, **k):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(type(fig), "savefig", full)
    with pytest.raises(OSError) as info:
        save_figure(fig, target)
    plt.close(fig)
    assert info.value.filename == str(target) and list(tmp_path.iterdir()) == []


def test_geometry_errors_are_in_the_users_units_and_the_given_dx_is_honoured(here, capsys):
    line = refused(capsys, ["design", "cube", "--pitch", "20um", "--half-width", "12um", "--height", "6um",
                            "--E-star", "2MPa", "--W", "40mJ/m2", "--eps", "200nm", "--p-max", "50kPa", "--out", "o"],
                   here)
    assert "24 µm exceeds its cell 20 µm" in line
    line = refused(capsys, ["design", "hemisphere", "--pitch", "1um", "--radius", "2um", "--E-star", "2MPa",
                            "--W", "40mJ/m2", "--eps", "20nm", "--p-max", "50kPa", "--out", "o"], here)
    assert "4 µm exceeds its cell 1 µm" in line
    # a 1 mm pitch at dx 20 µm: judged at the given dx (by its budget, here 1 s), not refused by the default dx's
    # grid (a path of thousands of rows: the budget refuses it, in seconds, not the pixels per side)
    line = refused(capsys, ["design", "pyramid", "--pitch", "1mm", "--base", "0.5mm", "--height", "0.2mm",
                            "--E-star", "5MPa", "--W", "20mJ/m2", "--eps", "50nm", "--p-max", "20kPa", "--dx", "20um",
                            "--budget", "1s", "--out", "o"], here)
    assert "pixels per side" not in line and "dx=" not in line and "budget" in line


def test_a_wrong_key_points_to_the_shapes_help_and_help_lists_only_keys_taken(capsys):
    assert main(["design", *S, "--width", "3um", "--out", "o"]) == 2
    assert "tengsim design pyramid --help" in capsys.readouterr().err
    assert main(["design", "pyramid", "--help"]) == 0
    assert "tabor" not in capsys.readouterr().out


def test_a_long_name_and_many_unknown_keys_give_short_lines(here, capsys):
    refused(capsys, ["design", *S, "--name", "n" * 10_000, "--out", "o"], here, contains="at most")
    (here / "k.toml").write_text(S_TOML + "".join(f"k{i} = 1\n" for i in range(20_000)))
    refused(capsys, ["design", "k.toml", "--out", "o"], here, contains="more")


def test_a_sweep_of_points_that_all_need_a_missing_solver_is_one_line(here, capsys):
    pytest.importorskip("jax")
    import jax

    if any(d.platform == "gpu" for d in jax.devices()):
        pytest.skip("this machine has a GPU")
    (here / "s.toml").write_text('[base.contact]\nshape = "pyramid"\nN = 0.946\ncell = 3.78\ndx = 0.3\n'
                                 'tabor = 0.5\nd_min = 0.0\nd_max = 0.5\nd_step = 0.5\n'
                                 '[axes]\n"contact.solver" = ["gpu"]\n"contact.N" = [0.9, 1.0]\n')
    refused(capsys, ["sweep", "s.toml", "--out", "o", "--workers", "1", "--quiet"], here, contains="GPU")


def test_the_interrupt_message_no_longer_claims_nothing_was_kept():
    import inspect

    from tengsim.cli import main as m

    assert "no partial output was written" not in inspect.getsource(m._main)


def test_check_writable_creates_nothing(tmp_path):
    from tengsim.io import check_output

    check_output(tmp_path / "a" / "b" / "o.csv")
    check_output(tmp_path / "c" / "d", folder=True)
    assert list(tmp_path.iterdir()) == []


def test_a_very_soft_material_is_refused_before_the_default_grids_kernel_is_made(here, capsys):
    """E* = 197 Pa puts the default grid at 65 625²: its kernel (136 GiB) was allocated to measure the pixel
    snap number, before any memory check (found by the property test on design values)."""
    refused(capsys, ["design", *S, "--E-star", "197", "--out", "o"], here, contains="memory")
