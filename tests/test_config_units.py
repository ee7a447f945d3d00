"""Physical units for every shape (Scaling, Eq. 7/9/10), the [contact] schema and its refusals."""
import json
import math

import numpy as np
import pytest
import xarray as xr

from tengsim.cli.main import main
from tengsim.run.keys import contact_table
from tengsim.run.plan import plan_contact
from tengsim.errors import TengsimError
from tengsim.shapes import Cone, Cube, HeightMap, Hemisphere, Paraboloid, Pyramid
from tengsim.grid import Grid
from tengsim.registry import SHAPES
from tengsim.cases.paper.units import paper_scaling
from tengsim.units import Scaling, eps_for_tabor

E, W = 1e6, 0.05  # Pa, J/m²


def test_scaling_generalises_paper_scaling():
    """Scaling with ℓ = ε m/n and cell area L² gives the pyramid's PaperScaling numbers exactly."""
    ps = paper_scaling("B")
    s = Scaling(ps.E_star, ps.W, ps.eps, ps.eps * ps.m / ps.n, ps.L**2)
    assert s.mu == pytest.approx(ps.mu, rel=1e-12) and s.mu == pytest.approx(0.5)
    assert s.coupling == pytest.approx(0.5**1.5, rel=1e-12)
    for F in (-0.3, 1.0, 7.5):
        assert s.force(F) == pytest.approx(ps.force(F), rel=1e-12)
        assert s.pressure(F) == pytest.approx(ps.pressure(F), rel=1e-12)
    assert s.length(2 * ps.N) == pytest.approx(ps.m, rel=1e-12)
    assert s.displacement(2.0) == pytest.approx(2 * ps.eps)
    assert (ps.lateral, ps.cell_area) == (s.lateral, s.cell_area)


def test_sphere_tabor_from_physical_input_plan_only():
    """R = 5 µm, E* = 1 MPa, W = 50 mJ/m², ε = 0.3 nm: μ = (R W²/(E*² ε³))^{1/3} ≈ 773.6."""
    R, eps = 5e-6, 0.3e-9
    mu = (R * W**2 / (E**2 * eps**3)) ** (1 / 3)
    assert mu == pytest.approx(773.6, abs=0.05)
    plan = plan_contact(dict(shape="sphere", radius="5um", E_star="1MPa", W="50mJ/m2", eps="0.3nm"))
    assert plan.tabor == pytest.approx(mu, rel=1e-12)
    assert plan.shape == Paraboloid(1.0, 10.0)
    assert plan.scaling.lateral == pytest.approx(math.sqrt(R * eps), rel=1e-12)
    assert plan.extra["radius_m"] == pytest.approx(R)


PHYS = {  # shape: physical input (SI) for a plan with tabor 0.8
    "pyramid": dict(pitch=2e-6, base=1e-6, height=0.7e-6),
    "sphere": dict(radius=2e-6, pitch=0.4e-6),
    "cone": dict(slope=0.4, pitch=1e-6, height=0.2e-6),
    "hemisphere": dict(radius=1e-6, pitch=3e-6),
    "cube": dict(half_width=0.3e-6, height=0.2e-6, pitch=1e-6),
    "line": dict(half_width=0.3e-6, height=0.2e-6, pitch=1e-6),
}


@pytest.mark.parametrize("name", sorted(PHYS))
def test_tabor_solves_eps_for_every_shape(name):
    """Given tabor, ε solves κ(ε) = W ℓ(ε)/(E* ε²) = μ^{3/2}; the closed forms agree with the root finder."""
    cls = SHAPES.get(name)
    p = PHYS[name]
    plan = plan_contact(dict(shape=name, E_star=E, W=W, tabor=0.8, **p))
    eps = plan.scaling.eps
    lat = cls.lateral_scale(p, eps)
    assert W * lat / (E * eps**2) == pytest.approx(0.8**1.5, rel=1e-10)
    assert plan.tabor == pytest.approx(0.8, rel=1e-10)
    assert eps_for_tabor(lambda e: cls.lateral_scale(p, e), E, W, 0.8) == pytest.approx(eps, rel=1e-10)
    # and the scaling's own pressure is force per cell over the pitch²
    assert plan.scaling.pressure(1.0) == pytest.approx(plan.scaling.force(1.0) / p["pitch"] ** 2, rel=1e-10)


