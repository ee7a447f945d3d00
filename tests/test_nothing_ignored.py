"""Nothing accepted and silently ignored (issue 21, item 4).

The registry is walked: for every registered shape, in each of its input modes (dimensionless,
physical), every key its [contact] table accepts either changes the plan (the gap U0 on its grid, the
grid, the scaling, the path, the kernel, the law, ...) when changed from a valid table's value, or is
refused with one line where the shape variant does not use it, or is declared metadata by the shape
(``metadata_fields``).  A key added later without a case here fails ``test_every_key_has_a_case``:
give it a changed value below (and it must then change the plan) or declare it.

Everything runs at plan level (:func:`tengsim.run.plan.plan_contact`, ``shape.gap(grid)``): no solve.
"""
from __future__ import annotations

import numpy as np
import pytest

from tengsim.run.keys import common_fields, contact_table, law_fields, law_keys
from tengsim.run.plan import plan_contact
from tengsim.errors import TengsimError
from tengsim.plugins import LAWS, SHAPES
from tengsim.shapes.roughened import roughness_fields

DX = 0.5
GPA = {"E_star": "1GPa", "W": "50mJ/m2", "tabor": 0.5}
PAPER = {"E_star": "0.59MPa", "W": "54mJ/m2", "tabor": 0.5}

# per (shape, mode): a small valid table of the shape's own keys (physical: with E_star, W, tabor), and a
# changed value of each of its own keys.  Grids stay below 60 x 60 at dx = 0.5.
SHAPE_CASES = {
    ("pyramid", "dimensionless"): ({"N": 0.946, "cell": 3.78}, {"N": 0.8, "cell": 4.0}),
    ("pyramid", "physical"): ({"pitch": "2um", "base": "1um", "height": "0.7um", **PAPER},
                              {"pitch": "2.2um", "base": "0.9um", "height": "0.6um"}),
    ("sphere", "dimensionless"): ({"radius": 10.0, "cell": 8.0}, {"radius": 5.0, "cell": 6.0}),
    ("sphere", "physical"): ({"radius": "1um", "pitch": "0.3um", **GPA}, {"radius": "1.5um", "pitch": "0.25um"}),
    ("cone", "dimensionless"): ({"slope": 1.0, "cell": 8.0}, {"slope": 0.5, "cell": 6.0, "height": 2.0}),
    ("cone", "physical"): ({"slope": 0.5, "pitch": "5nm", **GPA}, {"slope": 0.8, "pitch": "4nm", "height": "1nm"}),
    ("hemisphere", "dimensionless"): ({"radius": 3.0, "cell": 10.0}, {"radius": 2.0, "cell": 8.0, "k": 2.0}),
    ("hemisphere", "physical"): ({"radius": "0.1um", "pitch": "0.3um", **GPA},
                                 {"radius": "0.12um", "pitch": "0.35um"}),
    ("flat_punch", "dimensionless"): ({"radius": 1.0, "cell": 6.0}, {"radius": 1.5, "cell": 5.0, "step": 20.0}),
    ("flat_punch", "physical"): ({"radius": "0.2nm", "pitch": "0.8nm", **GPA},
                                 {"radius": "0.25nm", "pitch": "1nm", "step": "3nm"}),
    ("cube", "dimensionless"): ({"half_width": 1.0, "height": 5.0, "cell": 6.0},
                                {"half_width": 1.5, "height": 3.0, "cell": 5.0}),
    ("cube", "physical"): ({"half_width": "0.2nm", "height": "0.7nm", "pitch": "0.9nm", **GPA},
                           {"half_width": "0.25nm", "height": "0.5nm", "pitch": "1nm"}),
    ("line", "dimensionless"): ({"half_width": 1.0, "height": 5.0, "cell": 6.0},
                                {"half_width": 1.5, "height": 3.0, "cell": 5.0}),
    ("line", "physical"): ({"half_width": "0.2nm", "height": "0.7nm", "pitch": "0.9nm", **GPA},
                           {"half_width": "0.25nm", "height": "0.5nm", "pitch": "1nm"}),
    ("sinusoid", "dimensionless"): ({"wavelength": 10.0, "amplitude": 1.0}, {"wavelength": 8.0, "amplitude": 2.0}),
    ("sinusoid", "physical"): ({"wavelength": "1.4nm", "amplitude": "0.14nm", **GPA},
                               {"wavelength": "1.2nm", "amplitude": "0.3nm"}),
    # the rough surface refuses boundary = 'free' (PERIODIC_ONLY); its default short cut-off (cell/32) is below
    # 2 pixels at dx = 0.5, so the base tables give one
    ("rough", "dimensionless"): ({"cell": 8.0, "short_cutoff": 1.5, "boundary": "periodic"},
                                 {"cell": 10.0, "hurst": 0.5, "rms_height": 2.0, "rms_slope": 0.3, "short_cutoff": 2.0,
                                  "long_cutoff": 4.0, "seed": 1}),
    ("rough", "physical"): ({"cell": "3nm", "short_cutoff": "0.3nm", "boundary": "periodic", **GPA},
                            {"cell": "3.5nm", "hurst": 0.6, "rms_height": "0.2nm", "rms_slope": 0.3,
                             "short_cutoff": "0.4nm", "long_cutoff": "2nm", "seed": 2}),
}
PERIODIC_ONLY = {"rough"}  # shapes that refuse boundary = 'free' with one line (their base tables are periodic)
SPECIAL = {"array", "topography"}  # their cases are built below (a pattern per array; files for a topography)

