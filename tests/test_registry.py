"""Extension points: registries of shapes, laws, kernels, solvers, observers; user plugins from outside."""
import csv
import importlib
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from tengsim.run.plan import ContactPlan
import tengsim as ts
from tengsim import registry
from tengsim import plugins
from tengsim.cli.main import main
from tengsim.errors import TengsimError
from tengsim.laws import LJ93, Repulsive, SafeLaw, make_law
from tengsim.kernels import FreeKernel, PeriodicKernel, make_kernel
from tengsim.registry import KERNELS, LAWS, OBSERVERS, SHAPES, SOLVERS
from tengsim.solvers import FastSolver, VSRSolver, make_solver


def test_builtins_are_registered():
    assert set(SHAPES.names()) >= {"pyramid", "sphere", "cone", "hemisphere", "cube", "line", "flat_punch",
                                   "sinusoid"}
    assert SHAPES.get("sphere") is ts.Paraboloid and SHAPES.get("flat-punch") is ts.FlatPunch
    assert LAWS.get("lj") is LJ93 and LAWS.get("paper") is LJ93 and LAWS.get("repulsive") is Repulsive
    assert KERNELS.names() == ("free", "periodic") and SOLVERS.names() == ("fast", "vsr", "homotopy", "pk", "pk_jax", "ram", "jax",
                                                                           "gpu", "auto")
    assert "summary" in OBSERVERS


def test_make_functions_are_thin_wrappers():
    g = ts.Grid.square(3.0, 0.5)
    assert isinstance(make_kernel("free", g, 0.3), FreeKernel)
    assert isinstance(make_kernel("periodic", g, 0.3), PeriodicKernel)
    assert isinstance(make_solver("fast", tol=1e-5), FastSolver) and make_solver("vsr").tol == 1e-6
    assert isinstance(make_solver("vsr"), VSRSolver)
    assert make_law("lj93") == LJ93() and make_law("repulsive", exponent=5.0).exponent == 5.0
    for fn, args, word in ((make_kernel, ("moebius", g, 0.3), "free, periodic"),
                           (make_solver, ("newton",), "fast, vsr"), (make_law, ("hooke",), "lj93, repulsive")):
        with pytest.raises(TengsimError, match=word):
            fn(*args)


def test_a_new_registration_reaches_every_name_list():
    """Registering a kernel makes it valid in simulate, the [contact] schema and its error texts."""
    KERNELS.register("periodic_copy", lambda grid, coupling: PeriodicKernel(grid, coupling))
    try:
        from tengsim.run.plan import plan_contact

        assert plan_contact(dict(N=0.946, cell=3.78, boundary="periodic_copy")).boundary == "periodic_copy"
        with pytest.raises(TengsimError, match="periodic_copy"):
            make_kernel("x", ts.Grid.square(3.0, 0.5), 0.3)
        res = ts.simulate(ContactPlan(ts.Pyramid(0.946, 3.78), 0.5, 0.3, ts.PathSpec(-1, 0, 0.5, retract=False), boundary="periodic_copy"))
        ref = ts.simulate(ContactPlan(ts.Pyramid(0.946, 3.78), 0.5, 0.3, ts.PathSpec(-1, 0, 0.5, retract=False), boundary="periodic"))
        np.testing.assert_allclose(res.table["F"], ref.table["F"], rtol=1e-12)
        assert res.params["boundary"] == "periodic_copy"
    finally:
        KERNELS.unregister("periodic_copy")


def test_law_params_are_its_fields_not_its_caches():
    law = LJ93()
    safe = SafeLaw(law)
    safe.evaluate(np.array([0.1, 1.0]))  # below g_safe: fills the wrapper's cached safe-extension values
    assert law.params() == {"g_safe": 0.6, "law": "LJ93"} and safe.params() == law.params()
    r = Repulsive(exponent=5.0)
    r.evaluate(np.array([0.1]))
    assert set(r.params()) == {"scale", "exponent", "g_safe", "law"}


