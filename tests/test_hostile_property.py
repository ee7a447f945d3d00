"""Generated hostile input (issue 30): values, strings, TOML tables and files fed to the CLI entry points.

Whatever hypothesis draws, every command ends with exit 0 or 2, never 70 (an internal error) or a signal,
with no traceback on stderr; an exit 2 is one line and writes nothing; no run outlasts its bound.  The
commands are cheap by construction (a 13² pyramid grid, two equilibria; a study's sweep pointed at a
port where nothing listens, so a study that parses is refused at the connection and none is computed).
The whole module runs in about 30 s on one core (``derandomize``: the same examples every run).
"""
import json
import math
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from tengsim.cli.main import main  # noqa: E402

BASE = ["contact", "pyramid", "--N", "0.946", "--cell", "3.78", "--dx", "0.3", "--d-min", "0", "--d-max", "0.5",
        "--d-step", "0.5", "--tabor", "0.5", "--quiet"]
BOUND_S = 20.0  # no single command may take longer (an exit-0 run here takes well under a second)
NOWHERE = "tcp://127.0.0.1:9"  # the discard port: nothing listens, the connection is refused at once


def SETTINGS(n):
    return settings(max_examples=n, deadline=None, derandomize=True, database=None,
                    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])


def check(folder: Path, argv, capsys):
    """Run ``argv`` in process in ``folder`` and assert the promise; returns the exit code."""
    before = sorted(os.listdir(folder))
    t0 = time.perf_counter()
    rc = main([str(a) for a in argv])
    took = time.perf_counter() - t0
    err = capsys.readouterr().err
    assert rc in (0, 2), (argv[:8], rc, err[-500:])
    assert "Traceback" not in err and "internal error" not in err, err[-1000:]
    assert took < BOUND_S, (argv[:8], took)
    if rc == 2:
        lines = err.strip().splitlines()
        assert lines and lines[-1].startswith("tengsim: error:"), err[-500:]
        assert len([l for l in lines if l.startswith("tengsim: error:")]) == 1, err[-500:]
        assert len(lines[-1]) < 1200, lines[-1][:200]  # a hostile value is never echoed whole
        assert sorted(os.listdir(folder)) == before, (argv[:8], set(os.listdir(folder)) - set(before))
    return rc


# ---- values --------------------------------------------------------------------------------------
number_text = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.integers(min_value=-10**400, max_value=10**400).map(str),
    st.from_regex(r"-?[0-9]{1,3}_[0-9]{1,3}", fullmatch=True),
    st.builds(lambda m, e: f"{m}e{e}", st.integers(-9, 9), st.integers(-400, 400)),
    st.sampled_from(["0x10", "1e", ".", "-", "--", "1,5", "½", "١", "1e-320", "1e308", "5e292", "0.5 MPa",
                     "-0.59MPa", "2um", "=1+1", "9" * 5000, "nan", "-inf", "0_5"]),
    st.text(max_size=80),
)
# keys whose value moves no grid: an accepted value keeps the run cheap (dx and cell are drawn hostile only)
CHEAP_KEYS = ["--N", "--tabor", "--d-max", "--tol", "--d-step"]
GRID_KEYS = ["--dx", "--cell"]
hostile_grid = st.one_of(st.floats(max_value=0.05).map(repr), st.floats(min_value=50).map(repr),
                         st.sampled_from(["1e-320", "1e308", "0_3", "nan", "-0.3", "x"]))


@SETTINGS(60)
@given(key=st.sampled_from(CHEAP_KEYS), value=number_text)
def test_generated_values_on_contact(tmp_path_factory, capsys, key, value):
    d = tmp_path_factory.mktemp("v")
    check(d, [*BASE, key, value, "--out", d / "o.csv"], capsys)


@SETTINGS(25)
@given(key=st.sampled_from(GRID_KEYS), value=hostile_grid)
def test_generated_grid_values_are_refused_or_cheap(tmp_path_factory, capsys, key, value):
    d = tmp_path_factory.mktemp("g")
    check(d, [*BASE, key, value, "--out", d / "o.csv"], capsys)


