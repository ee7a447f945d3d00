"""Roughness superimposed on any shape (issue 23, item 1): tengsim.shapes.roughened.Roughened and the
[contact] keys roughness = true, roughness_* (CLI --roughness, --roughness-*)."""
from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from tengsim.cli.main import main
from tengsim.run.plan import plan_contact
from tengsim.errors import TengsimError
from tengsim.shapes import Paraboloid, Pyramid, Rough
from tengsim.shapes.roughened import Roughened

PYR = {"shape": "pyramid", "N": 0.946, "cell": 3.78, "dx": 0.1}
_U0 = ("import sys; from tengsim.shapes import Pyramid; from tengsim.shapes.roughened import Roughened; "
       "r = Roughened(Pyramid(N=0.946, cell=3.78), hurst=0.7, rms_height=0.4, short_cutoff=0.4, seed=5); "
       "sys.stdout.write(r.gap(r.grid(0.1)).tobytes().hex())")


def test_roughened_pyramid_gap_is_pyramid_gap_plus_rough_field_minus_min():
    p = Pyramid(N=0.946, cell=3.78)
    r = Roughened(p, hurst=0.7, rms_height=0.4, short_cutoff=0.4, seed=5)
    g = r.grid(0.1)
    field = Rough(cell=3.78, hurst=0.7, rms_height=0.4, short_cutoff=0.4, seed=5).gap(g)  # max h − h
    expected = p.gap(g) + field
    assert np.allclose(r.gap(g), expected - expected.min(), rtol=0, atol=1e-12)
    assert r.gap(g).min() == 0.0
    assert r.mirror_axes == () and p.cell == r.cell and r.long_cutoff == 3.78  # no mirror; defaults: the cell
    assert Roughened(Paraboloid(radius=10.0, cell=8.0), short_cutoff=1.0).mirror_axes == ()  # base has mirrors


def test_same_seed_same_gap_in_and_across_processes_different_seed_different():
    r = Roughened(Pyramid(N=0.946, cell=3.78), hurst=0.7, rms_height=0.4, short_cutoff=0.4, seed=5)
    g = r.grid(0.1)
    a = r.gap(g)
    assert np.array_equal(a, Roughened(Pyramid(N=0.946, cell=3.78), hurst=0.7, rms_height=0.4, short_cutoff=0.4,
                                       seed=5).gap(g))
    other = subprocess.run([sys.executable, "-c", _U0], capture_output=True, text=True, check=True).stdout
    assert other == a.tobytes().hex()
    b = Roughened(Pyramid(N=0.946, cell=3.78), hurst=0.7, rms_height=0.4, short_cutoff=0.4, seed=6).gap(g)
    assert np.max(np.abs(a - b)) > 0.1


def test_rms_height_and_slope_as_requested_dimensionless_and_physical():
    # dimensionless: the added field's rms is the rms height asked for (the generator rescales it exactly)
    plan = plan_contact({**PYR, "roughness": True, "roughness_rms_height": 0.25, "roughness_short_cutoff": 0.3})
    g = plan.shape.grid(plan.dx)
    h = plan.shape.heights(g)
    assert abs(h.mean()) < 1e-12 and abs(h.std() - 0.25) < 1e-9
    # physical: rms height 5 nm (h in ε), rms slope 0.2 as dh/dx (dU0/dX · ε/ℓ), cut-offs in ℓ
    phys = {"shape": "pyramid", "pitch": "2um", "base": "1um", "height": "0.7um", "E_star": "0.59MPa",
            "W": "54mJ/m2", "tabor": 0.5, "dx": "40nm", "roughness": True, "roughness_short_cutoff": "0.2um"}
    p = plan_contact({**phys, "roughness_rms_height": "5nm", "roughness_long_cutoff": "1um"})
    s, sc = p.shape, p.scaling
    g = s.grid(p.dx)
    assert s.heights(g).std() * sc.eps == pytest.approx(5e-9, rel=1e-9)
    assert s.short_cutoff * sc.lateral == pytest.approx(2e-7) and s.long_cutoff * sc.lateral == pytest.approx(1e-6)
    assert p.extra["roughness_rms_height_m"] == pytest.approx(5e-9)
    p = plan_contact({**phys, "roughness_rms_slope": 0.2})
    h = p.shape.heights(g)
    H = np.fft.fft2(h) / h.size
    q = 2 * np.pi * np.fft.fftfreq(g.nx, d=g.dx)
    slope_X = np.sqrt(np.sum(np.abs(H) ** 2 * (q[:, None] ** 2 + q[None, :] ** 2)))  # dU0/dX
    assert slope_X * p.scaling.eps / p.scaling.lateral == pytest.approx(0.2, rel=1e-9)
    # a bare number is in ε (heights) or X units (cut-offs), as dx is
    p = plan_contact({**phys, "roughness_rms_height": 0.5, "roughness_short_cutoff": 0.4})
    assert p.shape.rms_height == 0.5 and p.shape.short_cutoff == 0.4