# the array's own keys: (context that makes the key apply, changed value); the pattern's keys are walked
# per pattern from SHAPE_CASES
ARRAY_OWN = {
    "dimensionless": {"K": ({}, 3), "scatter_height": ({}, 0.1), "scatter_size": ({}, 0.05),
                      "scatter_tilt": ({}, 0.1), "waviness_amplitude": ({}, 0.5),
                      "seed": ({"scatter_height": 0.1}, 1), "distribution": ({"scatter_height": 0.1}, "uniform"),
                      "waviness_wavelength": ({"waviness_amplitude": 0.5}, 2.0)},
    "physical": {"K": ({}, 3), "scatter_height": ({}, 0.1), "scatter_size": ({}, 0.05), "tilt": ({}, 0.1),
                 "waviness": ({}, "0.2um"), "seed": ({"scatter_height": 0.1}, 1),
                 "distribution": ({"scatter_height": 0.1}, "uniform"),
                 "waviness_wavelength": ({"waviness": "0.2um"}, 2.0)},
}
# keys of the array refused where they do not apply: (table additions, words of the one-line refusal)
ARRAY_UNUSED = {
    "dimensionless": [({"seed": 3}, "seed applies only with a scatter"),
                      ({"distribution": "uniform"}, "distribution applies only with a scatter"),
                      ({"seed": 3, "distribution": "uniform", "scatter_height": 0.0}, "seed and distribution apply"),
                      ({"waviness_wavelength": 2.0}, "waviness_wavelength applies only with a waviness")],
    "physical": [({"seed": 3}, "seed applies only with a scatter"),
                 ({"waviness_wavelength": 2.0}, "waviness_wavelength applies only with a waviness (waviness > 0)")],
}