def _grid_m(shape, lat, n=41):
    g = Grid.square(shape.cell, shape.cell / n)
    X, Y = g.mesh()
    return g, X * lat, Y * lat


@pytest.mark.parametrize("name", ["sphere", "cone", "hemisphere", "cube", "pyramid"])
def test_physical_shape_gap_is_h0_over_eps(name):
    """The dimensionless U0 built from physical input is h0(x, y)/ε of the real surface, exactly."""
    p = PHYS[name]
    plan = plan_contact(dict(shape=name, E_star=E, W=W, eps=2e-9, dx="50nm", **p))
    sh, lat, eps = plan.shape, plan.scaling.lateral, 2e-9
    g, x, y = _grid_m(sh, lat)
    r = np.hypot(x, y)
    if name == "sphere":
        h0 = r**2 / (2 * p["radius"])
    elif name == "cone":
        h0 = np.minimum(p["slope"] * r, p["height"])
    elif name == "hemisphere":
        R = p["radius"]
        h0 = R - np.sqrt(R**2 - np.minimum(r, R) ** 2)
    elif name == "cube":
        h0 = np.where((abs(x) <= p["half_width"]) & (abs(y) <= p["half_width"]), 0.0, p["height"])
    else:  # the paper's pyramid: slope 2n/m up to its height n
        h0 = np.minimum(2 * np.maximum(abs(x), abs(y)) * p["height"] / p["base"], p["height"])
    np.testing.assert_allclose(sh.gap(g), h0 / eps, rtol=1e-9, atol=1e-9 * float(np.max(h0 / eps)))
    assert sh.cell * lat == pytest.approx(p["pitch"], rel=1e-12)


def test_hemisphere_vertical_factor_default_keeps_old_gap():
    g = Grid.square(10.0, 0.5)
    X, Y = g.mesh()
    r2 = np.minimum(X**2 + Y**2, 9.0)
    np.testing.assert_allclose(Hemisphere(3.0, 10.0).gap(g), 3.0 - np.sqrt(9.0 - r2))
    np.testing.assert_allclose(Hemisphere(3.0, 10.0, k=2.5).gap(g), 2.5 * (3.0 - np.sqrt(9.0 - r2)))


def test_dimensionless_sphere_radius_is_a_real_field():
    """`sphere --radius 2` used to be accepted and ignored (U0 kept radius 1)."""
    plan = plan_contact(dict(shape="sphere", radius=2, cell=6))
    assert plan.shape.radius == 2.0
    g = plan.shape.grid(0.5)
    X, Y = g.mesh()
    np.testing.assert_allclose(plan.shape.gap(g), (X**2 + Y**2) / 4)


def test_physical_dx_may_be_a_length():
    p = PHYS["cube"]
    plan = plan_contact(dict(shape="cube", E_star=E, W=W, eps="1nm", dx="25nm", **p))
    assert plan.dx == pytest.approx(25.0)  # ℓ = ε = 1 nm
    plan = plan_contact(dict(shape="cube", E_star=E, W=W, eps="1nm", dx=40, **p))
    assert plan.dx == 40.0