@SETTINGS(30)
@given(opt=st.sampled_from(["--law", "--boundary", "--solver", "--E-star", "--W", "--maps", "--resolve"]),
       value=st.text(max_size=120))
def test_generated_strings_on_options(tmp_path_factory, capsys, opt, value):
    d = tmp_path_factory.mktemp("s")
    check(d, [*BASE, opt, value, "--out", d / "o.csv"], capsys)


# ---- TOML tables ---------------------------------------------------------------------------------
def toml_value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        return "nan" if math.isnan(v) else ("inf" if v == math.inf else "-inf" if v == -math.inf else repr(v))
    if isinstance(v, int):
        return str(v)
    if isinstance(v, str):
        return json.dumps(v)  # a JSON string is a TOML basic string
    if isinstance(v, list):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{json.dumps(k)} = {toml_value(x)}" for k, x in v.items()) + " }"
    raise TypeError(v)


def toml_table(name, table) -> str:
    return f"[{name}]\n" + "".join(f"{json.dumps(k)} = {toml_value(v)}\n" for k, v in table.items())


scalar = st.one_of(st.booleans(), st.integers(min_value=-2**63, max_value=2**63 - 1), st.floats(),
                   number_text, st.text(max_size=30))
value = st.recursive(scalar, lambda inner: st.one_of(st.lists(inner, max_size=4),
                                                     st.dictionaries(st.text(max_size=8), inner, max_size=3)),
                     max_leaves=6)
contact_keys = st.sampled_from(["N", "cell", "tabor", "dx", "d_min", "d_max", "d_step", "law", "boundary",
                                "solver", "shape", "E_star", "W", "maps", "resolve", "seed", "tol"])
some_key = st.one_of(contact_keys, st.text(max_size=12))
BASE_TABLE = {"shape": "pyramid", "N": 0.946, "cell": 3.78, "dx": 0.3, "tabor": 0.5, "d_min": 0.0, "d_max": 0.5,
              "d_step": 0.5}


@SETTINGS(40)
@given(extra=st.dictionaries(some_key, value, max_size=4))
def test_generated_contact_tables(tmp_path_factory, capsys, extra):
    d = tmp_path_factory.mktemp("t")
    cfg = d / "run.toml"
    table = {**BASE_TABLE, **extra, "out": str(d / "o.csv")}
    cfg.write_text(toml_table("contact", table))
    check(d, ["run", cfg, "--quiet"], capsys)


axis_name = st.one_of(st.sampled_from(["contact.N", "contact.tabor", "contact.dx", "contact.shape", "var.k",
                                       "device.R", "contact.nope"]), st.text(max_size=12))
axis_spec = st.one_of(
    st.lists(scalar, min_size=0, max_size=4),
    st.fixed_dictionaries({"start": scalar, "stop": scalar}, optional={"num": scalar, "scale": scalar}),
    st.fixed_dictionaries({"zip": st.dictionaries(axis_name, st.lists(scalar, max_size=3), max_size=2)}),
    value)


@SETTINGS(40)
@given(axes=st.dictionaries(axis_name, axis_spec, min_size=1, max_size=2),
       study=st.dictionaries(st.sampled_from(["sampling", "n", "seed", "x"]), scalar, max_size=2),
       objective=st.none() | st.dictionaries(st.sampled_from(["minimize", "maximize", "subject_to", "popsize",
                                                             "maxiter", "seed"]), value, max_size=3))
def test_generated_study_tables(tmp_path_factory, capsys, axes, study, objective):
    d = tmp_path_factory.mktemp("study")
    f = d / "s.toml"
    text = toml_table("base.contact", BASE_TABLE) + toml_table("base.var", {"k": 1.0}) + toml_table("axes", axes)
    if study:
        text += toml_table("study", study)
    if objective is not None:
        text += toml_table("objective", objective)
    f.write_text(text)
    cmd = "optimize" if objective is not None else "sweep"
    rc = check(d, [cmd, f, "--out", d / "o", "--scheduler", NOWHERE, "--quiet"], capsys)
    assert rc == 2  # a study that parses is refused at the connection: nothing is ever computed here