# keys every shape has: (context that makes the key apply, changed value); physical runs get E_star, W and
# eps from the base plan's scaling (below)
COMMON = {
    "tabor": ({}, 0.7), "dx": ({}, 0.25), "d_min": ({}, -0.5), "d_max": ({}, 3.0), "d_step": ({}, 0.1),
    "refine_levels": ({}, 2), "maps_at": ({}, [0.5]), "control": ({}, {"control": "load", "f_max": 1.0, "f_step": 0.5}),
    "f_min": ({"control": "load", "f_max": 1.0, "f_step": 0.5}, -0.5),
    "f_max": ({"control": "load", "f_max": 1.0, "f_step": 0.5}, 1.5),
    "f_step": ({"control": "load", "f_max": 1.0, "f_step": 0.5}, 0.25),
    "adaptive": ({}, True), "adapt_tol": ({"adaptive": True}, 0.1), "boundary": ({}, "periodic"),
    "thickness": ({}, 5.0), "substrate": ({"thickness": 5.0}, "frictionless"),
    "poisson": ({"thickness": 5.0}, 0.3), "solver": ({}, "vsr"), "tol": ({}, 1e-5), "law": ({}, "md"),
    "symmetry": ({}, "off"),
    "observers": ({}, ["array_area"]),
    "resolve": ({}, "auto"), "resolve_tol": ({"resolve": "auto"}, 0.05), "max_pixels": ({"resolve": "auto"}, 10000),
}
# [contact] keys that are not the run's: the CLI's output files (`tengsim run` reads them; out must be .nc
# when maps are asked for, test_maps_need_a_nc_output)
OUTPUTS = {"out", "plot", "shape"}
# the roughness superimposed on a shape (tengsim.shapes.roughened): walked per shape by
# test_roughness_keys_change_the_gap_or_are_refused (its cut-offs depend on the shape's cell and grid)
ROUGHNESS = {f.name for f in roughness_fields()}
# common keys refused where they do not apply: (table additions, words)
COMMON_UNUSED = [
    ({"f_max": 1.0}, "f_max does not apply to control = 'approach'"),
    ({"adapt_tol": 0.1}, "adapt_tol applies only with adaptive = true"),
    ({"control": "load", "f_max": 1.0, "f_step": 0.5, "adapt_tol": 0.1}, "adapt_tol does not apply to control"),
    ({"substrate": "frictionless"}, "give its thickness too"),
    ({"poisson": 0.3}, "give its thickness too"),
    ({"maps_at": [9.0]}, "maps_at D = 9 is outside the path's D range [-1, 4]"),
    ({"resolve_tol": 0.05}, "resolve_tol applies only with resolve = 'auto'"),
    ({"max_pixels": 10000}, "max_pixels applies only with resolve = 'auto'"),
    ({"resolve_pressures": "5kPa"}, "resolve_pressures applies only with resolve = 'auto'"),
    ({"control": "load", "f_max": 1.0, "f_step": 0.5, "maps_at": [2.0]}, "maps_at load F = 2 is outside"),
]


def _modes(name):
    cls = SHAPES.get(name)
    from tengsim.shapes.base import dimensionless_fields, physical_fields

    return [m for m, f in (("dimensionless", dimensionless_fields), ("physical", physical_fields)) if f(cls)]


def _own_keys(name, mode):
    skip = {f.name for f in common_fields()} | set(law_keys())
    return [k for k in contact_table(name, mode).keys() if k not in skip]


def _sig(plan) -> dict:
    """What a run is built from: the gap on its grid and everything else the plan holds."""
    g = plan.shape.grid(plan.dx)
    return {"grid": (g.nx, g.ny, g.dx, g.dy), "U0": plan.shape.gap(g), "tabor": plan.tabor, "path": plan.path,
            "boundary": plan.boundary, "solver": plan.solver, "tol": plan.solver_tol, "law": repr(plan.law),
            "symmetry": plan.symmetry,
            "observers": plan.observers, "kernel": plan.kernel_params, "resolve": plan.resolve,
            "scaling": None if plan.scaling is None else plan.scaling.params()}


def _changed(a, b) -> list:
    out = []
    for k in a:
        x, y = a[k], b[k]
        same = (x.shape == y.shape and np.array_equal(x, y)) if isinstance(x, np.ndarray) else x == y
        if not same:
            out.append(k)
    return out


def _table(name, base, /, **more):
    cfg = {"shape": name, **base, **more}
    return {k: v for k, v in cfg.items() if v is not None}


def _assert_changes(name, base, key, ctx, value):
    """Changing ``key`` to ``value`` (in context ``ctx``) changes the plan of the table ``base``."""
    ref = plan_contact(_table(name, base, **ctx))
    alt = value if isinstance(value, dict) else {key: value}
    new = plan_contact(_table(name, base, **{**ctx, **alt}))
    assert _changed(_sig(ref), _sig(new)), f"shape {name}: {key} = {value!r} changes nothing in the plan"


