"""Start-up and help of the command line: `tengsim --version`/`--help` import no numerical library, and
`tengsim contact SHAPE --help` is one page per registered shape (its keys, then the common ones)."""
import subprocess
import sys
import time

import pytest

from tengsim.cli.keyhelp import shape_keys
from tengsim.cli.main import main
from tengsim.run.keys import common_fields, law_keys
from tengsim.registry import SHAPES

HEAVY = ("numpy", "scipy", "xarray", "matplotlib", "dask", "SurfaceTopography")


def _imports_after(argv):
    """Run `tengsim ARGV` in a fresh interpreter; return (the heavy modules it imported, stdout, seconds)."""
    code = ("import sys\nfrom tengsim.cli.main import main\n"
            f"try:\n    main({argv!r})\nexcept SystemExit:\n    pass\n"
            f"print('HEAVY:' + ','.join(m for m in {HEAVY!r} if m in sys.modules))")
    t0 = time.perf_counter()
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    seconds = time.perf_counter() - t0
    heavy = out.rsplit("HEAVY:", 1)[1].strip()
    return [m for m in heavy.split(",") if m], out, seconds


@pytest.mark.parametrize("argv", [["--version"], ["--help"]])
def test_version_and_help_import_no_numerical_library(argv):
    heavy, out, seconds = _imports_after(argv)
    assert heavy == [], f"tengsim {' '.join(argv)} imported {heavy}"
    assert ("tengsim " in out) if argv == ["--version"] else ("contact" in out and "device" in out)
    assert seconds < 3.0  # generous (a loaded 2-core machine); measured ~0.1 s


def test_import_tengsim_is_light_and_the_api_still_there():
    heavy, _, _ = _imports_after([])
    assert heavy == []
    import tengsim

    assert tengsim.Pyramid.__name__ == "Pyramid" and callable(tengsim.resolve)
    assert set(tengsim.__all__) <= set(dir(tengsim))
    with pytest.raises(AttributeError):
        tengsim.no_such_name


def _page(capsys, argv):
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 0
    return capsys.readouterr().out


@pytest.mark.parametrize("shape", SHAPES.names())
def test_shape_help_is_one_page_with_its_keys_then_the_common_ones(shape, capsys):
    page = _page(capsys, ["contact", shape, "--help"])
    lines = page.splitlines()
    assert len(lines) <= 100, f"{shape}: {len(lines)} lines"
    flags = [ln.split()[0] for ln in lines if ln.startswith("  --")]
    own = ["--" + k.replace("_", "-") for k in shape_keys(shape)]
    common = ["--" + f.name.replace("_", "-") for f in common_fields() if f.name not in ("shape", "out", "plot")]
    assert flags[:len(own)] == own  # the shape's keys first, in schema order
    assert set(common) <= set(flags[len(own):])
    assert {"--" + k.replace("_", "-") for k in law_keys()} <= set(flags)
    others = {k for s in SHAPES.names() for k in shape_keys(s)} - set(shape_keys(shape)) - {
        f.name for f in common_fields()}
    assert not {"--" + k.replace("_", "-") for k in others} & set(flags)  # no other shape's key


def test_contact_help_lists_the_shapes_and_says_how_to_see_one(capsys):
    page = _page(capsys, ["contact", "--help"])
    assert "tengsim contact SHAPE --help" in page
    for name in SHAPES.names():
        assert any(ln.split()[:1] == [name] for ln in page.splitlines()), name
    assert len(page.splitlines()) < 316 // 2


@pytest.mark.parametrize("given,expected", [(None, "1"), ("3", "3")])
def test_the_command_line_runs_one_blas_thread_unless_told(given, expected):
    """The entry point sets OPENBLAS_NUM_THREADS (and MKL's) to 1 before NumPy loads, so NumPy's OpenBLAS runs
    one thread; a value the user set is kept."""
    import os

    env = {k: v for k, v in os.environ.items() if k not in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")}
    if given is not None:
        env["OPENBLAS_NUM_THREADS"] = given
    code = ("import sys, os\nfrom tengsim.cli import main\nassert 'numpy' not in sys.modules\n"
            "print(os.environ['OPENBLAS_NUM_THREADS'], os.environ['MKL_NUM_THREADS'])")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, env=env).stdout
    assert out.split() == [expected, "1"]
