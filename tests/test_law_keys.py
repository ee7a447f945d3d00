"""A law's own parameters as [contact] keys: TOML, CLI and sweeps give the API's numbers; refusals."""
import csv
import json
from dataclasses import dataclass

import numpy as np
import pytest
import xarray as xr

from tengsim.run.plan import ContactPlan
import tengsim as ts
from tengsim.cli.main import main
from tengsim.run.keys import contact_table, law_fields, law_keys
from tengsim.run.plan import plan_contact
from tengsim.errors import TengsimError
from tengsim.shapes import Paraboloid
from tengsim.laws import LJ93, Exponential, Law, MaugisDugdale
from tengsim.registry import LAWS, SHAPES
from tengsim.study.validate import validate
from tengsim.study.spec import parse_study

# a sphere on a 21 x 21 grid, two D values each way: a fraction of a second a run
RUN = {"shape": "sphere", "radius": 10.0, "cell": 8.0, "dx": 0.5, "tabor": 0.5, "d_min": 0.0, "d_max": 0.5,
       "d_step": 0.5}
CASES = [
    ("md", {"smoothing": 0.4, "wall_stiffness": 3e3}, MaugisDugdale(smoothing=0.4, wall_stiffness=3e3)),
    ("exp", {"range": 0.5}, Exponential(range=0.5)),
]


def _toml(d):
    return "\n".join(f"{k} = {json.dumps(v)}" for k, v in d.items())


def _csv(path):
    head = {}
    for line in open(path):
        if line.startswith("# "):
            k, v = line[2:].split(": ", 1)
            head[k] = json.loads(v)
    rows = list(csv.DictReader(l for l in open(path) if not l.startswith("#")))
    return head, np.array([float(r["F"]) for r in rows])


@pytest.mark.parametrize("law, keys, obj", CASES, ids=[c[0] for c in CASES])
def test_toml_and_cli_law_keys_give_the_api_numbers(law, keys, obj, tmp_path, capsys):
    api = ts.simulate(ContactPlan(Paraboloid(radius=RUN["radius"], cell=RUN["cell"]), 0.5, RUN["dx"], ts.PathSpec(RUN["d_min"], RUN["d_max"], RUN["d_step"]), law=obj))
    default = ts.simulate(ContactPlan(Paraboloid(radius=RUN["radius"], cell=RUN["cell"]), 0.5, RUN["dx"], ts.PathSpec(RUN["d_min"], RUN["d_max"], RUN["d_step"]), law=law))
    assert np.abs(api.table["F"] - default.table["F"]).max() > 1e-4  # the keys change the answer

    toml, nc = tmp_path / "run.toml", tmp_path / "toml.nc"
    toml.write_text(f"[contact]\n{_toml({**RUN, 'law': law, **keys, 'out': str(nc)})}\n")
    assert main(["run", str(toml), "--quiet"]) == 0, capsys.readouterr().err
    ds = xr.load_dataset(nc)
    np.testing.assert_allclose(ds["F"].values, api.table["F"], rtol=1e-12, atol=0)
    stored = json.loads(ds.attrs["params"])  # parameters stored once, as JSON (CF layout)
    for k, v in obj.params().items():  # the resolved law, defaults included, in the file's parameters
        assert stored[k] == v, k

    out = tmp_path / "cli.csv"
    argv = ["contact", "sphere", "--law", law, "--quiet", "--out", str(out)]
    for k, v in {**RUN, **keys}.items():
        if k != "shape":
            argv += ["--" + k.replace("_", "-"), str(v)]
    assert main(argv) == 0, capsys.readouterr().err
    head, F = _csv(out)
    np.testing.assert_allclose(F, api.table["F"], rtol=1e-12, atol=0)
    assert {k: head[k] for k in obj.params()} == obj.params()


def test_law_fields_come_from_the_law_less_its_internal_guards():
    assert [f.name for f in law_fields("md")] == ["tension", "wall_stiffness", "smoothing"]
    assert [f.name for f in law_fields("exponential")] == ["range", "wall_stiffness"]  # an alias
    assert law_fields("lj93") == ()
    assert {f.name: f.default for f in law_fields("md")} == {
        "tension": MaugisDugdale.tension, "wall_stiffness": 1000.0, "smoothing": 0.2}
    assert "g_safe" in MaugisDugdale.internal_fields and "g_safe" not in law_keys()
    # a plan with no law key has the law's own defaults
    assert plan_contact({**RUN, "law": "exp"}).law == Exponential()
    assert plan_contact({**RUN, "law": "md", "tension": 0.5}).law == MaugisDugdale(tension=0.5)
    t = contact_table("sphere", "dimensionless", "md")
    assert t.fields["smoothing"].default == 0.2 and "range" not in t and "W/ε²" in t.fields["wall_stiffness"].help


