"""The docs infrastructure: stored notebook, floors file, docstring escaping, notebook runner."""
from __future__ import annotations

import importlib.util
import json
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOK = ROOT / "docs" / "tutorial" / "tutorial.ipynb"
RUNNER = ROOT / "docs" / "tutorial" / "run_notebook.py"


def _load(path: Path, name: str):
    spec = importlib.util.spec_from_file_location(name, path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_tutorial_is_stored_without_outputs():
    nb = json.loads(NOTEBOOK.read_text(encoding="utf-8"))
    code = [c for c in nb["cells"] if c["cell_type"] == "code"]
    assert len(code) >= 5
    for c in code:
        assert c["outputs"] == [] and c["execution_count"] is None, "strip the outputs before committing"


def test_floors_pin_every_lower_bound_of_pyproject():
    try:
        import tomllib
    except ModuleNotFoundError:  # Python 3.10
        tomllib = pytest.importorskip("tomli")
    deps = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]["dependencies"]
    floors = {}
    for line in (ROOT / ".ci" / "floors.txt").read_text(encoding="utf-8").splitlines():
        line = line.split("#")[0].strip()
        if line:
            name, ver = line.split("==")
            floors[name.strip().lower()] = ver.strip()
    checked = 0
    for dep in deps:
        if ";" in dep:  # environment markers (tomli on 3.10) are not floors of the tested interpreter
            continue
        m = re.fullmatch(r"([A-Za-z0-9_.\-\[\]]+)>=([0-9.]+)", dep.replace(" ", ""))
        assert m, f"dependency {dep!r} has no plain lower bound"
        name = re.sub(r"\[.*\]", "", m.group(1)).lower()
        assert name in floors, f"{name} missing from .ci/floors.txt"
        have = [int(x) for x in floors[name].split(".")]
        want = [int(x) for x in m.group(2).split(".")]
        assert have[:len(want)] == want, f"{name}: pyproject says >={m.group(2)}, floors.txt pins {floors[name]}"
        checked += 1
    assert checked >= 6


def test_docstring_bars_are_escaped_outside_literals():
    conf = _load(ROOT / "docs" / "conf.py", "tengsim_docs_conf")
    assert conf._escape_bars("max |r| of Eq. (9)") == r"max \|r\| of Eq. (9)"
    assert conf._escape_bars("|X − Y| and |q|") == r"\|X − Y\| and \|q\|"
    assert conf._escape_bars("``|x|`` stays") == "``|x|`` stays"
    assert conf._escape_bars("a | b or c|d") == "a | b or c|d"
    lines = ["Example::", "", "    |x| kept", "", "after |y|"]
    conf._process_docstring(None, "function", "f", None, {}, lines)
    assert lines == ["Example::", "", "    |x| kept", "", r"after \|y\|"]


@pytest.mark.slow  # starts a Jupyter kernel (~3-6 s)
def test_notebook_runner_fails_on_a_cell_error(tmp_path):
    nbformat = pytest.importorskip("nbformat")
    pytest.importorskip("nbclient")
    pytest.importorskip("ipykernel")
    nb = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell("x = 1"),
                                         nbformat.v4.new_code_cell("raise ValueError('boom')")])
    nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3", "language": "python"}
    bad = tmp_path / "bad.ipynb"
    nbformat.write(nb, bad)
    run = subprocess.run([sys.executable, str(RUNNER), str(bad), "--timeout", "60"],
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 1
    assert "boom" in run.stderr and "FAILED" in run.stdout
