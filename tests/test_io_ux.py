"""Result files as users meet them: strict JSON, ordinary permissions, a fast exact CSV writer."""
import json
import os
from pathlib import Path

import numpy as np
import pytest

from tengsim import io
from tengsim.results.read import _read_csv


def _strict(text):
    return json.loads(text, parse_constant=lambda c: pytest.fail(f"non-JSON constant {c} written"))


def test_write_json_is_strict_json(tmp_path):
    """NaN and ±inf (Python, numpy scalars, inside arrays and nested dicts) come out as null."""
    p = tmp_path / "summary.json"
    obj = {"pull_off": float("nan"), "a": np.float64("inf"), "arr": np.array([1.5, np.nan, -np.inf]),
           "nested": {"x": [np.float32(2.5), -float("inf")], 3: (np.int64(4), True)}, "ok": 0.1}
    io.write_json(p, obj)
    got = _strict(p.read_text())
    assert got == {"pull_off": None, "a": None, "arr": [1.5, None, None],
                   "nested": {"x": [2.5, None], "3": [4, True]}, "ok": 0.1}


def test_dumps_refuses_nothing_slips_through():
    assert io.dumps({"v": [float("nan")]}) == '{"v": [null]}'
    assert "NaN" not in io.dumps(np.full((2, 2), np.nan))


def test_csv_header_is_strict_json(tmp_path):
    p = tmp_path / "t.csv"
    io.write_csv(p, {"D": [1.0, 2.0]}, header={"pull_off_F": float("nan"), "list": [np.inf]})
    head = [line for line in p.read_text().splitlines() if line.startswith("#")]
    for line in head:
        _strict(line.partition(":")[2])
    header, _ = _read_csv(p)
    assert header == {"pull_off_F": None, "list": [None]}


@pytest.fixture
def umask():
    old = os.umask(0o022)
    yield lambda m: os.umask(m)
    os.umask(old)


def _mode(p):
    return os.stat(p).st_mode & 0o777


def test_new_files_follow_the_umask(tmp_path, umask):
    io.write_text(tmp_path / "a.txt", "x")
    io.write_json(tmp_path / "a.json", {})
    io.write_csv(tmp_path / "a.csv", {"D": [1.0]})
    for name in ("a.txt", "a.json", "a.csv"):
        assert _mode(tmp_path / name) == 0o644, name
    umask(0o077)
    io.write_text(tmp_path / "b.txt", "x")
    assert _mode(tmp_path / "b.txt") == 0o600


def test_overwrite_keeps_the_files_mode(tmp_path, umask):
    p = tmp_path / "r.csv"
    p.write_text("old\n")
    os.chmod(p, 0o644)
    io.write_csv(p, {"D": [1.0]})
    assert _mode(p) == 0o644
    os.chmod(p, 0o640)
    io.write_text(p, "new")
    assert _mode(p) == 0o640 and p.read_text() == "new"
    assert [q.name for q in tmp_path.iterdir()] == ["r.csv"]  # no temporary left behind


def test_netcdf_and_figures_follow_the_umask(tmp_path, umask):
    import xarray as xr

    from tengsim.plots import pyplot, save

    io.write_dataset(xr.Dataset({"a": ("x", [1.0, 2.0])}), tmp_path / "d.nc")
    fig = pyplot().figure()
    save(fig, tmp_path / "f.png")
    assert _mode(tmp_path / "d.nc") == 0o644 and _mode(tmp_path / "f.png") == 0o644


def _per_cell_csv(columns, header):
    """The per-cell writer this package had before (reference for the format and the speed)."""
    names = list(columns)
    arrays = [np.asarray(columns[k]) for k in names]
    lines = [f"# {k}: {json.dumps(v)}" for k, v in header.items()]
    lines.append(",".join(names))
    for i in range(len(arrays[0])):
        row = []
        for a in arrays:
            x = a[i]
            if isinstance(x, (float, np.floating)):
                row.append(repr(float(x)))
            elif isinstance(x, (bool, np.bool_)):
                row.append(str(int(x)))
            else:
                row.append(str(x))
        lines.append(",".join(row))
    return "\n".join(lines) + "\n"


