"""The solvers' side of the array seam (issue 28, item 4): solve buffers are allocated through
tengsim.backend, and a fast solve brings its scalars to the host at most once per iteration."""
import io
import tokenize
from pathlib import Path

import numpy as np
import pytest

SOLVERS = Path(__file__).resolve().parents[1] / "src" / "tengsim" / "solvers"

#: NumPy allocators: a solve buffer made by one of these bypasses the backend
ALLOCATORS = {"empty", "zeros", "ones", "full", "empty_like", "zeros_like", "ones_like", "full_like"}
#: also copies, in the fast solver's own modules (its iterate and start arrays)
COPIES = {"array", "ascontiguousarray", "copy"}
FAST_PARTS = {"fast.py", "_workspace.py", "_lbfgs.py", "_sweep.py", "_linesearch.py", "types.py"}
#: modules whose NumPy arrays are not the backend's, each with its reason
EXEMPT = {"_reduce.py": "MPI reductions exchange host buffers",
          "_jax_loop.py": "JAX arrays, made by jax.numpy inside the compiled loop"}


def numpy_calls(text: str, names) -> list[str]:
    """Code (not comments or strings) calling np.<name> or numpy.<name> for a name in ``names``."""
    toks = [t for t in tokenize.generate_tokens(io.StringIO(text).readline)
            if t.type in (tokenize.NAME, tokenize.OP)]
    hits = []
    for i, t in enumerate(toks[:-3]):
        if (t.string in ("np", "numpy") and toks[i + 1].string == "." and toks[i + 2].string in names
                and toks[i + 3].string == "("):
            hits.append(f"{t.start[0]}: {t.line.strip()}")
    return hits


def test_solvers_allocate_through_the_backend():
    bad = {}
    for path in sorted(SOLVERS.glob("*.py")):
        if path.name in EXEMPT:
            continue
        names = ALLOCATORS | (COPIES if path.name in FAST_PARTS else set())
        found = numpy_calls(path.read_text(encoding="utf-8"), names)
        if found:
            bad[path.name] = found
    assert not bad, f"solve buffers allocated with NumPy, not tengsim.backend: {bad}"


@pytest.mark.parametrize("code", ["a = np.empty(5)\n", "b = numpy.zeros((2, 2))\n", "c = np.zeros_like(a)\n"])
def test_the_grep_catches_each_allocator(code):
    assert numpy_calls(code, ALLOCATORS)


def test_the_grep_ignores_comments_strings_and_other_calls():
    assert not numpy_calls('# np.empty(3) is the seam\ns = "np.zeros(2)"\nx = np.add(a, b)\nnp.empty\n',
                           ALLOCATORS)


def test_the_fast_solver_allocates_from_the_backend(monkeypatch):
    """Every workspace and memory array of a solve comes from backend.empty / backend.zeros."""
    from tengsim import backend
    from tengsim.solvers._workspace import Workspace

    made = []

    def spy(fn):
        def alloc(shape, dtype=float):
            a = fn(shape, dtype)
            made.append(a)
            return a
        return alloc

    monkeypatch.setattr(backend, "empty", spy(backend.empty))
    monkeypatch.setattr(backend, "zeros", spy(backend.zeros))
    ws = Workspace(64, 3, 0.1)
    ids = {id(a) for a in made}
    arrays = [getattr(ws, k) for k in ("g", "gt", "P", "Pt", "d", "Kd", "r", "rn", "G", "Gn", "y", "ky", "cP")]
    arrays += [ws.memory.B, ws.memory.KB, ws.memory.SY, ws.memory.YY, ws.memory.pS, ws.memory.pY]
    assert all(id(a) in ids for a in arrays)
    n = len(made)
    scratch = ws.sweeper.buf(ws.sweeper._scratch[0], "a", 10)     # the sweeper's scratch, made on first use
    assert len(made) == n + 1 and np.shares_memory(scratch, made[-1])