def test_hysteresis_needs_no_numpy_trapezoid_name(monkeypatch):
    """ContactResult.hysteresis integrates with scipy: NumPy 1.x has no np.trapezoid, NumPy 2.4 no np.trapz."""
    from tengsim.grid import Grid
    from tengsim.results import ContactResult

    monkeypatch.delattr(np, "trapezoid", raising=False)
    monkeypatch.delattr(np, "trapz", raising=False)
    x = np.linspace(0, 1, 101)
    res = ContactResult(table={"branch": np.array(["approach"] * 101 + ["retraction"] * 101),
                               "D": np.r_[x, x[::-1]], "F": np.r_[x**2, 0 * x]}, grid=Grid(3, 3, 1.0, 1.0))
    assert res.hysteresis == pytest.approx(1 / 3, abs=2e-5) and isinstance(res.hysteresis, float)
    one = ContactResult(table={"branch": np.array(["approach", "retraction"]), "D": np.r_[0.0, 0.0],
                               "F": np.r_[1.0, 1.0]}, grid=Grid(3, 3, 1.0, 1.0))
    assert one.hysteresis == 0.0


class PApex:
    columns = ("P_apex", "H_apex")
    units = {"P_apex": "W/ε"}

    def __call__(self, eq, ctx):
        return {"P_apex": eq.P[ctx.apex], "H_apex": eq.H[ctx.apex]}