def _base(name, mode):
    base, _ = SHAPE_CASES[(name, mode)]
    return {**base, "dx": DX}


def _scaled(base_plan):
    """Changed E_star, W, eps of a physical run (SI numbers and a length), from its scaling."""
    s = base_plan.scaling
    return {"E_star": ({}, 1.3 * s.E_star), "W": ({}, 1.3 * s.W), "eps": ({}, {"eps": f"{1.2 * s.eps}m",
                                                                               "tabor": None})}


# ---- the walk --------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """Text height maps in metres (no unit, no size), one with a missing pixel, and a NetCDF file written by
    SurfaceTopography with its own size and unit."""
    d = tmp_path_factory.mktemp("topo")
    rng = np.random.default_rng(0)
    x = np.arange(8)
    tilt = 2e-10 * x[:, None] + 1e-10 * x[None, :]
    a = 2e-10 * rng.standard_normal((8, 8)) + tilt
    np.savetxt(d / "a.txt", a)
    np.savetxt(d / "b.txt", 2e-10 * rng.standard_normal((8, 8)) + tilt)
    c = a.copy()
    c[3, 3] = np.nan
    np.savetxt(d / "c.txt", c)
    import SurfaceTopography as st

    st.Topography(a * 1e9, (1.5, 1.5), unit="nm", periodic=True).to_netcdf(str(d / "s.nc"))
    return d


def _topo_base(files):
    return {"file": str(files / "a.txt"), "physical_size": "1.5nm", **GPA}


def _topo_own(files):
    return {"file": ({}, str(files / "b.txt")), "physical_size": ({}, "2nm"), "unit": ({}, "nm"),
            "detrend": ({}, "none"), "fill_missing": ({"file": str(files / "c.txt")}, None)}


CASES = [(name, mode) for name in SHAPES.names() for mode in _modes(name)]


@pytest.mark.parametrize("name, mode", CASES, ids=[f"{n}-{m}" for n, m in CASES])
def test_every_key_has_a_case(name, mode, files):
    """Every key a registered shape accepts, and every common key, is exercised here or declared."""
    meta = set(getattr(SHAPES.get(name), "metadata_fields", {}) or {})
    if name == "array":
        pattern_keys = {k for (p, m), (b, alt) in SHAPE_CASES.items() if m == mode for k in (*b, *alt)}
        covered = set(ARRAY_OWN[mode]) | pattern_keys | {"pattern"}
    elif name == "topography":
        covered = set(_topo_own(files))
    else:
        assert (name, mode) in SHAPE_CASES, f"new shape {name} ({mode}): add a case to SHAPE_CASES"
        base, alt = SHAPE_CASES[(name, mode)]
        covered = set(base) | set(alt)
    missing = [k for k in _own_keys(name, mode) if k not in covered | meta]
    assert not missing, (f"shape {name} ({mode}) accepts {missing} but this test has no case for them: give "
                         "each a changed value (it must change the plan) or declare it in metadata_fields")
    common = {f.name for f in common_fields()}
    assert common <= set(COMMON) | OUTPUTS | ROUGHNESS | {"E_star", "W", "eps", "resolve_pressures"}, \
        f"common keys without a case: {sorted(common - set(COMMON) - OUTPUTS - ROUGHNESS)}"


@pytest.mark.parametrize("name, mode", [c for c in CASES if c[0] not in SPECIAL],
                         ids=[f"{n}-{m}" for n, m in CASES if n not in SPECIAL])
def test_each_shape_key_changes_the_plan(name, mode):
    base = _base(name, mode)
    for key, value in SHAPE_CASES[(name, mode)][1].items():
        _assert_changes(name, base, key, {}, value)


@pytest.mark.parametrize("name, mode", CASES, ids=[f"{n}-{m}" for n, m in CASES])
def test_each_common_key_changes_the_plan(name, mode, files):
    if name == "topography":
        base = _topo_base(files)
    elif name == "array":
        base = {"K": 2, **_base("pyramid", mode)}
    else:
        base = _base(name, mode)
    cases = dict(COMMON)
    if mode == "physical":
        cases.update(_scaled(plan_contact(_table(name, base))))
        cases["tabor"] = ({}, 0.6)
        cases["resolve_pressures"] = ({"resolve": "auto"}, "5kPa")  # physical runs only (refused below)
    else:
        with pytest.raises(TengsimError, match="resolve_pressures applies only to a physical run") as e:
            plan_contact(_table(name, base, resolve="auto", resolve_pressures="5kPa"))
        assert "\n" not in str(e.value)
    if name in PERIODIC_ONLY:  # boundary: 'periodic' is the base's, 'free' is refused
        del cases["boundary"]
        with pytest.raises(TengsimError, match="boundary = 'free' is refused") as e:
            plan_contact(_table(name, base, boundary="free"))
        assert "\n" not in str(e.value)
    for key, (ctx, value) in cases.items():
        _assert_changes(name, base, key, ctx, value)


@pytest.mark.parametrize("name, mode", CASES, ids=[f"{n}-{m}" for n, m in CASES])
def test_common_keys_are_refused_where_they_do_not_apply(name, mode, files):
    base = _topo_base(files) if name == "topography" else (
        {"K": 2, **_base("pyramid", mode)} if name == "array" else _base(name, mode))
    for more, words in COMMON_UNUSED:
        with pytest.raises(TengsimError, match=words.replace("(", r"\(").replace(")", r"\)")
                           .replace("[", r"\[").replace("]", r"\]")) as e:
            plan_contact(_table(name, base, **more))
        assert "\n" not in str(e.value)


@pytest.mark.parametrize("mode", ["dimensionless", "physical"])
def test_array_keys_change_the_plan_or_are_refused(mode):
    """The array's own keys (with the context where each applies), and per pattern shape each of the
    pattern's keys; the pattern keys of other patterns and the array keys without their context refused."""
    base = {"K": 2, **_base("pyramid", mode)}
    for key, (ctx, value) in ARRAY_OWN[mode].items():
        _assert_changes("array", base, key, ctx, value)
    for more, words in ARRAY_UNUSED[mode]:
        with pytest.raises(TengsimError, match=words.replace("(", r"\(").replace(")", r"\)")):
            plan_contact(_table("array", base, **more))
    patterns = [p for p in SHAPES.names() if getattr(SHAPES.get(p), "is_pattern", True)]
    union = {k: v for (p, m), (b, alt) in SHAPE_CASES.items() if m == mode and p in patterns
             for k, v in {**b, **alt}.items()}
    assert set(patterns) <= {p for p, _ in SHAPE_CASES}, "a new pattern shape: add its case to SHAPE_CASES"
    ref = plan_contact(_table("array", base))
    for p in patterns:
        pbase = {"pattern": p, "K": 2, **_base(p, mode)}
        if p != "pyramid":  # the default pattern, that of ref
            assert _changed(_sig(ref), _sig(plan_contact(_table("array", pbase)))), f"pattern {p} changes nothing"
        for key, value in SHAPE_CASES[(p, mode)][1].items():
            _assert_changes("array", pbase, key, {}, value)
        own = set(_own_keys(p, mode))
        for key in sorted(set(union) - own - set(PAPER) - set(GPA)):
            with pytest.raises(TengsimError, match=f"has no (physical )?key '{key}'") as e:
                plan_contact(_table("array", pbase, **{key: union[key]}))
            assert "\n" not in str(e.value)