# ---- files ---------------------------------------------------------------------------------------
matrix = st.lists(st.lists(st.floats(width=32), min_size=1, max_size=20), min_size=1, max_size=20)


@SETTINGS(30)
@given(content=st.one_of(st.binary(max_size=3000), st.sampled_from([8192, 2 * 17 * 17, 2 * 33 * 33]).map(os.urandom),
                         matrix.map(lambda rows: "\n".join(" ".join(repr(x) for x in r) for r in rows).encode()),
                         st.text(max_size=500).map(str.encode)),
       suffix=st.sampled_from([".txt", ".dat", ".asc", ".hgt", ".nc", ""]))
def test_generated_topography_files(tmp_path_factory, capsys, content, suffix):
    d = tmp_path_factory.mktemp("f")
    f = d / f"surface{suffix}"
    f.write_bytes(content)
    check(d, ["contact", "topography", f, "--physical-size", "2um,2um", "--E-star", "1GPa", "--W", "50mJ/m2",
              "--tabor", "1", "--d-min", "-0.5", "--d-max", "0.5", "--d-step", "0.5", "--quiet",
              "--out", d / "o.csv"], capsys)


@SETTINGS(25)
@given(content=st.one_of(st.text(max_size=400), st.binary(max_size=400).map(lambda b: b.decode("latin-1"))),
       header=st.sampled_from(["", "branch,D,F\n", "t,V\n", "R,energy_per_cycle,average_power\n"]))
def test_generated_result_files_to_plot(tmp_path_factory, capsys, content, header):
    d = tmp_path_factory.mktemp("p")
    f = d / "r.csv"
    f.write_text(header + content, encoding="utf-8", errors="surrogatepass")
    rc = check(d, ["plot", f, "--out", d / "p.png"], capsys)
    if rc == 0:
        (d / "p.png").unlink()


# ---- a few through a real process: the exit code, not only main()'s return value -----------------
SRC = str(Path(__import__("tengsim").__file__).resolve().parents[1])  # the tengsim under test


@pytest.mark.parametrize("args", [
    ["--tabor", "9" * 100_000],
    ["--E-star", "-0.59MPa"],
    ["--dx", "1e-320"],
])
def test_hostile_values_through_a_process(tmp_path, args):
    env = {**os.environ, "PYTHONPATH": SRC, "OPENBLAS_NUM_THREADS": "1", "MPLBACKEND": "Agg"}
    p = subprocess.run([sys.executable, "-m", "tengsim.cli.main", *BASE, *args, "--out", str(tmp_path / "o.csv")],
                       capture_output=True, text=True, env=env, timeout=60)
    assert p.returncode == 2, p.stderr[-500:]
    assert len(p.stderr.strip().splitlines()) == 1 and "Traceback" not in p.stderr
    assert list(tmp_path.iterdir()) == []


# ---- the newer surfaces: design (one and a comparison), device --area-from, run with device tables ------
# A design is run here with a budget of 10 ms: every design that parses is refused by its estimate before
# anything is solved, so what is drawn is judged by the planning (the whole path to the budget's refusal).
DESIGN = ["design", "pyramid", "--pitch", "1um", "--base", "0.5um", "--height", "0.2um", "--E-star", "5MPa",
          "--W", "20mJ/m2", "--eps", "50nm", "--p-max", "20kPa", "--p-step", "10kPa", "--tol", "0.05",
          "--maps", "false", "--quiet", "--budget", "10ms"]
DESIGN_KEYS = ["--pitch", "--base", "--height", "--E-star", "--W", "--eps", "--p-max", "--p-step", "--p-min",
               "--sigma", "--eps-r", "--T", "--gap", "--tol", "--dx", "--max-pixels", "--fit-max", "--name",
               "--maps", "--law", "--boundary", "--solver", "--thickness", "--poisson"]
