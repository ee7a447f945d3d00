"""The `rough` shape (issue 23, item 1): a periodic self-affine random surface from SurfaceTopography's
generator, reproducible from its seed, refusing bad values with one line."""
from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from tengsim.cli.main import main
from tengsim.run.plan import plan_contact
from tengsim.errors import TengsimError
from tengsim.grid import Grid
from tengsim.shapes import Rough

_U0 = ("import numpy as np, sys; from tengsim.shapes import Rough; r = Rough(cell=16.0, hurst=0.7, "
       "rms_slope=0.2, short_cutoff=1.0, seed=5); sys.stdout.write(r.gap(r.grid(0.25)).tobytes().hex())")


def test_same_seed_same_surface_in_and_across_processes():
    r = Rough(cell=16.0, hurst=0.7, rms_slope=0.2, short_cutoff=1.0, seed=5)
    g = r.grid(0.25)
    a = r.gap(g)
    assert np.array_equal(a, Rough(cell=16.0, hurst=0.7, rms_slope=0.2, short_cutoff=1.0, seed=5).gap(g))
    other = subprocess.run([sys.executable, "-c", _U0], capture_output=True, text=True, check=True).stdout
    assert other == a.tobytes().hex()  # another process: the same bytes
    assert not np.array_equal(a, Rough(cell=16.0, hurst=0.7, rms_slope=0.2, short_cutoff=1.0, seed=6).gap(g))
    assert a.min() == 0.0 and np.all(a >= 0)


# Fourier coefficients of three surfaces, recorded with SurfaceTopography 1.27.1 / NumPy 2.4.6 and equal to
# ~1e-15 with 1.18.2 / NumPy 1.24 (the floor), 1.19.0 / 2.0.2 and 1.24.0 / 2.4.6: the same seed draws the same
# surface on every supported release (CI runs this file on the floors and on the newest versions).
_RECORDED = [
    ((16.0, 0.7, None, 0.2, 1.0, None, 5), 35, 0.0107888416069533 + 0.007831221427263663j,
     8.318054246890529e-05 + 0.0027149794873276077j, 1.7922163752206117),
    ((32.0, 0.8, 1.5, None, 2.0, 32.0, 1), 35, 0.0004547570544967187 - 0.0013776351820720485j,
     0.11046599361181349 - 0.04416266373702701j, 13.454920773895449),
    ((3.78, 0.8, 0.4, None, 0.4, None, 0), 21, -0.007103173097059352 + 0.0035857698204021637j,
     -0.010470557166544492 - 0.004576653601425912j, 2.446074352781302),
]


@pytest.mark.parametrize("args, n, c12, c3m1, total", _RECORDED)
def test_the_same_seed_draws_the_same_surface_on_every_supported_release(args, n, c12, c3m1, total):
    from tengsim.shapes.rough import _coefficients

    c, n_ref = _coefficients(*args)
    assert n_ref == n
    scale = float(np.abs(c).max())
    assert abs(c[1, 2] - c12) < 1e-12 * scale and abs(c[3, -1] - c3m1) < 1e-12 * scale
    assert float(np.abs(c).sum()) == pytest.approx(total, rel=1e-12)


def test_the_draw_leaves_numpys_global_random_state_as_it_was():
    from tengsim.shapes.rough import _coefficients

    np.random.seed(123)
    expected = np.random.random(3)
    np.random.seed(123)
    _coefficients(16.0, 0.7, None, 0.2, 1.0, None, 11)  # a seed not drawn elsewhere: not cached
    assert np.array_equal(np.random.random(3), expected)


def test_rms_height_and_slope_as_requested_and_the_same_surface_on_a_finer_grid():
    r = Rough(cell=32.0, hurst=0.8, rms_height=1.5, short_cutoff=2.0, seed=1)
    coarse, fine = Grid.square(32.0, 32 / 33), Grid.square(32.0, 32 / 99)  # 33 and 99 pixels: every 3rd shared
    hc, hf = r.heights(coarse), r.heights(fine)
    assert abs(hc.std() - 1.5) < 1e-9 and abs(hf.std() - 1.5) < 1e-9
    assert np.allclose(hf[1::3, 1::3], hc, atol=1e-9)  # Fourier interpolation of one band-limited surface
    s = Rough(cell=32.0, hurst=0.5, rms_slope=0.2, short_cutoff=2.0, seed=1)
    g = s.grid(0.5)
    h = s.heights(g)
    H = np.fft.fft2(h) / h.size
    q = 2 * np.pi * np.fft.fftfreq(g.nx, d=g.dx)
    assert abs(np.sqrt(np.sum(np.abs(H) ** 2 * (q[:, None] ** 2 + q[None, :] ** 2))) - 0.2) < 1e-9


def test_cli_runs_a_rough_surface(tmp_path, capsys):
    out = tmp_path / "r.csv"
    rc = main(["contact", "rough", "--hurst", "0.8", "--rms-slope", "0.2", "--cell", "8", "--short-cutoff", "1",
               "--seed", "3", "--dx", "0.4", "--boundary", "periodic", "--d-min", "0", "--d-max", "1",
               "--d-step", "1", "--out", str(out)])
    assert rc == 0 and out.exists()


@pytest.mark.parametrize("args, words", [
    (["--hurst", "1.2"], "hurst must be in (0, 1), got 1.2"),
    (["--hurst", "0"], "hurst must be in (0, 1)"),
    (["--rms-height", "1", "--rms-slope", "0.2"], "give rms_height or rms_slope, not both"),
    (["--short-cutoff", "6", "--long-cutoff", "4"], "short_cutoff = 6 must be below long_cutoff = 4"),
    (["--long-cutoff", "20"], "long_cutoff = 20 exceeds the cell 8"),
    (["--short-cutoff", "0.3"], "short_cutoff = 0.3 is below 2 pixels"),
    (["--seed", "-1"], "seed must be an integer >= 0"),
    (["--cell", "-8"], "cell"),
    (["--rms-height", "-1"], "rms_height"),
    (["--boundary", "free"], "boundary = 'free' is refused"),
])
def test_bad_values_are_one_line_exit_2_nothing_written(args, words, tmp_path, capsys):
    out = tmp_path / "b.csv"
    base = ["contact", "rough", "--cell", "8", "--short-cutoff", "1", "--dx", "0.4", "--out", str(out)]
    if "--boundary" not in args:
        base += ["--boundary", "periodic"]
    assert main(base + args) == 2
    err = capsys.readouterr().err.strip()
    assert words in err and len(err.splitlines()) == 1, err
    assert not out.exists()


def test_free_boundary_is_refused_by_default():
    with pytest.raises(TengsimError, match="boundary = 'free' is refused"):
        plan_contact({"shape": "rough", "cell": 8.0, "short_cutoff": 1.0, "dx": 0.4})


def test_physical_input_plans_with_ell_eps():
    plan = plan_contact({"shape": "rough", "cell": "2um", "rms_height": "5nm", "short_cutoff": "0.2um",
                         "eps": "1nm", "E_star": "1MPa", "W": "50mJ/m2", "dx": "50nm", "boundary": "periodic"})
    s = plan.shape
    assert s.cell == pytest.approx(2000) and s.rms_height == pytest.approx(5) and s.short_cutoff == pytest.approx(200)
    assert s.long_cutoff == pytest.approx(2000) and plan.dx == pytest.approx(50)
    assert plan.scaling.lateral == pytest.approx(1e-9)