def test_topography_keys_change_the_plan_or_are_refused(files):
    base = _topo_base(files)
    for key, (ctx, value) in _topo_own(files).items():
        if key == "fill_missing":
            continue
        _assert_changes("topography", base, key, ctx, value)
    # fill_missing: needed (and used) for a file with missing pixels, refused for one without
    with pytest.raises(TengsimError, match="1 missing"):
        plan_contact(_table("topography", base, file=str(files / "c.txt")))
    plan = plan_contact(_table("topography", base, file=str(files / "c.txt"), fill_missing=True))
    assert np.all(np.isfinite(plan.shape.gap(plan.shape.grid(plan.dx))))
    with pytest.raises(TengsimError, match="has no missing pixels: drop fill_missing"):
        plan_contact(_table("topography", base, fill_missing=True))
    # a file with its own unit and size: unit and physical_size refused, the same unit too
    nc = {"file": str(files / "s.nc"), **GPA}
    plan_contact(_table("topography", nc))
    for more, words in (({"unit": "nm"}, "declares its unit 'nm'; drop unit = 'nm'"),
                        ({"unit": "um"}, "declares its unit"), ({"physical_size": "2nm"}, "drop physical_size")):
        with pytest.raises(TengsimError, match=words):
            plan_contact(_table("topography", nc, **more))