@pytest.mark.parametrize("cfg, words", [
    # physical and dimensionless shape keys mixed
    (dict(shape="pyramid", N=0.9, pitch="2um", base="1um", height="0.7um", E_star="1MPa", W="50mJ/m2", tabor=0.5),
     ["N", "mix"]),
    # a unit on a dimensionless key in a dimensionless run
    (dict(shape="cube", half_width="0.7um"), ["half_width", "dimensionless"]),
    # a key the shape does not have
    (dict(shape="cone", radius=2), ["cone", "radius"]),
    (dict(shape="line", N=2), ["line", "N"]),
    # E_star and W without the shape's physical fields
    (dict(shape="sphere", E_star="1MPa", W="50mJ/m2", eps="1nm"), ["radius"]),
    (dict(shape="cube", E_star="1MPa", W="50mJ/m2", tabor=1), ["half_width", "height", "pitch"]),
    # no fake tabor default in a physical run
    (dict(shape="sphere", radius="1um", E_star="1MPa", W="50mJ/m2"), ["eps or tabor"]),
    (dict(shape="sphere", radius="1um", E_star="1MPa", W="50mJ/m2", eps="1nm", tabor=1), ["either"]),
    # a length dx in a dimensionless run
    (dict(shape="cube", dx="20nm"), ["dx", "dimensionless"]),
    # a physical input for a shape that has none, a dimensionless pyramid without N
    (dict(shape="pyramid", cell=3), ["N"]),
    # every key is typed
    (dict(shape="pyramid", N=0.9, cell=3.78, refine_levels=1.5), ["refine_levels"]),
    (dict(shape="pyramid", N=0.9, cell=3.78, tol="small"), ["tol"]),
    (dict(shape="pyramid", N=0.9, cell=3.78, maps_at="one,two"), ["maps_at"]),
    (dict(shape="pyramid", N=0.9, cell=3.78, law="hooke"), ["hooke", "lj93"]),
    (dict(shape="pyramid", N=0.9, cell=3.78, solver="newton"), ["newton", "fast"]),
    (dict(shape="pyramid", N=0.9, cell=3.78, observers=["nope"]), ["nope", "summary"]),
    (dict(shape="pyramid", N=0.9, cell=3.78, d_min="-1um"), ["d_min"]),
])
def test_contact_table_refusals(cfg, words):
    with pytest.raises(TengsimError) as exc:
        plan_contact(cfg)
    msg = str(exc.value)
    assert "\n" not in msg
    for w in words:
        assert w in msg, msg


def test_refusals_through_the_cli_are_one_line_exit_2(tmp_path, capsys):
    out = tmp_path / "x.csv"
    for argv in (["cone", "--radius", "2"], ["cube", "--half-width", "0.7um"],
                 ["sphere", "--radius", "5um", "--E-star", "1MPa", "--W", "50mJ/m2"]):
        assert main(["contact", *argv, "--quiet", "--out", str(out)]) == 2
        err = capsys.readouterr().err
        assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert list(tmp_path.iterdir()) == []


def test_cli_help_from_registry_and_schema(capsys):
    with pytest.raises(SystemExit):
        main(["contact", "--help"])
    out = " ".join(capsys.readouterr().out.split())
    for name in SHAPES.names():
        assert name in out
    assert "default 0.5" in out and "no default" in out  # --tabor
    pages = {}
    for shape in ("cube", "hemisphere", "sinusoid"):  # a shape's keys: on its own page
        with pytest.raises(SystemExit):
            main(["contact", shape, "--help"])
        pages[shape] = " ".join(capsys.readouterr().out.split())
    assert "--half-width" in pages["cube"] and "--k" in pages["hemisphere"] and "--wavelength" in pages["sinusoid"]
    assert "--half-width" not in pages["sinusoid"]


def test_contact_table_lists_the_shape_keys():
    t = contact_table("cone")
    assert {"slope", "cell", "height", "pitch", "tabor", "dx", "observers"} <= set(t.keys())
    assert "N" not in t and "radius" not in t
    assert contact_table("sphere", "physical").fields["radius"].dim == "length"
    assert contact_table("sphere", "dimensionless").fields["radius"].dim is None


