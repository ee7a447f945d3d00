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
    a FoldedEquilibrium wraps the block's equilibrium with its mirror at construction and refuses any later
    assignment; the
    slab solver's gathered equilibrium is a new value, the inner solver's left as it was."""
    import dataclasses

    from tengsim.solvers.distributed import SlabSolver
    from tengsim.solvers.mirror import FoldedEquilibrium
    from tengsim.solvers.types import Equilibrium, State

    z = np.zeros((2, 2))
    block = Equilibrium(State(z, z), z, z, 0.0, True, 1, 2, 0.0, 0.0, "ok")
    eq = FoldedEquilibrium(block, mirror=None)
    for name in ("mirror", "block", "H", "residual"):
        with pytest.raises(dataclasses.FrozenInstanceError):
            setattr(eq, name, 1)
    assert eq.mirror is None and eq.block is block

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


def _count_syncs(monkeypatch, solve):
    """(result, syncs, line-search evaluations, checked law blocks) of ``solve()``: backend.sync is the one
    host transfer; a checked block is SafeLaw.energy_pressure (it looks at its gaps: one sync itself),
    run only when a sweep's unchecked pass met a gap below g_safe."""
    from tengsim import backend
    from tengsim.laws.safe import SafeLaw
    from tengsim.solvers._linesearch import WolfeLineSearch

    n = {"sync": 0, "trial": 0, "checked": 0}

    def counting(key, fn):
        def call(*a, **k):
            n[key] += 1
            return fn(*a, **k)
        return call

    monkeypatch.setattr(backend, "sync", counting("sync", backend.sync))
    monkeypatch.setattr(WolfeLineSearch, "evaluate", counting("trial", WolfeLineSearch.evaluate))
    monkeypatch.setattr(SafeLaw, "energy_pressure", counting("checked", SafeLaw.energy_pressure))
    out = solve()
    monkeypatch.undo()
    return out, n["sync"], n["trial"], n["checked"]


@pytest.mark.parametrize("block", [None, 29], ids=["one-block", "many-blocks"])
def test_a_fast_solve_syncs_once_per_sweep(monkeypatch, block):
    """Host syncs of fast solves (group A, LJ93, free kernel: a cold solve and the path's next, warm one):
    one per sweep over the grid, however many blocks the sweep has: the direction's (with the line
    search's first trial α = 1 swept along when the memory has pairs), one per further trial, the new
    residual's, plus the start and the re-anchoring (every ``resync`` iterations): about 2.4 per
    iteration on the warm solve.  (Before, each block of each sweep returned 3 to 6 host floats: ~15 per iteration on
    one block.)  A sweep whose unchecked law pass met a gap below g_safe is swept again, checked block
    by block (rare: a cold start or a trial far into contact); a warm solve has none."""
    import tengsim.solvers._sweep as S
    from tengsim.laws import LJ93
    from tengsim.shapes import Pyramid
    from tengsim.kernels import FreeKernel
    from tengsim.solvers import FastSolver, Problem, State

    shape = Pyramid(0.946, 3.78)
    grid = shape.grid(0.2)
    U0, K = shape.gap(grid), FreeKernel(grid, 0.5**1.5)
    if block:
        monkeypatch.setattr(S, "BLOCK", block)
    blocks = len(S.Sweeper(grid.nx * grid.ny).groups[0])
    assert blocks > 10 if block else blocks == 1
    solver = FastSolver(1e-8)
    cold, syncs, trials, checked = _count_syncs(
        monkeypatch, lambda: solver.solve(Problem(U0 - 1.0 + 1.0, LJ93(), K), State.zero(grid.shape)))
    warm, w_syncs, w_trials, w_checked = _count_syncs(
        monkeypatch, lambda: solver.solve(Problem(U0 - 1.1 + 1.0, LJ93(), K), cold.state))
    for eq, n, t, c in ((cold, syncs, trials, checked), (warm, w_syncs, w_trials, w_checked)):
        it = eq.iterations
        assert eq.converged and it > 10
        # per iteration: the direction (again after a memory reset: at most once per first step), each
        # trial, the residual; per re-anchoring: its law sweep and q·w; α for a first direction (empty
        # memory); the start: its law sweep, mean q, q·w, max|r|; a checked block: its own two (its
        # smallest gap; below g_safe, SafeLaw.evaluate's test) and at most one more for its sweep
        first = 1
        assert n <= 2 * it + t + 2 * (it // solver.resync) + 2 * first + 4 + 3 * c, (n, it, t, c)
    assert w_checked == 0 and checked <= 4 * blocks   # the cold start: a few sweeps checked again
    # the first trial (α = 1) rides on the direction's sweep and sync: few trials are swept on their own
    assert w_trials <= warm.iterations // 3 and w_syncs <= 2 * warm.iterations + w_trials + 8


HOST = {"float", "int", "bool"}                      # conversions that wait for the device
HOT = {"energy_pressure", "energy_pressure_unchecked", "energy_sum_xp"}


def host_conversions(text: str, names=None) -> list[str]:
    """float()/int()/bool() calls and .item()/.tolist() inside the block functions of a sweep (``*_block``)
    or the laws' hot paths: "function: line" for each."""
    import ast

    hits = []
    for fn in ast.walk(ast.parse(text)):
        if not isinstance(fn, ast.FunctionDef) or not (fn.name.endswith("_block") or fn.name in (names or HOT)):
            continue
        for node in ast.walk(fn):
            if isinstance(node, ast.Call) and (
                    (isinstance(node.func, ast.Name) and node.func.id in HOST)
                    or (isinstance(node.func, ast.Attribute) and node.func.attr in ("item", "tolist"))):
                hits.append(f"{fn.name}: {node.lineno}")
    return hits


def test_sweeps_and_law_hot_paths_keep_their_sums_on_the_device():
    """No block of a sweep (tengsim.solvers) and no law's hot path (tengsim.laws) turns a reduction into a
    host number: the sweep's sums come over at its end, in one backend.sync."""
    src = SOLVERS.parent
    bad = {}
    for path in sorted(list(SOLVERS.glob("*.py")) + list((src / "laws").glob("*.py"))):
        if path.name in EXEMPT:
            continue
        found = host_conversions(path.read_text(encoding="utf-8"))
        if found:
            bad[str(path.relative_to(src))] = found
    assert not bad, f"host conversions inside sweeps: {bad}"
    assert host_conversions("def _x_block(a, acc):\n    acc[0] += float(a.sum())\n")
    assert host_conversions("def energy_pressure(g, out, w):\n    return g.sum().item()\n")
    assert not host_conversions("def other(a):\n    return float(a.sum())\n")