def test_observers_append_columns_to_table_csv_and_netcdf(tmp_path):
    spec = ts.PathSpec(-0.5, 0.5, 0.5, maps_at=(0.5,))
    res = ts.simulate(ContactPlan(ts.Pyramid(0.946, 3.78), 0.5, 0.3, spec, observers=[PApex()]))
    t = res.table
    assert res.columns[-2:] == ["P_apex", "H_apex"]
    for m in res.maps:  # the observer saw the same state as the maps
        i = np.flatnonzero((t["branch"] == m["branch"]) & (t["D"] == m["D"]))[0]
        i0, j0 = (n // 2 for n in m["P"].shape)
        assert t["P_apex"][i] == m["P"][i0, j0] and t["H_apex"][i] == m["H"][i0, j0]
    res.save(tmp_path / "o.csv")
    res.save(tmp_path / "o.nc")
    rows = list(csv.DictReader(l for l in open(tmp_path / "o.csv") if not l.startswith("#")))
    assert [float(r["P_apex"]) for r in rows] == pytest.approx(list(t["P_apex"]))
    ds = xr.load_dataset(tmp_path / "o.nc")
    np.testing.assert_allclose(ds["H_apex"].values, t["H_apex"])
    # CF: a dimensionless column has units "1"; the observer's unit is its scale (tests/test_cf.py)
    assert ds["P_apex"].attrs["units"] == "1" and ds["P_apex"].attrs["unit_scale_text"] == "W/ε (Eq. 8)"


def test_observer_errors_are_named():
    spec = ts.PathSpec(-0.5, 0.0, 0.5, retract=False)

    class Clash:
        columns = ("F",)

        def __call__(self, eq, ctx):
            return {"F": 0.0}

    class Wrong:
        columns = ("a",)

        def __call__(self, eq, ctx):
            return {"b": 0.0}

    with pytest.raises(TengsimError, match="'F' is already"):
        ts.simulate(ContactPlan(ts.Pyramid(0.946, 3.78), 0.5, 0.3, spec, observers=[Clash()]))
    with pytest.raises(TengsimError, match="Wrong"):
        ts.simulate(ContactPlan(ts.Pyramid(0.946, 3.78), 0.5, 0.3, spec, observers=[Wrong()]))
    with pytest.raises(TengsimError, match="unknown observer 'nope'"):
        ts.simulate(ContactPlan(ts.Pyramid(0.946, 3.78), 0.5, 0.3, spec, observers=["nope"]))


def test_paper_study_uses_an_observer_not_a_monkeypatch():
    """scripts/paper_study.py used to replace tengsim.continuation.path.summarize on import."""
    import tengsim.continuation.path

    before = dict(vars(tengsim.continuation.path))
    path = Path(__file__).parent.parent / "scripts" / "paper_study.py"
    spec = importlib.util.spec_from_file_location("_paper_study_under_test", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    assert {k: v for k, v in vars(tengsim.continuation.path).items() if before.get(k) is not v} == {}
    case = dict(name="t_A", study="t", group="A", mu=0.5, boundary="free", d_min=-1.0, d_max=0.0,
                d_step=0.5, tol=1e-5, dx=0.3, variant="")
    _, rows, info = mod.run_case(case)
    assert len(rows["L_diag"]) == info["n_rows"] == len(rows["D"])
    assert np.all(rows["L_rep"] >= 0) and np.all((rows["floor"] >= 0) & (rows["floor"] <= 1))


# ---- a user's plugin, from outside the package -------------------------------------------------
PLUGIN = '''
"""A user's extension of tengsim: a law, a shape and an observer."""
from dataclasses import dataclass

import numpy as np

from tengsim.shapes import Shape
from tengsim.laws import LJ93, Law
from tengsim.registry import LAWS, OBSERVERS, SHAPES


@LAWS.register("half_lj", summary="the paper's law at half strength")
@dataclass(frozen=True)
class HalfLJ(Law):
    factor: float = 0.5
    g_safe: float = 0.6

    def _raw(self, g, need_dp=True):
        phi, p, dp = LJ93()._raw(g, need_dp)
        f = self.factor
        return f * phi, f * p, None if dp is None else f * dp


@SHAPES.register("tent", summary="square tent with a flat tip")
@dataclass(frozen=True)
class Tent(Shape):
    slope: float = 1.0
    cell: float = 4.0
    tip: float = 0.0

    def gap(self, grid):
        X, Y = grid.mesh()
        return self.slope * np.maximum(np.abs(X) + np.abs(Y) - self.tip, 0.0)


@OBSERVERS.register("p_apex", summary="pressure at the apex")
class PApex:
    columns = ("P_apex",)

    def __call__(self, eq, ctx):
        return {"P_apex": float(eq.P[ctx.apex])}
'''


@pytest.fixture
def plugin(tmp_path, monkeypatch):
    name = "tengsim_user_plugin_" + tmp_path.name.replace("-", "_")
    (tmp_path / f"{name}.py").write_text(textwrap.dedent(PLUGIN))
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setenv("TENGSIM_PLUGINS", name)
    monkeypatch.setattr(plugins, "_LOADED", set())
    yield name
    for reg, key in ((LAWS, "half_lj"), (SHAPES, "tent"), (OBSERVERS, "p_apex")):
        if key in reg:
            reg.unregister(key)
    sys.modules.pop(name, None)


def test_user_plugin_via_api_toml_and_cli(plugin, tmp_path, capsys):
    # the command line loads TENGSIM_PLUGINS before it builds its parser: the new shape, its new
    # field (--tip), the new law and the new observer are all usable
    out = tmp_path / "cli.csv"
    assert main(["contact", "tent", "--slope", "1.5", "--tip", "0.3", "--law", "half_lj", "--observers",
                 "p_apex", "--dx", "0.3", "--d-min", "-0.5", "--d-max", "0.5", "--d-step", "0.5", "--quiet",
                 "--out", str(out)]) == 0, capsys.readouterr().err
    head = "".join(l for l in open(out) if l.startswith("#"))
    assert '"shape": "tent"' in head and "# law: \"HalfLJ\"" in head and "# tip: 0.3" in head
    rows = list(csv.DictReader(l for l in open(out) if not l.startswith("#")))
    assert "P_apex" in rows[0] and all(r["converged"] == "1" for r in rows)

    # the API: registered names (the module is now imported)
    Tent = SHAPES.get("tent")
    res = ts.simulate(ContactPlan(Tent(slope=1.5, tip=0.3), 0.5, 0.3, ts.PathSpec(-0.5, 0.5, 0.5), law="half_lj", observers=["p_apex"]))
    F_cli = np.array([float(r["F"]) for r in rows])
    np.testing.assert_allclose(res.table["F"], F_cli, rtol=1e-12)
    np.testing.assert_allclose(res.table["P_apex"], [float(r["P_apex"]) for r in rows], rtol=1e-12)
    # the law is really half the paper's: at the same state the pressures are halved
    full = ts.simulate(ContactPlan(Tent(slope=1.5, tip=0.3), 0.5, 0.3, ts.PathSpec(-0.5, 0.5, 0.5), observers=["p_apex"]))
    assert not np.allclose(full.table["F"], res.table["F"])

    # a TOML run
    cfg = tmp_path / "run.toml"
    out2 = tmp_path / "toml.nc"
    cfg.write_text(f'''
[contact]
shape = "tent"
slope = 1.5
tip = 0.3
law = "half_lj"
observers = ["p_apex"]
dx = 0.3
d_min = -0.5
d_max = 0.5
d_step = 0.5
out = "{out2}"
''')
    assert main(["run", str(cfg), "--quiet"]) == 0, capsys.readouterr().err
    ds = xr.load_dataset(out2)
    np.testing.assert_allclose(ds["P_apex"].values, res.table["P_apex"], rtol=1e-12)
    # a key the new shape does not have is refused with its name
    assert main(["contact", "tent", "--radius", "2", "--quiet", "--out", str(tmp_path / "x.csv")]) == 2
    assert "radius" in capsys.readouterr().err

    # the new law's own field is a key of the CLI, TOML and help, with the law's default
    HalfLJ = LAWS.get("half_lj")
    api = ts.simulate(ContactPlan(Tent(slope=1.5, tip=0.3), 0.5, 0.3, ts.PathSpec(-0.5, 0.5, 0.5), law=HalfLJ(factor=0.25)))
    assert not np.allclose(api.table["F"], res.table["F"])
    out3 = tmp_path / "factor.csv"
    assert main(["contact", "tent", "--slope", "1.5", "--tip", "0.3", "--law", "half_lj", "--factor", "0.25",
                 "--dx", "0.3", "--d-min", "-0.5", "--d-max", "0.5", "--d-step", "0.5", "--quiet",
                 "--out", str(out3)]) == 0, capsys.readouterr().err
    rows = list(csv.DictReader(l for l in open(out3) if not l.startswith("#")))
    np.testing.assert_allclose([float(r["F"]) for r in rows], api.table["F"], rtol=1e-12)
    assert "# factor: 0.25" in "".join(l for l in open(out3) if l.startswith("#"))
    cfg.write_text(cfg.read_text().replace('law = "half_lj"', 'law = "half_lj"\nfactor = 0.25'))
    assert main(["run", str(cfg), "--quiet"]) == 0, capsys.readouterr().err
    np.testing.assert_allclose(xr.load_dataset(out2)["F"].values, api.table["F"], rtol=1e-12)
    assert main(["contact", "tent", "--factor", "0.25", "--quiet", "--out", str(tmp_path / "y.csv")]) == 2
    assert "law lj93 has no key 'factor' (its keys: none)" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(["contact", "--help"])
    assert "--factor parameter of law half_lj, in units of W and ε [law half_lj: default 0.5]" in " ".join(
        capsys.readouterr().out.split())


def test_broken_plugin_is_one_line(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("TENGSIM_PLUGINS", "no_such_tengsim_plugin_module")
    monkeypatch.setattr(plugins, "_LOADED", set())
    assert main(["contact", "--help"]) == 2
    err = capsys.readouterr().err
    assert "no_such_tengsim_plugin_module" in err and len(err.strip().splitlines()) == 1