def test_heightmap_grid_does_not_ignore_dx():
    z = np.random.default_rng(0).random((16, 16))
    hm = HeightMap(z, 4.0)
    assert hm.grid().dx == 0.25 and hm.grid(0.25).dx == 0.25
    with pytest.raises(TengsimError, match="does not match"):
        hm.grid(0.1)


def test_physical_run_has_si_columns_and_its_own_units(tmp_path):
    """A physical sphere run: F_N, pressure_Pa, contact_length_m in CSV and NetCDF; units from its ℓ."""
    R, mu = 1e-6, 1.0
    eps = (math.sqrt(R) * W / (E * mu**1.5)) ** (2 / 3)
    lat = math.sqrt(R * eps)
    nc, csv = tmp_path / "s.nc", tmp_path / "s.csv"
    args = ["contact", "sphere", "--radius", "1um", "--pitch", f"{8 * lat}", "--E-star", "1MPa", "--W",
            "50mJ/m2", "--tabor", "1", "--dx", "0.5", "--d-min", "-0.5", "--d-max", "1", "--d-step", "0.5",
            "--quiet"]
    assert main(args + ["--out", str(nc)]) == 0
    assert main(args + ["--out", str(csv)]) == 0
    ds = xr.load_dataset(nc)
    F = ds["F"].values
    np.testing.assert_allclose(ds["F_N"].values, 3 * math.pi * W * lat**2 / eps * F, rtol=1e-9)
    np.testing.assert_allclose(ds["pressure_Pa"].values, ds["F_N"].values / (8 * lat) ** 2, rtol=1e-9)
    np.testing.assert_allclose(ds["contact_length_m"].values, ds["contact_length"].values * lat, rtol=1e-9)
    # CF units (tests/test_cf.py): SI columns in UDUNITS units, dimensionless ones "1" with their scale
    assert ds["F_N"].attrs["units"] == "N" and ds["pressure_Pa"].attrs["units"] == "Pa"
    assert ds["F"].attrs["units"] == "1" and "m/n" not in ds["F"].attrs["unit_scale_text"]
    assert "per cell" in ds["F"].attrs["unit_scale_text"] and ds["F"].attrs["unit_scale_units"] == "N"
    assert ds["F"].attrs["unit_scale"] == pytest.approx(3 * math.pi * W * lat**2 / eps, rel=1e-9)
    assert ds["contact_length"].attrs["unit_scale"] == pytest.approx(lat, rel=1e-9)
    params = json.loads(ds.attrs["params"])
    assert params["tabor"] == pytest.approx(1.0) and params["eps_m"] == pytest.approx(eps, rel=1e-10)
    head = [line for line in open(csv) if line.startswith("#")]
    cols = next(line for line in open(csv) if not line.startswith("#")).strip().split(",")
    assert {"F_N", "pressure_Pa", "contact_length_m"} <= set(cols)
    assert any(line.startswith("# units:") and "N per cell" in line for line in head)


def test_dimensionless_units_name_the_shape_not_the_pyramid(tmp_path):
    nc = tmp_path / "c.nc"
    assert main(["contact", "cube", "--half-width", "1", "--height", "3", "--cell", "4", "--dx", "0.5",
                 "--d-max", "0.5", "--d-step", "0.5", "--quiet", "--out", str(nc)]) == 0
    ds = xr.load_dataset(nc)
    assert "m/n" not in ds["F"].attrs["unit_scale_text"] and "m/n" not in ds["contact_length"].attrs["unit_scale_text"]
    assert "unit_scale" not in ds["F"].attrs  # a dimensionless run: the scale in words only
    assert "F_N" not in ds
    nc2 = tmp_path / "p.nc"
    assert main(["contact", "pyramid", "--N", "0.946", "--cell", "3.78", "--dx", "0.3", "--d-max", "0.5",
                 "--d-step", "0.5", "--quiet", "--out", str(nc2)]) == 0
    assert "ε m/n" in xr.load_dataset(nc2)["contact_length"].attrs["unit_scale_text"]