def _table(n, seed=0):
    rng = np.random.default_rng(seed)
    F = rng.standard_normal(n) * 10.0 ** rng.integers(-300, 300, n)
    F[:12] = [np.nan, np.inf, -np.inf, -0.0, 0.0, 1e16, 9999999999999998.0, 1e-5, 5e-324, 0.1, 1 / 3, 2.0**60]
    return {"branch": np.where(rng.random(n) < 0.5, "approach", "retraction"),
            "D": np.round(rng.uniform(-1, 14, n), 2), "F": F,
            "contact_length": rng.random(n).astype(np.float32).astype(float),
            "converged": rng.random(n) < 0.9, "iterations": rng.integers(0, 3000, n)}


def test_csv_same_format_and_exact_round_trip(tmp_path):
    cols = _table(2000)
    p = tmp_path / "t.csv"
    io.write_csv(p, cols, header={"nx": 5})
    assert p.read_text() == _per_cell_csv(cols, {"nx": 5})
    _, back = _read_csv(p)
    for k in ("D", "F", "contact_length", "iterations"):
        np.testing.assert_array_equal(back[k], cols[k])  # exact (NaN == NaN here)
    assert np.array_equal(np.signbit(back["F"]), np.signbit(cols["F"]))  # -0.0 kept
    assert (back["converged"] == cols["converged"]).all() and (back["branch"] == cols["branch"]).all()


def _python_calls(fn):
    """Function calls made from Python code while running ``fn``: Python functions and builtins called
    from Python (a builtin that ``map`` applies inside C is not counted)."""
    import sys

    n = 0

    def prof(frame, event, arg):
        nonlocal n
        n += event in ("call", "c_call")

    sys.setprofile(prof)
    try:
        fn()
    finally:
        sys.setprofile(None)
    return n


def test_csv_100k_rows_no_per_row_python(tmp_path):
    """The writer runs no Python code per row: 1 000 and 100 000 rows × 6 mixed columns cost the same
    few hundred calls from Python code, give or take a few inside NumPy (the per-cell loop it replaced
    made several per cell), and the big file reads
    back exactly. Its speed against the per-cell loop is measured, not gated: benchmarks/csv_write.py."""
    small, big = _table(1_000, seed=1), _table(100_000, seed=1)
    n_small = _python_calls(lambda: io.write_csv(tmp_path / "small.csv", small))
    n_big = _python_calls(lambda: io.write_csv(tmp_path / "big.csv", big))
    n_loop = _python_calls(lambda: _per_cell_csv(small, {}))
    assert abs(n_big - n_small) < 0.2 * n_small and n_big < 1_000, (n_small, n_big)
    assert n_loop > 1_000 > n_small, (n_loop, n_small)  # the check can fail: the old loop trips it
    _, back = _read_csv(tmp_path / "big.csv")
    np.testing.assert_array_equal(back["F"], big["F"])
    assert (back["branch"] == big["branch"]).all()


def test_csv_text_with_commas_quotes_and_newlines_round_trips(tmp_path):
    """Text cells and names holding a comma, a quote or a newline are quoted (csv module, minimal quoting:
    plain cells stay bare) and read back whole; a cell starting with '#' is data, not a header line."""
    p = tmp_path / "q.csv"
    notes = ["plain", 'a, "b"', 'say "hi"', "two\nlines", "", "#not a header"]
    io.write_csv(p, {"label": ["#x", "y", "z", "w", "v", "u"], "D": np.arange(6.0), "note": notes,
                     'n, "count"': np.arange(6)}, header={"title": 'a, "b"'})
    text = p.read_text()
    assert '"a, ""b"""' in text and '"say ""hi"""' in text and "\n#x,0.0,plain,0\n" in text
    header, back = _read_csv(p)
    assert header == {"title": 'a, "b"'}
    assert list(back) == ["label", "D", "note", 'n, "count"']
    assert back["note"].tolist() == notes and back["label"][0] == "#x"
    np.testing.assert_array_equal(back["D"], np.arange(6.0))
    np.testing.assert_array_equal(back['n, "count"'], np.arange(6))