@pytest.mark.parametrize("cfg, words", [
    ({"smoothing": 0.4}, ["law lj93 has no key 'smoothing'", "its keys: none"]),
    ({"law": "exp", "smoothing": 0.4, "range": 0.5},
     ["law exp has no key 'smoothing'", "its keys: range, wall_stiffness"]),
    ({"law": "repulsive", "wall_stiffness": 1e4}, ["law repulsive has no key 'wall_stiffness'", "scale, exponent"]),
    ({"law": "md", "smoothing": "0.4nm"}, ["smoothing is dimensionless", "'0.4nm'"]),
    ({"law": "md", "wall_stiffness": -1}, ["wall_stiffness must be finite and > 0", "-1"]),
    ({"law": "md", "smoothing": 2.0}, ["smoothing must be smaller than the range"]),
    ({"law": "exp", "range": 0}, ["range must be finite and > 0"]),
    ({"law": "md", "smoothing": True}, ["smoothing must be a number"]),
    ({"law": "md", "smoothing": 0.3, "N": 1.0}, ["shape sphere has no key 'N'"]),
])
def test_law_key_refusals(cfg, words):
    with pytest.raises(TengsimError) as exc:
        plan_contact({**RUN, **cfg})
    msg = str(exc.value)
    assert "\n" not in msg
    for w in words:
        assert w in msg, msg


@pytest.mark.parametrize("keys, words", [
    ({"smoothing": 0.4}, ["law lj93 has no key 'smoothing'"]),
    ({"law": "md", "smoothing": "0.4nm"}, ["smoothing is dimensionless"]),
    ({"law": "md", "wall_stiffness": -5.0}, ["wall_stiffness must be finite and > 0"]),
    ({"law": "exp", "smoothing": 0.1}, ["law exp has no key 'smoothing'", "range, wall_stiffness"]),
])
def test_law_key_refusals_through_cli_and_toml(keys, words, tmp_path, capsys):
    argv = [a for k, v in keys.items() for a in ("--" + k.replace("_", "-"), str(v))]
    out = tmp_path / "x.csv"
    assert main(["contact", "sphere", "--radius", "10", "--cell", "8", *argv, "--quiet", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert all(w in err for w in words), err
    assert list(tmp_path.iterdir()) == []
    # the same table from a TOML file: refused the same way, nothing written
    toml = tmp_path / "bad.toml"
    toml.write_text(f"[contact]\n{_toml({**RUN, **keys, 'out': str(out)})}\n")
    assert main(["run", str(toml), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and all(w in err for w in words), err
    assert not out.exists()


def test_contact_help_lists_every_law_key(capsys):
    with pytest.raises(SystemExit):
        main(["contact", "--help"])
    out = " ".join(capsys.readouterr().out.split())
    for name in LAWS.names():
        for f in law_fields(name):
            assert "--" + f.name.replace("_", "-") in out
    assert "--g-safe" not in out
    assert "W/ε²" in out and "law md: default 0.2" in out and "law md: default 1000, exp: default 1000" in out


def test_sweep_over_a_law_key_validates():
    base = {**RUN, "law": "md"}
    s = parse_study({"base": {"contact": base}, "axes": {"contact.smoothing": [0.2, 0.4]}})
    valid, invalid = validate(s)
    assert not invalid and len(valid) == 2
    assert sorted(plan_contact(dict(c)).law.smoothing for c in valid.values()) == [0.2, 0.4]
    # a bad value is one invalid point with the law's message; the others run
    s = parse_study({"base": {"contact": base}, "axes": {"contact.smoothing": [0.2, 2.0]}})
    valid, invalid = validate(s)
    assert len(valid) == 1 and len(invalid) == 1
    assert "smoothing must be smaller than the range" in next(iter(invalid.values()))
    # a key the law lacks at every point is a study error
    s = parse_study({"base": {"contact": {**RUN}}, "axes": {"contact.smoothing": [0.2, 0.4]}})
    with pytest.raises(TengsimError, match="law lj93 has no key 'smoothing'"):
        validate(s)
    # a law axis with its keys: the exp point has no smoothing
    s = parse_study({"base": {"contact": {**RUN, "smoothing": 0.3}}, "axes": {"contact.law": ["md", "exp"]}})
    valid, invalid = validate(s)
    assert len(valid) == 1 and "law exp has no key 'smoothing'" in next(iter(invalid.values()))


@pytest.fixture
def clashing_law():
    names = []

    def register(name, field):
        cls = dataclass(frozen=True)(type(name, (Law,), {"__annotations__": {field: float, "g_safe": float},
                                                          field: 1.0, "g_safe": 0.6,
                                                          "_raw": lambda self, g, need_dp=True: LJ93()._raw(g)}))
        LAWS.register(name, cls)
        names.append(name)
        return cls

    yield register
    for n in names:
        if n in LAWS:
            LAWS.unregister(n)


def test_a_law_key_clashing_with_another_key_is_a_schema_error(clashing_law):
    clashing_law("clash_tol", "tol")
    with pytest.raises(TengsimError, match="law clash_tol field 'tol' clashes"):
        contact_table("sphere")
    LAWS.unregister("clash_tol")
    clashing_law("clash_radius", "radius")
    assert "sphere" in SHAPES
    with pytest.raises(TengsimError, match="law clash_radius field 'radius' clashes with the key of that name of "
                                           "shape sphere"):
        plan_contact(dict(RUN))


def test_docs_name_every_built_in_law_key():
    from pathlib import Path

    text = (Path(__file__).parents[1] / "docs" / "validation.md").read_text(encoding="utf-8")
    for name in ("lj93", "repulsive", "md", "exp"):
        for f in law_fields(name):
            assert f"`{f.name}`" in text, f"docs/validation.md does not name law {name}'s key {f.name}"