def test_plot_curves_uses_physical_axes(tmp_path, monkeypatch):
    import tengsim.plots as plots
    from tengsim.results.read import load_result

    figs = []
    monkeypatch.setattr(plots, "save", lambda fig, path: figs.append(fig))
    plan_cfg = dict(shape="cube", half_width="0.3um", height="0.2um", pitch="1um", E_star="1MPa",
                    W="50mJ/m2", eps="20nm", dx=2, d_min=-0.5, d_max=0.5, d_step=0.5)
    from tengsim.run.simulate import simulate as run_contact

    res = run_contact(plan_cfg)
    plots.plot_curves(res, tmp_path / "p.png")
    ax = figs[-1].axes
    assert "nm" in ax[0].get_xlabel() and "µN" in ax[0].get_ylabel() and "µm" in ax[1].get_ylabel()
    line_y = ax[0].lines[0].get_ydata()
    assert np.nanmax(np.abs(line_y)) == pytest.approx(np.max(np.abs(res.branch("approach")["F_N"])) * 1e6)
    res.save(tmp_path / "d.nc")
    _, back = load_result(tmp_path / "d.nc")
    assert np.array_equal(back.table["F_N"], res.table["F_N"])  # the SI columns survive the round trip
    plots.plot_curves(back, tmp_path / "q.png")  # and the redrawn figure keeps the physical axes
    assert "nm" in figs[-1].axes[0].get_xlabel() and "µN" in figs[-1].axes[0].get_ylabel()


def test_json_config_goes_through_the_schema_reader(tmp_path):
    cfg = tmp_path / "run.json"
    out = tmp_path / "r.csv"
    cfg.write_text(json.dumps({"contact": {"shape": "pyramid", "N": 0.946, "cell": 3.78, "dx": 0.3,
                                           "d_max": 0.5, "d_step": 0.5, "out": str(out)}}))
    assert main(["run", str(cfg), "--quiet"]) == 0
    assert out.exists()


def test_paper_scaling_pyramid_plan_is_unchanged():
    plan = plan_contact(dict(shape="pyramid", pitch="2um", base="1um", height="0.7um", E_star="0.59MPa",
                             W="54mJ/m2", tabor=0.5))
    sc = paper_scaling("A")
    # the core builds the generic Scaling (no paper special case); its numbers are the paper's
    assert type(plan.scaling) is Scaling and plan.scaling == Scaling(sc.E_star, sc.W, sc.eps, sc.lateral, sc.cell_area)
    for F in (-0.3, 1.0, 7.5):
        assert plan.scaling.pressure(F) == pytest.approx(sc.pressure(F), rel=1e-12)
    assert plan.shape == Pyramid(sc.N, sc.cell) or plan.shape.N == pytest.approx(sc.N, rel=1e-12)
    assert plan.extra["pitch_m"] == pytest.approx(2e-6) and plan.extra["eps_m"] == pytest.approx(sc.eps)


def test_cone_and_cube_dimensionless_defaults():
    assert plan_contact(dict(shape="cone")).shape == Cone(1.0, 10.0)
    assert plan_contact(dict(shape="cube")).shape == Cube(1.0, 5.0, 6.0)
    assert plan_contact(dict(shape="cone")).tabor == 0.5


def test_eps_for_tabor_root_and_no_root():
    """Brent in log ε reproduces a closed form (ℓ = sqrt(Rε)) and names a μ no ε in range can give."""
    R = 3e-6
    eps = eps_for_tabor(lambda e: math.sqrt(R * e), E, W, 2.0)
    assert eps == pytest.approx((math.sqrt(R) * W / (E * 2.0**1.5)) ** (2 / 3), rel=1e-12)
    with pytest.raises(TengsimError, match="tabor = 2"):
        eps_for_tabor(lambda e: e * e, E, W, 2.0)  # κ = W/E* whatever ε is