def test_cli_run_records_the_roughness(tmp_path):
    out = tmp_path / "x.csv"
    rc = main(["contact", "pyramid", "--N", "0.946", "--cell", "3.78", "--dx", "0.2", "--roughness",
               "--roughness-hurst", "0.7", "--roughness-rms-height", "0.3", "--roughness-short-cutoff", "0.5",
               "--roughness-seed", "2", "--d-min", "0", "--d-max", "1", "--d-step", "0.5", "--quiet",
               "--out", str(out)])
    assert rc == 0 and out.exists()
    head = [ln for ln in out.read_text().splitlines() if ln.startswith("#")]
    for line in ("# roughness: true", "# roughness_hurst: 0.7", "# roughness_rms_height: 0.3",
                 "# roughness_short_cutoff: 0.5", "# roughness_long_cutoff: 3.78", "# roughness_seed: 2"):
        assert line in head, line


ON = ["--roughness", "--roughness-short-cutoff", "0.5"]  # >= 2 pixels at dx 0.2


@pytest.mark.parametrize("args, words", [
    (["--roughness-seed", "3"], "roughness_seed applies only with roughness = true"),
    (["--roughness", "false", "--roughness-hurst", "0.5", "--roughness-rms-height", "1"],
     "roughness_hurst, roughness_rms_height apply only with roughness = true"),
    (ON + ["--roughness-hurst", "1.2"], "roughness_hurst must be in (0, 1), got 1.2"),
    (ON + ["--roughness-hurst", "0"], "roughness_hurst must be in (0, 1), got 0"),
    (ON + ["--roughness-rms-height", "-1"], "roughness_rms_height must be finite and > 0, got -1"),
    (ON + ["--roughness-rms-slope", "-0.2"], "roughness_rms_slope must be finite and > 0, got -0.2"),
    (ON + ["--roughness-rms-height", "1", "--roughness-rms-slope", "0.2"],
     "give roughness_rms_height or roughness_rms_slope, not both"),
    (["--roughness", "--roughness-short-cutoff", "0.3"], "roughness_short_cutoff = 0.3 (X units) is below 2 pixels"),
    (["--roughness"], "roughness_short_cutoff = 0.118125 (X units) is below 2 pixels"),  # default cell/32
    (["--roughness", "--roughness-short-cutoff", "2", "--roughness-long-cutoff", "1.5"],
     "roughness_short_cutoff = 2 must be below roughness_long_cutoff = 1.5"),
    (ON + ["--roughness-long-cutoff", "5"], "roughness_long_cutoff = 5 exceeds the shape's cell 3.78"),
    (ON + ["--roughness-seed", "-1"], "roughness_seed must be an integer >= 0"),
    (ON + ["--roughness-rms-height", "5nm"], "roughness_rms_height = '5nm' has a unit, but this run is "
     "dimensionless"),
    (ON + ["--roughness-hurst", "abc"], "roughness_hurst is dimensionless: give a plain number"),
    (["--roughness", "maybe"], "roughness must be true or false"),
])
def test_bad_values_are_one_line_exit_2_nothing_written(args, words, tmp_path, capsys):
    out = tmp_path / "b.csv"
    base = ["contact", "pyramid", "--N", "0.946", "--cell", "3.78", "--dx", "0.2", "--out", str(out)]
    assert main(base + args) == 2
    err = capsys.readouterr().err.strip()
    assert words in err and len(err.splitlines()) == 1, err
    assert not out.exists()


def test_rough_shape_refuses_roughness(tmp_path, capsys):
    out = tmp_path / "r.csv"
    rc = main(["contact", "rough", "--cell", "8", "--short-cutoff", "1", "--dx", "0.4", "--boundary", "periodic",
               "--roughness", "--roughness-short-cutoff", "1", "--out", str(out)])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and "shape rough is already rough" in err and len(err.splitlines()) == 1 and not out.exists()
    with pytest.raises(TengsimError, match="already rough"):
        Roughened(Rough(cell=8.0, short_cutoff=1.0))


def test_roughness_on_an_array_is_periodic_in_the_super_cell():
    plan = plan_contact({"shape": "array", "K": 2, "N": 0.946, "cell": 3.78, "dx": 0.2, "roughness": True,
                         "roughness_short_cutoff": 0.5, "roughness_rms_height": 0.2})
    s = plan.shape
    assert s.cell == pytest.approx(2 * 3.78) and s.long_cutoff == pytest.approx(2 * 3.78)
    g = s.grid(plan.dx)
    assert getattr(g, "cells", 1) == 2  # the array's grid (its observer counts cells) is kept
    h = s.heights(g)
    assert abs(h.std() - 0.2) < 1e-9
