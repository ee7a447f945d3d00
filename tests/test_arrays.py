"""Arrays with scatter: K × K super-cells, their scatter statistics, the array_area observer, input."""
import csv

import numpy as np
import pytest

from tengsim.run.plan import ContactPlan
import tengsim
from tengsim.shapes.arrays import Array
from tengsim.cli.main import main
from tengsim.run.plan import plan_contact
from tengsim.run.simulate import simulate as run_contact
from tengsim.errors import TengsimError

A = dict(N=0.946, cell=3.78)


def _rows(path):
    with open(path) as fh:
        return list(csv.DictReader(l for l in fh if not l.startswith("#")))


def test_zero_scatter_array_equals_the_single_periodic_cell():
    """K = 2 without scatter is the periodic cell repeated: force per cell equal to 1e-8."""
    spec = tengsim.PathSpec(-1.0, 1.0, 0.5, retract=False)
    one = tengsim.simulate(ContactPlan(tengsim.Pyramid(**A), 0.5, 0.2, spec, boundary="periodic", solver_tol=1e-11))
    arr = tengsim.simulate(ContactPlan(Array("pyramid", K=2, **A), 0.5, 0.2, spec, boundary="periodic", solver_tol=1e-11, observers=["array_area"]))
    assert arr.params["nx"] == 2 * one.params["nx"]
    assert len(arr.table["F"]) == len(one.table["F"])
    assert np.abs(arr.table["F"] / 4 - one.table["F"]).max() < 1e-8
    # the Greenwood A/S of the array is the single cell's Λc²/L̄²
    lam = one.table["contact_length"]
    assert arr.table["area_fraction_greenwood"] == pytest.approx(np.minimum(lam**2 / 3.78**2, 1), abs=1e-6)
    assert arr.table["area_fraction_greenwood"][-1] > 0
    assert set(arr.table["cells_in_contact"][arr.table["area_fraction_greenwood"] > 0]) == {4.0}


@pytest.mark.parametrize("dist", ["normal", "uniform"])
def test_realised_height_scatter_has_the_asked_rms(dist):
    """K = 16 (256 cells), 5 % rms: the apex heights read back from the gap map have rms 0.05 within
    three standard errors (0.05/sqrt(2·256) each) and mean 1 within three standard errors."""
    K, s = 16, 0.05
    arr = Array("pyramid", K=K, scatter_height=s, distribution=dist, seed=3, **A)
    g = arr.grid(0.4)
    z = arr.heights_map(g)
    n = g.nx // K
    apex = z.reshape(K, n, K, n).max(axis=(1, 3)) / (2 * A["N"])
    se = s / np.sqrt(2 * K * K)
    assert abs(apex.std() - s) < 3 * se
    assert abs(apex.mean() - 1) < 3 * s / K
    if dist == "uniform":
        assert np.abs(apex - 1).max() <= s * np.sqrt(3) + 1e-12


def test_size_and_tilt_scatter_change_the_cells():
    arr = Array("pyramid", K=4, scatter_size=0.05, scatter_tilt=0.05, seed=1, N=0.946, cell=4.5)
    g = arr.grid(0.1)
    z = arr.heights_map(g)
    n = g.nx // 4
    foot = (z.reshape(4, n, 4, n) > 0).sum(axis=(1, 3)) * g.area
    # the footprint of a pyramid scaled by s is (2N s)² to within the pixel rim
    base = (2 * 0.946 * arr.sizes) ** 2
    assert np.abs(foot / base - 1).max() < 0.25
    assert np.corrcoef(foot.ravel(), base.ravel())[0, 1] > 0.9


def test_seeded_array_is_reproducible():
    kw = dict(K=4, scatter_height=0.1, scatter_size=0.05, scatter_tilt=0.1, seed=7, **A)
    g = Array("pyramid", **kw).grid(0.2)
    a, b = Array("pyramid", **kw).gap(g), Array("pyramid", **kw).gap(g)
    assert np.array_equal(a, b)
    c = Array("pyramid", **{**kw, "seed": 8}).gap(g)
    assert not np.array_equal(a, c)


