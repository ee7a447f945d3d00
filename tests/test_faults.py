"""Bad input, generated: every bad CLI value and every bad study file gets one line, exit 2, nothing written.

Hypothesis draws the bad values (non-positive, NaN, infinite, text, a unit on a dimensionless key, a choice
not offered) and the key they go to; each is sent through the real command line in process (no solve is
reached: validation refuses before any work).  The table of faults tried, and what happened, is in
docs/statuses.md ("Faults and bad input").
"""
import math

import pytest

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from tengsim.cli.main import main  # noqa: E402
from tengsim.registry import SOLVERS  # noqa: E402

BASE = ["contact", "pyramid", "--N", "0.946", "--cell", "3.78", "--dx", "0.3", "--d-min", "0", "--d-max", "0.5",
        "--d-step", "0.5", "--quiet"]
# keys whose value must be a finite number > 0 in a dimensionless pyramid run
POSITIVE = ["--N", "--cell", "--tabor", "--dx", "--d-step", "--tol"]
CHOICES = {"--boundary": ("free", "periodic"), "--solver": SOLVERS.names(), "--law": ("lj93",),
           "--control": ("approach", "load"), "--substrate": ("bonded", "frictionless")}

non_positive = st.floats(max_value=0.0, allow_nan=False, allow_infinity=False).map(repr)
not_finite = st.sampled_from(["nan", "inf", "-inf", "NaN", "Infinity"])
words = st.text(alphabet="abcdefghijklmnopqrstuvwxyz", min_size=1, max_size=8).filter(
    lambda w: w not in ("nan", "inf", "infinity", "e"))
with_unit = st.sampled_from(["2um", "0.5MPa", "54mJ/m2", "1nm", "3 kPa"])
bad_number = st.one_of(non_positive, not_finite, words, with_unit)

SETTINGS = settings(max_examples=40, deadline=None, derandomize=True,
                    suppress_health_check=[HealthCheck.function_scoped_fixture])


def _refused(tmp_path, capsys, argv, out):
    rc = main(argv)
    err = capsys.readouterr().err
    lines = err.strip().splitlines()
    assert rc == 2, (argv, err)
    assert len(lines) == 1 and lines[0].startswith("tengsim: error:"), (argv, err)
    assert "Traceback" not in err
    assert not out.exists() and list(tmp_path.iterdir()) == [], argv
    return lines[0]


@SETTINGS
@given(key=st.sampled_from(POSITIVE), value=bad_number)
def test_bad_cli_number_is_one_line_exit_2_nothing_written(tmp_path_factory, capsys, key, value):
    tmp = tmp_path_factory.mktemp("cli")
    out = tmp / "x.csv"
    argv = list(BASE)
    if key in argv:
        argv[argv.index(key) + 1] = value
    else:
        argv += [key, value]
    line = _refused(tmp, capsys, argv + ["--out", str(out)], out)
    name = key[2:].replace("-", "_")
    assert name in line or value.strip() in line, line


@SETTINGS
@given(key=st.sampled_from(sorted(CHOICES)), value=words)
def test_a_choice_not_offered_is_named(tmp_path_factory, capsys, key, value):
    hypothesis.assume(value not in CHOICES[key] and value not in ("md", "exp", "lj", "paper", "hertz", "dugdale",
                                                                    "repulsive", "exponential", "nonadhesive"))
    tmp = tmp_path_factory.mktemp("choice")
    out = tmp / "x.csv"
    line = _refused(tmp, capsys, BASE + [key, value, "--out", str(out)], out)
    assert value in line, line


STUDY_KEYS = {"tabor": "contact.tabor", "dx": "contact.dx", "d_step": "contact.d_step", "N": "contact.N",
              "cell": "contact.cell"}


@SETTINGS
@given(key=st.sampled_from(sorted(STUDY_KEYS)), value=st.one_of(
    st.floats(max_value=0.0, allow_nan=False, allow_infinity=False), st.just(math.nan), words, with_unit))
def test_bad_study_axis_value_refuses_the_study(tmp_path_factory, capsys, key, value):
    """A generated study file with one bad value on one axis: one line naming it, exit 2, no study folder."""
    tmp = tmp_path_factory.mktemp("study")
    bad = repr(value) if isinstance(value, float) and value == value else (
        "nan" if isinstance(value, float) else f'"{value}"')
    toml = (tmp / "s.toml")
    toml.write_text(f"""
[base.contact]
shape = "pyramid"
N = 0.946
cell = 3.78
dx = 0.3
d_min = 0
d_max = 0.5
d_step = 0.5

[axes]
"{STUDY_KEYS[key]}" = [0.5, {bad}]
""")
    out = tmp / "study"
    rc = main(["sweep", str(toml), "--out", str(out), "--workers", "1", "--quiet"])
    err = capsys.readouterr().err
    lines = err.strip().splitlines()
    assert rc == 2, err
    assert len(lines) == 1 and lines[0].startswith("tengsim: error:"), err
    assert not out.exists()
