"""Units right everywhere: a study expression's SI value gets the key's own unit (every dimensional key,
literal vs expression give the same run), expressions are dimension-checked, and a bare number on a
dimensional key of a physical run outside the plausible range of its quantity is refused with one line."""
import dataclasses
import math

import numpy as np
import pytest

from tengsim.cli.main import main
from tengsim.run.keys import X_UNIT_KEYS
from tengsim.run.plan import plan_contact
from tengsim.run.simulate import simulate as run_contact
from tengsim.errors import ConfigValueError, TengsimError
from tengsim.plugins import SHAPES
from tengsim.shapes.base import physical_fields
from tengsim.study.spec import parse_study
from tengsim.units import PLAUSIBLE, check_plausible, parse_quantity

GROUP_A = {"shape": "pyramid", "pitch": "2um", "base": "1um", "height": "0.7um", "E_star": "0.59MPa",
           "W": "54mJ/m2", "tabor": 0.5, "dx": 0.1, "d_min": -1.0, "d_max": 4.0, "d_step": 0.1,
           "boundary": "periodic"}


def _point(contact, var=None):
    base = {"contact": contact}
    if var:
        base["var"] = var
    return dict(parse_study({"base": base}).points[0].contact)


# ---- the issue's case: a real computed pull-off -----------------------------------------------------