DESIGN_TABLE = {"shape": "pyramid", "pitch": "1um", "base": "0.5um", "height": "0.2um", "E_star": "5MPa",
                "W": "20mJ/m2", "eps": "50nm", "p_max": "20kPa", "p_step": "10kPa", "tol": 0.05, "maps": False,
                "budget": "10ms"}
design_keys = st.one_of(st.sampled_from([k[2:].replace("-", "_") for k in DESIGN_KEYS] + ["shape", "budget"]),
                        st.text(max_size=12))


@SETTINGS(30)
@given(key=st.sampled_from(DESIGN_KEYS), value=st.one_of(number_text, st.text(max_size=60)))
def test_generated_values_on_design(tmp_path_factory, capsys, key, value):
    d = tmp_path_factory.mktemp("dv")
    rc = check(d, [*DESIGN, key, value, "--out", d / "o"], capsys)
    assert rc == 2  # at most planned: the 10 ms budget refuses every design that parses


@SETTINGS(20)
@given(extra=st.lists(st.dictionaries(design_keys, value, max_size=3), min_size=2, max_size=3),
       top=st.booleans())
def test_generated_design_comparisons(tmp_path_factory, capsys, extra, top):
    d = tmp_path_factory.mktemp("dc")
    files = []
    for k, e in enumerate(extra):
        f = d / f"d{k}.toml"
        table = {**DESIGN_TABLE, **e}
        f.write_text("".join(f"{json.dumps(a)} = {toml_value(b)}\n" for a, b in table.items()) if top
                     else toml_table("design", table))
        files.append(f)
    rc = check(d, ["design", *files, "--out", d / "o", "--quiet"], capsys)
    assert rc == 2


def _area_nc(path, p, a, status="ok"):
    import numpy as np
    import xarray as xr

    ds = xr.Dataset({"charged_area_fraction": (("branch", "applied_pressure"), np.asarray([a, a], dtype=float))},
                    coords={"branch": ["approach", "retraction"], "pressure": ("applied_pressure", p)})
    ds.attrs["status"] = status
    ds.to_netcdf(path, engine="h5netcdf")


area_values = st.lists(st.floats(allow_nan=True, allow_infinity=True), min_size=4, max_size=4)


@SETTINGS(25)
@given(content=st.one_of(st.binary(max_size=2000), st.text(max_size=400).map(str.encode),
                         st.tuples(area_values, area_values)),
       suffix=st.sampled_from([".nc", ".csv", ""]))
def test_generated_area_files_for_the_device(tmp_path_factory, capsys, content, suffix):
    d = tmp_path_factory.mktemp("af")
    f = d / f"area{suffix}"
    if isinstance(content, tuple):
        if suffix != ".nc":
            f = d / "area.nc"
        _area_nc(f, *content)
    else:
        f.write_bytes(content)
    rc = check(d, ["device", "fig7", "--area-from", f, "--t-end", "2ms", "--dt", "1ms", "--quiet",
                   "--out", d / "o.csv"], capsys)
    if rc == 0:
        (d / "o.csv").unlink()
        (d / "o.json").unlink()


device_keys = st.one_of(st.sampled_from(["mass_kg", "stiffness_N_per_m", "area_m2", "thickness_m", "gap_m",
                                         "eps_r", "sigma_C_per_m2", "load_ohm", "damping_ratio", "area",
                                         "force_model", "initial_charge"]), st.text(max_size=10))
waveform_keys = st.one_of(st.sampled_from(["kind", "amplitude_Pa", "frequency_Hz", "duty", "low_Pa", "t_s",
                                           "pressure_Pa"]), st.text(max_size=10))


@SETTINGS(30)
@given(device=st.dictionaries(device_keys, value, max_size=3),
       waveform=st.dictionaries(waveform_keys, value, max_size=3),
       case=st.sampled_from(["fig7", "run", "sweep"]))
