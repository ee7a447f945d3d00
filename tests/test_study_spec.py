"""Study files: parsing, expansion, point ids, observables settings (no Dask, no physics)."""
import math

import numpy as np
import pytest

from tengsim.errors import TengsimError
from tengsim.study.hashing import point_id
from tengsim.study.spec import parse_study

BASE = {"shape": "pyramid", "N": 0.946, "cell": 3.78, "tabor": 0.5, "dx": 0.2, "d_min": -1.0,
        "d_max": 3.0, "d_step": 0.25, "boundary": "free"}


def study(axes, **extra):
    return parse_study({"base": {"contact": dict(BASE)}, "axes": axes, **extra})


def test_issue_minimal_study_expands_to_full_grid():
    s = study({"contact.N": [0.946, 1.5], "contact.tabor": {"start": 0.3, "stop": 0.5, "num": 2}})
    assert s.is_grid and len(s.points) == 4
    got = sorted((p.contact["N"], p.contact["tabor"]) for p in s.points)
    assert got == [(0.946, 0.3), (0.946, 0.5), (1.5, 0.3), (1.5, 0.5)]
    for p in s.points:  # everything else is the base, unchanged
        assert {k: v for k, v in p.contact.items() if k not in ("N", "tabor")} == \
            {k: v for k, v in BASE.items() if k not in ("N", "tabor")}
    assert s.columns == ["contact.N", "contact.tabor"]
    assert len({p.id for p in s.points}) == 4


def test_point_id_is_deterministic_and_canonical():
    a = dict(BASE)
    b = dict(reversed(list(BASE.items())))
    assert point_id(a) == point_id(b)
    c = dict(BASE, N=1)
    d = dict(BASE, N=1.0)
    assert point_id(c) == point_id(d)
    assert point_id(a) != point_id(c)
    assert len(point_id(a)) == 16


def test_ranges_log_units_and_zip_group():
    s = study({"contact.E_star": {"start": "0.1MPa", "stop": "10MPa", "num": 3, "scale": "log"},
               "group": {"zip": {"contact.N": [0.5, 1.0, 1.5], "contact.cell": [2.0, 4.0, 6.0]},
                         "labels": ["A", "B", "C"]}})
    assert [a.name for a in s.axes] == ["contact.E_star", "group"]
    assert s.axes[0].coord() == ["0.1MPa", "1MPa", "10MPa"]
    assert s.axes[1].coord() == ["A", "B", "C"]
    assert len(s.points) == 9
    for p in s.points:  # zipped members vary together
        assert p.contact["cell"] == 4 * p.contact["N"]
        assert p.axes["group"] == "ABC"[int(p.contact["N"] / 0.5) - 1]
    assert s.columns == ["contact.E_star", "group", "contact.N", "contact.cell"]


@pytest.mark.parametrize("method", ["lhs", "sobol"])
def test_sampling_is_seeded_and_within_bounds(method):
    axes = {"contact.tabor": {"start": 0.2, "stop": 0.8}, "contact.N": {"start": 0.5, "stop": 1.5, "scale": "log"},
            "contact.boundary": ["free", "periodic"]}
    s1 = study(axes, study={"sampling": method, "n": 8, "seed": 3})
    s2 = study(axes, study={"sampling": method, "n": 8, "seed": 3})
    s3 = study(axes, study={"sampling": method, "n": 8, "seed": 4})
    assert len(s1.points) == 8
    assert [p.id for p in s1.points] == [p.id for p in s2.points]
    assert [p.id for p in s1.points] != [p.id for p in s3.points]
    t = np.array([p.contact["tabor"] for p in s1.points])
    assert np.all((t >= 0.2) & (t <= 0.8))
    assert {p.contact["boundary"] for p in s1.points} <= {"free", "periodic"}
    if method == "lhs":  # one sample in each of the 8 strata
        assert sorted(np.floor((t - 0.2) / 0.6 * 8).astype(int)) == list(range(8))


@pytest.mark.parametrize("cfg, msg", [
    ({"base": {"contact": BASE}, "axes": {"contact.N": []}}, "axis 'contact.N' is empty"),
    ({"base": {"contact": BASE}, "axes": {"contact.N": {"start": 1, "stop": 2, "num": 0}}}, "is empty"),
    ({"base": {"contact": BASE}, "axes": {"N": [1.0]}}, "must be named 'table.key'"),
    ({"base": {"contact": BASE}, "axes": {"shape.N": [1.0]}}, "must be named 'table.key'"),
    ({"base": {"contact": BASE}, "axes": {"device.charge": [1.0]}}, "unknown device parameter 'charge'"),
    ({"base": {"contact": BASE}, "axes": {"g": {"zip": {"contact.N": [1, 2], "contact.cell": [4]}}}},
     "different lengths"),
    ({"base": {"contact": BASE}, "axes": {"contact.N": [1.0]}, "bogus": {}}, "unknown table(s) 'bogus'"),
    ({"axes": {"contact.N": [1.0]}}, "needs a [base.contact] table"),
    ({"base": {"contact": BASE}, "study": {"sampling": "lhs"}, "axes": {"contact.N": [1.0]}}, "needs n"),
    ({"base": {"contact": BASE}, "study": {"sampling": "random", "n": 2}}, "not one of grid, lhs, sobol"),
    ({"base": {"contact": BASE}, "axes": {"contact.tabor": {"start": 0.1, "stop": 0.2}}}, "without num"),
    ({"base": {"contact": BASE}, "observables": {"fit_range": ["10kPa", "1kPa"]}}, "fit_range"),
    ({"base": {"contact": BASE}, "observables": {"grid_num": "1MPa"}}, "grid_num"),
])
def test_malformed_study_one_clear_error(cfg, msg):
    with pytest.raises(TengsimError) as e:
        parse_study(cfg)
    assert msg in str(e.value)
    assert "\n" not in str(e.value)