def test_thickness_expression_gives_the_literal_pull_off():
    """Issue 21: group A, periodic, on a film; thickness "=200*pitch" (pitch 2 µm) is the 400 µm film, not
    0.0004 X units (what it was: pull-off −0.274 instead of −1.074 on this grid)."""
    lit = _point({**GROUP_A, "thickness": "400um"})
    expr = _point({**GROUP_A, "thickness": "=200*pitch"})
    assert expr["thickness"] == "0.0004m"
    a, b = run_contact(lit), run_contact(expr)
    assert b.pull_off_force == pytest.approx(a.pull_off_force, rel=1e-9, abs=1e-12)
    assert a.pull_off_force < -1.0  # the 400 µm film (half-space-like), not a 0.8 nm one
    np.testing.assert_allclose(b.table["F"], a.table["F"], rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(b.table["area_repulsive"], a.table["area_repulsive"], rtol=1e-9, atol=1e-12)


# ---- every dimensional key: literal vs expression, plan-level ---------------------------------------

def _same(a, b, path="plan"):
    """Recursive equality of two plans' pieces, floats to 1e-10 relative."""
    if dataclasses.is_dataclass(a) and not isinstance(a, type):
        assert type(a) is type(b), path
        for f in dataclasses.fields(a):
            if f.name == "config":  # the table as written (kept for the result's parameters): the same keys
                assert set(a.config) == set(b.config), (path, set(a.config) ^ set(b.config))
                continue
            _same(getattr(a, f.name), getattr(b, f.name), f"{path}.{f.name}")
    elif isinstance(a, dict):
        assert set(a) == set(b), (path, set(a) ^ set(b))
        for k in a:
            _same(a[k], b[k], f"{path}[{k!r}]")
    elif isinstance(a, (list, tuple)):
        assert len(a) == len(b), path
        for i, (x, y) in enumerate(zip(a, b)):
            _same(x, y, f"{path}[{i}]")
    elif hasattr(a, "__dict__") and not callable(a):  # a shape that is not a dataclass (the array)
        assert type(a) is type(b), path
        _same(vars(a), vars(b), path)
    elif isinstance(a, np.ndarray):
        np.testing.assert_allclose(a, b, rtol=1e-10, atol=0, err_msg=path)
    elif isinstance(a, float) and not isinstance(a, bool):
        assert b == pytest.approx(a, rel=1e-10, abs=0), path
    else:
        assert a == b, path


UNITS = {"E_star": "0.59MPa", "W": "54mJ/m2"}
BASES = {  # shape: a physical [contact] table whose lengths are all literals with units
    "pyramid": {"pitch": "2um", "base": "1um", "height": "0.7um"},
    "sphere": {"radius": "2um", "pitch": "0.4um"},
    "cone": {"slope": 0.4, "pitch": "1um", "height": "0.2um"},
    "hemisphere": {"radius": "1um", "pitch": "3um"},
    "flat_punch": {"radius": "0.3um", "step": "0.05um", "pitch": "1um"},
    "cube": {"half_width": "0.3um", "height": "0.2um", "pitch": "1um"},
    "line": {"half_width": "0.3um", "height": "0.2um", "pitch": "1um"},
    "sinusoid": {"wavelength": "2um", "amplitude": "0.2um"},
    "rough": {"cell": "2um", "rms_height": "0.1um", "short_cutoff": "0.25um", "long_cutoff": "1um",
              "boundary": "periodic"},
    "array": {"pattern": "pyramid", "K": 2, "pitch": "2um", "base": "1um", "height": "0.7um", "waviness": "10nm"},
}
NOT_EXPRESSIONS = {("topography", "physical_size")}  # a list (two lengths): no expression reads it


def _length_cases():
    out = []
    for shape, keys in BASES.items():
        lengths = [k for k, v in keys.items() if isinstance(v, str) and v.endswith("m")]
        for k in lengths:
            ref = next(r for r in lengths if r != k)
            ratio = parse_quantity(keys[k]) / parse_quantity(keys[ref])
            out.append((shape, k, f"={ratio!r}*{ref}", None))
    return out


def _common_cases():
    pa = {"shape": "pyramid", **BASES["pyramid"]}
    k_E = 0.59e6 * 2e-6 / 0.054  # E* = W/pitch · k: J/m² / m is a pressure
    k_W = 0.054 / (0.59e6 * 2e-6)  # W = E* · pitch · k: Pa · m is an energy per area
    return [
        ("pyramid", "E_star", f"=W/pitch*{k_E!r}", None),
        ("pyramid", "E_star", "=E0*1e6", {"E0": 0.59}),  # a [var] is a plain number: read as SI
        ("pyramid", "W", f"=E_star*pitch*{k_W!r}", None),
        ("pyramid", "eps", "=0.185*pitch", None),
        ("pyramid", "dx", "=pitch/20", None),
        ("pyramid", "thickness", "=200*pitch", None),
        ("pyramid", "f_min", "=-f_step", None),
        ("pyramid", "f_max", "=2*f_step", None),
        ("pyramid", "f_step", "=f_max/2", None),
        ("pyramid", "f_step", "=E_star/295", None),
    ], pa


LITERAL = {"eps": "0.37um", "dx": "0.1um", "thickness": "400um", "f_min": "-2kPa", "f_max": "4kPa",
           "f_step": "2kPa"}


def _table(shape, key):
    t = {"shape": shape, **BASES[shape], **UNITS, "tabor": 0.8}
    if shape in ("pyramid", "array"):
        t["tabor"] = 0.5
    if key == "eps":
        t.pop("tabor")
        t["eps"] = LITERAL["eps"]
    if key == "dx":
        t["dx"] = LITERAL["dx"]
    if key == "thickness":
        t.update(thickness=LITERAL["thickness"], boundary="periodic")
    if key.startswith("f_"):
        t.update(control="load", f_min=LITERAL["f_min"], f_max=LITERAL["f_max"], f_step=LITERAL["f_step"])
    return t


CASES = _length_cases() + _common_cases()[0]


@pytest.mark.parametrize("shape, key, expr, var", CASES, ids=[f"{c[0]}-{c[1]}-{i}" for i, c in enumerate(CASES)])
def test_every_dimensional_key_literal_equals_expression(shape, key, expr, var):
    lit = _table(shape, key)
    ex = {**lit, key: expr}
    point = _point(ex, var)
    if key in X_UNIT_KEYS:  # a bare number here is X units or F: the SI value carries its unit
        assert isinstance(point[key], str) and point[key].endswith("m" if X_UNIT_KEYS[key] == "length" else "Pa")
    else:  # a bare number here is SI
        assert isinstance(point[key], float)
    assert parse_quantity(point[key]) == pytest.approx(parse_quantity(lit[key]), rel=1e-10)
    _same(plan_contact(dict(lit)), plan_contact(point))


def test_the_cases_cover_every_dimensional_key():
    """Every registered shape's physical length key and every [contact] quantity key is run above."""
    shapes = {(s, f.name) for s in SHAPES.names() for f in physical_fields(SHAPES.get(s)) if f.dim}
    covered = {(s, k) for s, k, _, _ in CASES}
    array_pattern_keys = {("array", f.name) for f in physical_fields(SHAPES.get("array"))
                          if f.dim and f.name not in BASES["array"]}  # the other patterns' keys: as their shapes
    assert shapes - covered - NOT_EXPRESSIONS - array_pattern_keys == set()
    for s, k in array_pattern_keys:
        assert any(c == k for (_, c) in covered), k
    assert {"E_star", "W", "eps", *X_UNIT_KEYS} <= {k for _, k, _, _ in CASES}


def test_dimensionless_runs_keep_plain_numbers():
    """A dimensionless run's expressions are plain numbers in X units (dx no longer gets 'm')."""
    c = _point({"shape": "pyramid", "N": 0.946, "cell": 3.78, "dx": "=cell/40", "thickness": "=10*cell",
                "d_max": "=d_min + 3", "d_min": -1.0, "control": "load", "f_max": "=0.2", "f_step": "=f_max/4"})
    assert c["dx"] == pytest.approx(3.78 / 40) and c["thickness"] == pytest.approx(37.8)
    assert c["f_step"] == pytest.approx(0.05) and c["d_max"] == 2.0
    plan = plan_contact(c)
    assert plan.dx == pytest.approx(3.78 / 40) and plan.kernel_params["thickness"] == pytest.approx(37.8)
    assert plan.scaling is None
    # and a bare number there is never checked for plausibility (X units, not SI)
    plan_contact({"shape": "pyramid", "N": 0.946, "cell": 3.78, "thickness": 4000.0})


@pytest.mark.parametrize("bad, msg", [
    ({"d_max": "=2*eps", "eps": "0.37um", "tabor": None}, "d_max = '=2*eps' is a length, but d_max takes a plain"),
    ({"dx": "=E_star/2"}, "dx = '=E_star/2' is a pressure, but dx takes a length"),
    ({"thickness": "=pitch + E_star"}, "adds a length and a pressure"),
    ({"E_star": "=pitch*2"}, "is a length, but E_star takes a pressure"),
    ({"W": "=E_star"}, "is a pressure, but W takes a energy/area"),
    ({"control": "load", "f_step": 0.1, "f_max": "=2*f_step"}, "f_step = 0.1 is in units of F"),
    ({"thickness": 3.0, "dx": "=thickness/40"}, "thickness = 3.0 is in X units, not SI"),
    ({"dx": 0.1, "thickness": "=200*dx"}, "dx = 0.1 is in X units"),
])
def test_expressions_of_the_wrong_dimension_are_refused(bad, msg):
    with pytest.raises(TengsimError, match=msg.replace("(", r"\(").replace("*", r"\*")) as e:
        _point({**GROUP_A, **bad})
    assert "\n" not in str(e.value)


def test_plain_numbers_added_to_a_quantity_are_si_and_ratios_are_plain():
    c = _point({**GROUP_A, "height": "=base - 3e-7", "d_max": "=1.2*height/pitch + 2*tabor"})
    assert c["height"] == pytest.approx(0.7e-6) and c["d_max"] == pytest.approx(1.2 * 0.7 / 2 + 1)
    with pytest.raises(TengsimError, match="is a length, but d_max takes a plain number"):
        _point({**GROUP_A, "d_max": "=1.2*height/(tabor*1e-6) + 2"})  # tabor is a plain number


# ---- bare numbers on dimensional keys: plausibility -------------------------------------------------

PHYS = {"shape": "pyramid", "pitch": "2um", "base": "1um", "height": "0.7um", "E_star": "0.59MPa",
        "W": "54mJ/m2", "tabor": 0.5}


@pytest.mark.parametrize("key, value, likely", [
    ("E_star", 0.59, "'0.59MPa'"),
    ("E_star", "0.59", "'0.59MPa'"),  # what the CLI passes
    ("E_star", 5e13, None),
    ("W", 54, "'54mJ/m2'"),
    ("W", 5e-8, None),
    ("pitch", 2, "'2um'"),
    ("height", 1e-13, None),
])
def test_implausible_bare_numbers_are_refused(key, value, likely):
    with pytest.raises(ConfigValueError) as e:
        plan_contact({**PHYS, key: value})
    msg = str(e.value)
    assert "\n" not in msg and msg.startswith(f"{key} = ") and "implausible" in msg
    if likely:
        assert f"e.g. {likely}" in msg
    else:
        assert "e.g." not in msg
    with pytest.raises(ConfigValueError):  # the same through run_contact (the API)
        run_contact({**PHYS, key: value})


def test_issue_message_for_E_star():
    with pytest.raises(ConfigValueError) as e:
        plan_contact({**PHYS, "E_star": 0.59})
    assert str(e.value) == ("E_star = 0.59 is read as 0.59 Pa (a bare number is SI), implausible for a modulus "
                            "(100 to 1e+12 Pa): give it with its unit, e.g. '0.59MPa'")


def test_plausible_bare_numbers_and_any_unit_string_pass():
    a = plan_contact({**PHYS, "E_star": 0.59e6, "W": 0.054, "pitch": 2e-6, "base": 1e-6, "height": 0.7e-6})
    b = plan_contact(dict(PHYS))
    _same(a, b)
    plan_contact({**PHYS, "E_star": "5000GPa", "dx": "0.05um", "boundary": "periodic"})  # a unit: as given
    plan_contact({**PHYS, "E_star": "1e12", "dx": "0.05um", "boundary": "periodic"})  # the edges are inside
    plan_contact({**PHYS, "E_star": 100, "W": 10, "dx": "0.1um"})


def test_plausibility_table():
    assert PLAUSIBLE["modulus"][:2] == (100.0, 1e12) and PLAUSIBLE["energy/area"][:2] == (1e-6, 10.0)
    assert PLAUSIBLE["length"][:2] == (1e-12, 1.0) and PLAUSIBLE["pressure"][1] == 1e10
    assert check_plausible("p", -2e9, "pressure") == -2e9
    with pytest.raises(ConfigValueError, match="p = -2e\\+10 is read as -2e\\+10 Pa"):
        check_plausible("p", -2e10, "pressure")
    assert check_plausible("x", 0.0, "length") == 0.0  # zero: each key's own check
    assert check_plausible("x", 1e9, "frequency") == 1e9  # not in the table
    assert math.isnan(check_plausible("x", math.nan, "length"))


def test_an_expression_value_is_checked_like_a_bare_number():
    """A [var] is a plain number: E0 = 0.59 meant as MPa gives 0.59 Pa, refused."""
    c = _point({**GROUP_A, "E_star": "=E0"}, {"E0": 0.59})
    with pytest.raises(ConfigValueError, match="E_star = 0.59 is read as 0.59 Pa"):
        plan_contact(c)


# ---- the command line: one line, exit 2, nothing written --------------------------------------------

def test_toml_run_refuses_a_bare_modulus(tmp_path, capsys):
    out = tmp_path / "r.csv"
    f = tmp_path / "r.toml"
    f.write_text('[contact]\nshape = "pyramid"\npitch = "2um"\nbase = "1um"\nheight = "0.7um"\nE_star = 0.59\n'
                 f'W = "54mJ/m2"\ntabor = 0.5\nout = "{out}"\n')
    assert main(["run", str(f), "--quiet"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "E_star = 0.59" in err and "'0.59MPa'" in err, err
    assert not out.exists()


def test_contact_cli_refuses_a_bare_work_of_adhesion(tmp_path, capsys):
    out = tmp_path / "c.csv"
    rc = main(["contact", "pyramid", "--pitch", "2um", "--base", "1um", "--height", "0.7um", "--E-star", "0.59MPa",
               "--W", "54", "--tabor", "0.5", "--out", str(out), "--quiet"])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and len(err.splitlines()) == 1 and "W = 54" in err and "'54mJ/m2'" in err, err
    assert not out.exists()


def test_sweep_refuses_a_bare_modulus_and_a_wrong_dimension(tmp_path, capsys):
    text = """
[base.contact]
shape = "pyramid"
pitch = "2um"
base = "1um"
height = "0.7um"
W = "54mJ/m2"
tabor = 0.5
dx = 0.3
d_max = 1.0
d_step = 0.5
[axes]
"contact.E_star" = [0.59, 1.2]
"""
    f = tmp_path / "s.toml"
    f.write_text(text)
    assert main(["sweep", str(f), "--out", str(tmp_path / "o"), "--quiet"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "E_star = 0.59" in err and "implausible" in err, err
    assert not (tmp_path / "o").exists()
    g = tmp_path / "t.toml"
    g.write_text(text.replace("[0.59, 1.2]", '["0.59MPa", "1.2MPa"]').replace("d_max = 1.0", 'd_max = "=2*pitch"'))
    assert main(["sweep", str(g), "--out", str(tmp_path / "o2"), "--quiet"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "d_max = '=2*pitch' is a length" in err, err
    assert not (tmp_path / "o2").exists()