def test_waviness_adds_a_long_wavelength_and_must_fit_the_supercell():
    arr = Array("pyramid", K=4, waviness_amplitude=0.5, waviness_wavelength=2, **A)
    g = arr.grid(0.2)
    n = g.nx // 4
    flat = Array("pyramid", K=4, **A).heights_map(g)
    w = arr.heights_map(g) - flat
    assert w.max() - w.min() == pytest.approx(1.0, rel=0.02)
    assert np.allclose(w[:2 * n], w[2 * n:])  # wavelength 2 cells
    with pytest.raises(TengsimError, match="does not divide K"):
        Array("pyramid", K=4, waviness_amplitude=0.5, waviness_wavelength=3, **A)


@pytest.mark.parametrize("kw, msg", [
    (dict(scatter_size=0.3, N=0.946, cell=2.0), "wider than its cell"),
    (dict(scatter_height=0.8, K=8), "height factor"),
    (dict(K=0), "K must be"),
    (dict(scatter_height=-0.1), "must be >= 0"),
])
def test_bad_scatter_refused(kw, msg):
    with pytest.raises(TengsimError, match=msg):
        a = Array("pyramid", **{**A, **kw})
        a.gap(a.grid(0.2))


def test_cli_array_physical_and_bad_scatter(tmp_path, capsys):
    out = tmp_path / "a.csv"
    args = ["contact", "array", "--pattern", "pyramid", "--pitch", "2um", "--base", "1um", "--height", "0.7um",
            "--E-star", "0.59MPa", "--W", "54mJ/m2", "--tabor", "0.5", "--K", "2", "--scatter-height", "0.05",
            "--tilt", "0.01", "--dx", "0.2", "--boundary", "periodic", "--observers", "array_area",
            "--d-min", "-1", "--d-max", "0.5", "--d-step", "0.5", "--quiet"]
    assert main(args + ["--out", str(out)]) == 0
    rows = _rows(out)
    assert "area_fraction_greenwood" in rows[0] and "pressure_Pa" in rows[0]
    head = [l for l in open(out) if l.startswith("# cell_area_m2:")]
    assert float(head[0].split(":")[1]) == pytest.approx(16e-12, rel=1e-12)  # 2 × 2 cells of 2 µm
    bad = tmp_path / "b.csv"
    rc = main(args[:-7] + ["--scatter-size", "0.9", "--boundary", "periodic", "--out", str(bad)])
    err = capsys.readouterr().err
    assert rc == 2 and "wider than its cell" in err and len(err.strip().splitlines()) == 1 and not bad.exists()


def test_array_config_table_dimensionless_and_mixing_refused():
    plan = plan_contact(dict(shape="array", pattern="sphere", radius=1.0, cell=6.0, K=3, scatter_height=0.02,
                             boundary="periodic", dx=0.5))
    assert plan.shape.cell == pytest.approx(18.0) and plan.shape.pattern_name == "sphere"
    with pytest.raises(TengsimError, match="do not mix"):
        plan_contact(dict(shape="array", N=0.946, cell=3.78, pitch="2um", E_star="1MPa", W="50mJ/m2",
                          tabor=0.5))
    res = run_contact(dict(shape="array", K=2, d_min=-1, d_max=0, d_step=0.5, dx=0.3, boundary="periodic",
                           observers="array_area", **A))
    assert res.params["K"] == 2 and "area_fraction_repulsive" in res.table


def test_toml_array_run(tmp_path):
    """An array from a TOML [contact] table through `tengsim run` (scatter, waviness, the observer)."""
    out = tmp_path / "r.csv"
    (tmp_path / "a.toml").write_text(f'''[contact]
shape = "array"
pattern = "pyramid"
N = 0.946
cell = 3.78
K = 2
scatter_height = 0.05
distribution = "uniform"
seed = 4
waviness_amplitude = 0.1
waviness_wavelength = 2
boundary = "periodic"
dx = 0.3
d_min = -1
d_max = 0
d_step = 0.5
observers = ["array_area"]
out = "{out}"
''')
    assert main(["run", str(tmp_path / "a.toml"), "--quiet"]) == 0
    rows = _rows(out)
    assert len(rows) >= 6 and "cells_in_contact" in rows[0]
    head = "".join(l for l in open(out) if l.startswith("#"))
    assert '"uniform"' in head and "waviness_amplitude: 0.1" in head