def test_observables_defaults_in_SI():
    s = study({"contact.N": [1.0]})
    o = s.observables
    assert o["pressures"] == [1e3, 1e4, 1e5]
    assert o["pressure_labels"] == ["1kPa", "10kPa", "100kPa"]
    assert o["fit_range"] == [0.0, math.inf]  # the sensor's numbers over each whole run
    assert o["grid_max"] == 1.5e5
    assert s.base["device"] == {"sigma": "5.84uC/m2", "eps_r": 2.40, "thickness": "400um"}
    assert "linear_tolerance" not in o  # one definition of the linear range (tengsim.device.sensor)


# ---- shape axis: per-shape base tables and expressions ---------------------------------------------

SHAPES_BASE = {
    "contact": {"E_star": "0.59MPa", "W": "54mJ/m2", "eps": "0.37um", "pitch": "2um", "dx": "=pitch/12",
                "d_min": -1.0, "d_max": "=1.2*height/eps + 2", "d_step": "=(d_max - d_min)/8"},
    "var": {"aspect": 0.7},
    "shapes": {"pyramid": {"base": "=0.5*pitch", "height": "=aspect*base"},
               "cone": {"slope": "=2*aspect", "height": "=aspect*0.5*pitch"}},
}


def test_shape_axis_merges_its_own_table_and_evaluates_expressions():
    s = parse_study({"base": SHAPES_BASE, "axes": {"contact.shape": ["pyramid", "cone"],
                                                   "var.aspect": [0.5, 1.5]}})
    assert len(s.points) == 4
    for p in s.points:
        c, a = p.contact, p.axes["var.aspect"]
        assert "aspect" not in c and p.tables["var"]["aspect"] == a
        assert c["dx"] == f"{2e-6 / 12:.12g}m"
        if c["shape"] == "pyramid":
            assert set(c) >= {"base", "height"} and "slope" not in c
            assert c["base"] == pytest.approx(1e-6) and c["height"] == pytest.approx(a * 1e-6)
        else:
            assert "base" not in c and c["slope"] == pytest.approx(2 * a)
            assert c["height"] == pytest.approx(a * 1e-6)
        assert c["d_max"] == pytest.approx(1.2 * a * 1e-6 / 0.37e-6 + 2)
        assert c["d_step"] == pytest.approx((c["d_max"] + 1) / 8)
    from tengsim.run.plan import plan_contact

    for p in s.points:  # every point is a valid run of its own shape
        plan_contact(dict(p.contact))


def test_axis_value_beats_the_shape_table():
    s = parse_study({"base": SHAPES_BASE, "axes": {"contact.shape": ["cone"], "contact.slope": [3.0]}})
    assert s.points[0].contact["slope"] == 3.0


@pytest.mark.parametrize("bad, msg", [
    ({"shapes": {"pyramid": {"base": "=0.5*pich"}}}, "unknown name 'pich'"),
    ({"shapes": {"pyramid": {"base": "=__import__('os')"}}}, "only numbers, names"),
    ({"shapes": {"pyramid": {"base": "=base*2"}}}, "depends on itself"),
    ({"shapes": {"blob": {}}}, "blob"),
    ({"shapes": {"cone": {"shape": "line"}}}, "may not set shape"),
    ({"var": {"aspect": "big"}}, "must be a number"),
])
def test_bad_shape_tables_are_study_errors(bad, msg):
    base = {k: dict(v) for k, v in SHAPES_BASE.items()}
    base["shapes"] = {k: dict(v) for k, v in SHAPES_BASE["shapes"].items()}
    for k, v in bad.items():
        if k == "shapes":
            for name, t in v.items():
                base["shapes"][name] = {**base["shapes"].get(name, {}), **t}
        else:
            base[k] = v
    with pytest.raises(TengsimError, match=msg.replace("(", r"\(").replace(")", r"\)")):
        parse_study({"base": base, "axes": {"contact.shape": ["pyramid", "cone"]}})


def test_issue_question_study_file_expands():
    from tengsim.run.plan import plan_contact
    from tengsim.study.spec import load_study

    from pathlib import Path

    s = load_study(Path(__file__).parents[1] / "examples" / "design" / "question.toml")
    shapes = {p.contact["shape"] for p in s.points}
    assert shapes == {"pyramid", "cone", "hemisphere", "line", "cube"}
    for p in s.points:
        plan = plan_contact(dict(p.contact))
        assert plan.scaling is not None and plan.shape.grid(plan.dx).nx == 45


@pytest.mark.parametrize("name", ["minimal", "quick", "pyramids", "patterns", "question"])
def test_example_studies_have_no_invalid_point(name):
    from pathlib import Path

    from tengsim.study.validate import validate
    from tengsim.study.spec import load_study

    s = load_study(Path(__file__).parents[1] / "examples" / "design" / f"{name}.toml")
    valid, invalid = validate(s)
    assert valid and not invalid, invalid