@pytest.mark.parametrize("law", LAWS.names())
def test_each_law_key_changes_the_law_and_other_laws_refuse_it(law):
    """Every key of every registered law changes its pressure P(g) (plan level); the keys of the other
    laws are refused with one line."""
    base = _base("pyramid", "dimensionless")
    g = np.linspace(0.65, 4.0, 400)
    ref = plan_contact(_table("pyramid", base, law=law)).law
    mine = [f.name for f in law_fields(law)]
    for f in law_fields(law):
        new = plan_contact(_table("pyramid", base, law=law, **{f.name: 1.3 * f.default})).law
        assert np.max(np.abs(new.pressure(g) - ref.pressure(g))) > 1e-6, f"law {law}: {f.name} changes nothing"
    for key, entries in law_keys().items():
        if key in mine:
            continue
        with pytest.raises(TengsimError, match=f"law {law} has no key '{key}'"):
            plan_contact(_table("pyramid", base, law=law, **{key: 1.3 * (entries[0][1].default or 1.0)}))


def test_maps_need_a_nc_output():
    """maps_at with a .csv output (curves only) is refused before anything runs; .nc is accepted."""
    base = {"shape": "pyramid", **_base("pyramid", "dimensionless"), "maps_at": [1.1]}
    with pytest.raises(TengsimError, match=r"maps_at = 1.1 needs a .nc output: out = 'r.csv'"):
        plan_contact({**base, "out": "r.csv"})
    plan_contact({**base, "out": "r.nc"})
    plan_contact({**{k: v for k, v in base.items() if k != "maps_at"}, "out": "r.csv"})


@pytest.mark.parametrize("name, mode", CASES, ids=[f"{n}-{m}" for n, m in CASES])
def test_roughness_keys_change_the_gap_or_are_refused(name, mode, files):
    """roughness = true and each roughness_* key (with it) change the gap of every shape but rough, which
    refuses them (already rough); a roughness_* key without roughness = true is refused (one line each)."""
    base = _topo_base(files) if name == "topography" else (
        {"K": 2, **_base("pyramid", mode)} if name == "array" else _base(name, mode))
    if name in PERIODIC_ONLY:
        for more in ({"roughness": True}, {"roughness": True, "roughness_seed": 2}):
            with pytest.raises(TengsimError, match="already rough") as e:
                plan_contact(_table(name, base, **more))
            assert "\n" not in str(e.value)
        return
    plan = plan_contact(_table(name, base))
    g = plan.shape.grid(plan.dx)
    on = {"roughness": True, "roughness_short_cutoff": 2.5 * g.dx}  # >= 2 pixels, below the cell
    cases = {"roughness": ({}, on), "roughness_hurst": (on, 0.5), "roughness_rms_height": (on, 2.0),
             "roughness_rms_slope": (on, 0.3), "roughness_short_cutoff": (on, 3.0 * g.dx),
             "roughness_long_cutoff": (on, 0.8 * plan.shape.cell), "roughness_seed": (on, 1)}
    assert set(cases) == ROUGHNESS, "a new roughness key: add its case here"
    for key, (ctx, value) in cases.items():
        _assert_changes(name, base, key, ctx, value)
        if key != "roughness":
            with pytest.raises(TengsimError, match=f"{key} applies only with roughness = true") as e:
                plan_contact(_table(name, base, **{key: value}))
            assert "\n" not in str(e.value)
