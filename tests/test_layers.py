"""The layers of src/tengsim hold: import-linter's contracts (pyproject.toml) and no import cycle at all.

The contract names each layer (README "Layout"); a module may import only its own layer and those below,
not even inside a function.  These tests run the real checker on the real tree, and once more on a copy
with one upward import added, which must fail.
"""
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

grimp = pytest.importorskip("grimp")

ROOT = Path(__file__).resolve().parents[1]
SRC = ROOT / "src"


def _lint(src: Path):
    """Run lint-imports with the project's contracts against the package under ``src``."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(src), os.environ.get("PYTHONPATH", "")]))
    exe = shutil.which("lint-imports") or str(Path(sys.executable).with_name("lint-imports"))
    return subprocess.run([exe, "--no-cache", "--config", str(ROOT / "pyproject.toml")], cwd=src.parent,
                          env=env, capture_output=True, text=True)


def test_layer_contracts_are_kept():
    r = _lint(SRC)
    assert r.returncode == 0, r.stdout[-4000:] + r.stderr[-2000:]
    assert "BROKEN" not in r.stdout and "KEPT" in r.stdout


def test_an_upward_import_breaks_the_contract(tmp_path):
    """units (foundation) importing contact (a driver) inside a function is caught."""
    copy = tmp_path / "src"
    shutil.copytree(SRC / "tengsim", copy / "tengsim", ignore=shutil.ignore_patterns("__pycache__"))
    units = copy / "tengsim" / "units.py"
    units.write_text(units.read_text() + "\n\ndef _upward():\n    from tengsim.run.simulate import simulate\n"
                     "    return simulate\n")
    r = _lint(copy)
    assert r.returncode != 0
    assert "tengsim.units -> tengsim.run.simulate" in r.stdout, r.stdout[-3000:]


def _cycles(graph) -> list:
    """Strongly connected components of more than one module (Tarjan, iterative)."""
    mods = sorted(graph.modules)
    index, low, on, stack, out = {}, {}, set(), [], []
    counter = [0]
    for root in mods:
        if root in index:
            continue
        work = [(root, iter(sorted(graph.find_modules_directly_imported_by(root))))]
        index[root] = low[root] = counter[0]
        counter[0] += 1
        stack.append(root)
        on.add(root)
        while work:
            v, it = work[-1]
            for w in it:
                if w not in index:
                    index[w] = low[w] = counter[0]
                    counter[0] += 1
                    stack.append(w)
                    on.add(w)
                    work.append((w, iter(sorted(graph.find_modules_directly_imported_by(w)))))
                    break
                if w in on:
                    low[v] = min(low[v], index[w])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[v])
                if low[v] == index[v]:
                    comp = []
                    while True:
                        w = stack.pop()
                        on.discard(w)
                        comp.append(w)
                        if w == v:
                            break
                    if len(comp) > 1:
                        out.append(sorted(comp))
    return out


def test_no_module_imports_another_that_imports_it_back():
    sys.path.insert(0, str(SRC))
    try:
        graph = grimp.build_graph("tengsim", cache_dir=None)
    finally:
        sys.path.remove(str(SRC))
    assert len(graph.modules) > 60
    assert _cycles(graph) == []
    # and the package's own facade is imported by nothing inside it: it is the user's entry point only
    assert graph.find_modules_that_directly_import("tengsim") == set()


def test_the_cycle_finder_finds_a_cycle():
    g = grimp.ImportGraph()
    for m in ("p", "p.a", "p.b", "p.c"):
        g.add_module(m)
    g.add_import(importer="p.a", imported="p.b")
    g.add_import(importer="p.b", imported="p.c")
    g.add_import(importer="p.c", imported="p.a")
    assert _cycles(g) == [["p.a", "p.b", "p.c"]]