def test_generated_device_tables_through_run(tmp_path_factory, capsys, device, waveform, case):
    d = tmp_path_factory.mktemp("dt")
    cfg = d / "dev.toml"
    text = toml_table("device", device) if device else ""
    text += toml_table("waveform", waveform) if waveform else ""
    run = {"case": case, "out": str(d / "o.csv"), "t_end": "2ms", "dt_out": "1ms"}
    if case == "sweep":
        run = {"case": case, "out": str(d / "o.csv"), "cycles": 2}
        text += toml_table("sweep", {"points": 2})
    cfg.write_text(text + toml_table("run", run))
    rc = check(d, ["run", cfg, "--quiet"], capsys)
    if rc == 0:
        (d / "o.csv").unlink()
        (d / "o.json").unlink()


# ---- calibrate: measured-data files and options (issue 48) ---------------------------------------------------
# Nothing is solved: a calibration that plans is stopped by PLANNED the moment plan_calibration returns (before
# the output folder is checked or any design runs), so what is drawn is judged by the reader and the planning.
class PLANNED(BaseException):
    """Raised where a calibration would start solving (main() does not catch a BaseException)."""


CAL_DESIGN = ('[design]\nshape = "pyramid"\npitch = "1um"\nbase = "0.5um"\nheight = "0.2um"\nE_star = "10MPa"\n'
              'eps = "50nm"\ntol = 0.05\n')


def check_calibrate(folder: Path, argv, capsys, monkeypatch):
    """``check`` for calibrate: a calibration that plans counts as exit 0 and has written nothing."""
    import tengsim.calibrate as cal

    real = cal.plan_calibration

    def planned(*a, **k):
        real(*a, **k)
        raise PLANNED

    monkeypatch.setattr(cal, "plan_calibration", planned)
    before = sorted(os.listdir(folder))
    try:
        return check(folder, argv, capsys)
    except PLANNED:
        err = capsys.readouterr().err
        assert "Traceback" not in err and "error" not in err, err[-500:]
        assert sorted(os.listdir(folder)) == before
        return 0


def _sheet(rows, sep, crlf, bom, comma):
    """A measured curve as a spreadsheet may write it: the separator, CRLF, a BOM, decimal commas."""
    num = (lambda x: repr(x).replace(".", ",")) if comma else repr
    end = "\r\n" if crlf else "\n"
    text = end.join([f"pressure_kPa{sep}voc_V"] + [f"{num(p)}{sep}{num(v)}" for p, v in rows]) + end
    return ("\ufeff" if bom else "") + text


sheet_rows = st.lists(st.tuples(st.floats(0, 50), st.floats(0, 20)), min_size=0, max_size=6)
header_words = st.sampled_from(["pressure_kPa", "pressure_Pa", "pressure_MPa", "pressure_mPa", "pressure_MPA",
                                "pressure", "Pressure (kPa)", "voc_V", "VOC_V", "voc_err_V", "branch", "x"])
csv_content = st.one_of(
    st.builds(_sheet, sheet_rows, st.sampled_from([",", ";", "\t", " "]), st.booleans(), st.booleans(),
              st.booleans()),
    st.builds(lambda h, sep, rows: sep.join(h) + "\n" + "\n".join(sep.join(r) for r in rows),
              st.lists(header_words, min_size=1, max_size=4), st.sampled_from([",", ";", "\t"]),
              st.lists(st.lists(st.one_of(number_text, st.sampled_from(["approach", "retraction", ""])),
                                max_size=5), max_size=5)),
    st.sampled_from(["pressure_kPa,voc_V\n2," + "9" * 140_000 + "\n", "pressure_kPa,voc_V\n2,0\n4,0\n6,0\n8,0\n",
                     "pressure_kPa,voc_V\n2,1e-12\n4,2e-12\n6,3e-12\n8,4e-12\n", "\x00\x01", ""]),
    st.text(max_size=300),
)


@SETTINGS(30)
@given(content=csv_content, encoding=st.sampled_from(["utf-8", "utf-16", "latin-1"]))
def test_generated_measured_data_for_calibrate(tmp_path_factory, capsys, monkeypatch, content, encoding):
    d = tmp_path_factory.mktemp("cd")
    (d / "d.toml").write_text(CAL_DESIGN)
    f = d / "m.csv"
    f.write_bytes(content.encode(encoding, errors="replace"))
    check_calibrate(d, ["calibrate", d / "d.toml", "--data", f, "--free", "sigma,W", "--quiet", "--out", d / "o"],
                    capsys, monkeypatch)


