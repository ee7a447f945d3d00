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


def test_wrapping_solvers_return_new_values():
    """The mirror and slab solvers build the equilibrium they return complete (issue 28, item 5):
    a FoldedEquilibrium takes its mirror at construction and refuses any later assignment; the
    slab solver's gathered equilibrium is a new value, the inner solver's left as it was."""
    import dataclasses

    from tengsim.solvers.distributed import SlabSolver
    from tengsim.solvers.mirror import FoldedEquilibrium
    from tengsim.solvers.types import Equilibrium, State

    z = np.zeros((2, 2))
    eq = FoldedEquilibrium(State(z, z), z, z, 0.0, True, 1, 2, 0.0, 0.0, "ok", mirror=None)
    for name in ("_mirror", "H", "residual"):
        with pytest.raises(dataclasses.FrozenInstanceError):
            setattr(eq, name, 1)
    assert eq._mirror is None and eq.H is z

    inner_eq = Equilibrium(State(z[:1], z[:1]), z[:1], z[:1], 0.5, True, 3, 4, -1.0, 0.1, "converged")

    class Comm:
        def allreduce(self, v, op=None):
            return 2.0 * v

    class Slab:  # a one-row slab of a 2-row grid, duck-typed as tengsim.kernels.distributed's
        comm, rows, local_shape = Comm(), (0, 1), (1, 2)

        class grid:
            shape = (2, 2)

        @staticmethod
        def gather(a):
            return np.vstack([a, a])

    class Inner:
        def solve(self, problem, start):
            return inner_eq

    pytest.importorskip("mpi4py", reason="SlabSolver reduces max|r| with MPI.MAX")
    from tengsim.solvers.types import Problem
    out = SlabSolver(Inner()).solve(Problem(np.ones((2, 2)), None, Slab()), State(np.zeros((2, 2)), np.zeros((2, 2))))
    assert out is not inner_eq and out.H.shape == (2, 2) and out.residual == 1.0
    assert inner_eq.H.shape == (1, 2) and inner_eq.residual == 0.5
