"""The `rough` shape (issue 23, item 1): a periodic self-affine random surface from SurfaceTopography's
generator, reproducible from its seed, refusing bad values with one line."""
from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from tengsim.cli.main import main
from tengsim.config import plan_contact
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