bound_text = st.one_of(
    st.builds(lambda k, lo, hi: f"{k}={lo}:{hi}", st.sampled_from(["W", "eps", "sigma", "E_star", "w", "x", ""]),
              st.one_of(number_text, st.sampled_from(["10mJ/m2", "30nm", "1uC/m2", "1e5mJ/m2", "1MPa"])),
              st.one_of(number_text, st.sampled_from(["100mJ/m2", "300nm", "100uC/m2", "1e6mJ/m2", "5MPa"]))),
    st.sampled_from(["W=10mJ/m2", "W=", "W", "=", ",", "W=1:2:3", "W=20mJ/m2:200mJ/m2,W=30mJ/m2:40mJ/m2",
                     "E_star=1MPa:2MPa", "eps=30nm:300nm"]),
    st.text(max_size=60))
CAL_OPTIONS = st.one_of(
    st.tuples(st.just("--bounds"), bound_text),
    st.tuples(st.sampled_from(["--expected-noise", "--nodes", "--zooms", "--refine"]),
              st.one_of(number_text, st.sampled_from(["2%", "0_5%", "-1%", "0.5V", "50mV", "150%", "4", "0_4"]),
                        st.text(max_size=20))))


@SETTINGS(40)
@given(opt=CAL_OPTIONS, eq=st.booleans())
def test_generated_calibrate_options(tmp_path_factory, capsys, monkeypatch, opt, eq):
    d = tmp_path_factory.mktemp("co")
    (d / "d.toml").write_text(CAL_DESIGN)
    (d / "m.csv").write_text("pressure_kPa,voc_V\n2,6.1\n4,6.4\n6,6.6\n8,6.7\n")
    key, value = opt
    given_opt = [f"{key}={value}"] if eq else [key, value]
    check_calibrate(d, ["calibrate", d / "d.toml", "--data", d / "m.csv", "--free", "sigma,W", *given_opt,
                        "--quiet", "--out", d / "o"], capsys, monkeypatch)


# ---- design --material: a material file (as calibrate writes it, or by hand) with hostile values and points ----
material_keys = st.one_of(st.sampled_from(["sigma", "W", "eps", "E_star"]), st.text(max_size=8))
material_value = st.one_of(number_text, st.sampled_from(["-5uC/m2", "1e9C/m2", "abc", "20mJ/m2", "8uC/m2", "50nm",
                                                         "-1MPa", "0uC/m2"]),
                           st.integers(-3, 3), st.booleans(), st.lists(st.integers(), max_size=2))
material_points = st.one_of(st.lists(st.dictionaries(material_keys, material_value, max_size=3), max_size=3),
                            st.sampled_from([5, "x", ["a"], [5]]))


@SETTINGS(30)
@given(values=st.dictionaries(material_keys, material_value, max_size=3), points=material_points,
       table=st.sampled_from(["design", "material", "other"]))
def test_generated_material_files_for_design(tmp_path_factory, capsys, values, points, table):
    """Every material file is refused in one line (exit 2, nothing written) or planned with all its points and then
    refused by the 10 ms budget: never exit 70, never a band point found bad after work was done."""
    d = tmp_path_factory.mktemp("dm")
    text = toml_table(table, values)
    if isinstance(points, list) and all(isinstance(p, dict) for p in points):
        text += "".join(toml_table("uncertainty.point", p).replace("[uncertainty.point]", "[[uncertainty.point]]")
                        for p in points)
    else:
        text += f"[uncertainty]\npoint = {toml_value(points)}\n"
    f = d / "material.toml"
    f.write_text(text)
    rc = check(d, [*DESIGN, "--material", f, "--out", d / "o"], capsys)
    assert rc == 2  # a bad file in one line, or planned (all its points) and refused by the budget