def test_csv_text_missing_cells_left_empty():
    """``missing``: None and non-finite floats (float and object columns) become that text; others as ever."""
    cols = {"x": [1.5, np.nan, np.inf], "o": np.array([None, 2.0, float("-inf")], dtype=object),
            "b": [True, False, True], "s": ["a", "b,c", "d"]}
    assert io.csv_text(cols, missing="") == 'x,o,b,s\n1.5,,1,a\n,2.0,0,"b,c"\n,,1,d\n'
    assert io.csv_text(cols).splitlines()[1:] == ["1.5,None,1,a", "nan,2.0,0,\"b,c\"", "inf,-inf,1,d"]


def test_csv_unequal_columns_refused(tmp_path):
    from tengsim.errors import TengsimError

    with pytest.raises(TengsimError, match="unequal length: a=2, b=3"):
        io.write_csv(tmp_path / "x.csv", {"a": [1, 2], "b": [1, 2, 3]})
    assert list(tmp_path.iterdir()) == []


def test_package_data_entries_exist():
    """Every [tool.setuptools.package-data] pattern names files that exist (no phantom data folder)."""
    try:
        import tomllib
    except ModuleNotFoundError:  # Python 3.10
        import tomli as tomllib
    root = Path(__file__).resolve().parents[1]
    cfg = tomllib.loads((root / "pyproject.toml").read_text())
    pkg_data = cfg.get("tool", {}).get("setuptools", {}).get("package-data", {})
    for pkg, patterns in pkg_data.items():
        for pat in patterns:
            assert list((root / "src" / pkg.replace(".", "/")).glob(pat)), f"{pkg}: {pat} matches nothing"


@pytest.fixture
def python_sigint():
    """SIGINT raising KeyboardInterrupt, as in an interactive run (CI may start us with it ignored)."""
    import signal

    old = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, old)


def test_ctrl_c_waits_for_a_netcdf_write_then_arrives(tmp_path, python_sigint):
    """SIGINT during write_dataset: the write finishes (the file is whole, no .part left), then
    KeyboardInterrupt is raised; the caller's handler is back in place afterwards."""
    import signal

    import xarray as xr

    ds = xr.Dataset({"F": ("D", np.linspace(0.0, 1.0, 50))})

    class Interrupted:  # a dataset whose write is hit by Ctrl-C half-way (made in memory: path None)
        def to_netcdf(self, path=None, engine=None):
            signal.raise_signal(signal.SIGINT)
            return ds.to_netcdf(path, engine=engine)

    before = signal.getsignal(signal.SIGINT)
    with pytest.raises(KeyboardInterrupt):
        io.write_dataset(Interrupted(), tmp_path / "r.nc")
    assert signal.getsignal(signal.SIGINT) is before
    assert xr.load_dataset(tmp_path / "r.nc", engine="h5netcdf").identical(ds)
    assert not list(tmp_path.glob(".*.part"))


def test_interrupts_held_nests_and_respects_an_ignored_sigint(python_sigint):
    """A nested hold delivers to the outer one (one KeyboardInterrupt, after the outer block); with
    SIGINT ignored by the caller nothing is raised; without a signal nothing changes."""
    import signal

    steps = []
    with pytest.raises(KeyboardInterrupt):
        with io.interrupts_held():
            with io.interrupts_held():
                signal.raise_signal(signal.SIGINT)
                steps.append("inner")
            steps.append("outer")
    assert steps == ["inner", "outer"]
    old = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        with io.interrupts_held():
            signal.raise_signal(signal.SIGINT)
        assert signal.getsignal(signal.SIGINT) is signal.SIG_IGN
    finally:
        signal.signal(signal.SIGINT, old)
    with io.interrupts_held():
        steps.append("quiet")
    assert steps[-1] == "quiet"
