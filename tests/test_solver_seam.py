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


def _count_syncs(solve):
    """(result, counts) of ``solve()``: ``sync`` the host transfers (backend.sync is the one), ``trial``
    the line-search evaluations (trials swept on their own), ``checked`` the checked law blocks
    (SafeLaw.energy_pressure: it looks at its gaps, one sync itself; run only when a sweep's unchecked
    pass met a gap below g_safe), ``direction`` the direction sweeps, ``taken_back`` the L-BFGS pairs
    that failed their curvature test after being stored unconfirmed, ``reset`` the memory's resets."""
    from tengsim import backend
    from tengsim.laws.safe import SafeLaw
    from tengsim.solvers._descent import _Descent
    from tengsim.solvers._lbfgs import KMetricLBFGS
    from tengsim.solvers._linesearch import WolfeLineSearch

    n = dict.fromkeys(("sync", "trial", "checked", "direction", "taken_back", "reset"), 0)

    def counting(key, fn):
        def call(*a, **k):
            n[key] += 1
            return fn(*a, **k)
        return call

    with pytest.MonkeyPatch.context() as mp:  # its own: the caller's patches stay
        mp.setattr(backend, "sync", counting("sync", backend.sync))
        mp.setattr(WolfeLineSearch, "evaluate", counting("trial", WolfeLineSearch.evaluate))
        mp.setattr(SafeLaw, "energy_pressure", counting("checked", SafeLaw.energy_pressure))
        mp.setattr(_Descent, "_direction", counting("direction", _Descent._direction))
        mp.setattr(KMetricLBFGS, "rollback", counting("taken_back", KMetricLBFGS.rollback))
        mp.setattr(KMetricLBFGS, "reset", counting("reset", KMetricLBFGS.reset))
        out = solve()
    return out, n


def _group_a_solves(boundary, mirror):
    """(solver, cold solve, warm solve) on group A (LJ93, dx 0.2): D = 1, then D = 1.1 from it."""
    from tengsim.grid import Mirror
    from tengsim.kernels import make_kernel
    from tengsim.kernels.mirror import MirrorKernel
    from tengsim.laws import LJ93
    from tengsim.shapes import Pyramid
    from tengsim.solvers import FastSolver, Problem, State
    from tengsim.solvers.mirror import MirrorSolver

    shape = Pyramid(0.946, 3.78)
    grid = shape.grid(0.2)
    U0 = shape.gap(grid)
    if mirror:
        K, solver = MirrorKernel(boundary, grid, 0.5**1.5, Mirror(grid, (0, 1))), MirrorSolver(FastSolver(1e-8))
    else:
        K, solver = make_kernel(boundary, grid, 0.5**1.5), FastSolver(1e-8)
    return (solver, lambda: solver.solve(Problem(U0 - 1.0 + 1.0, LJ93(), K), State.zero(grid.shape)),
            lambda start: solver.solve(Problem(U0 - 1.1 + 1.0, LJ93(), K), start))


@pytest.mark.parametrize("boundary,mirror", [("free", False), ("periodic", False), ("free", True)],
                         ids=["free", "periodic", "mirror"])
@pytest.mark.parametrize("block", [None, 29], ids=["one-block", "many-blocks"])
def test_a_fast_solve_syncs_once_per_iteration(monkeypatch, block, boundary, mirror):
    """Host syncs of fast solves (group A, LJ93: a cold solve and the path's next, warm one; free and
    periodic kernels, and a weighted solve on a mirror block): at most one per iteration, however many
    blocks a sweep has: the direction's sweep brings over its sums, the line search's first trial α = 1
    swept along (or max|K d| for a first direction), and the previous residual's numbers (max|r|, the
    new pair's curvature test), since the residual's sweep syncs nothing itself.  Besides: one per
    trial swept on its own, one per re-anchoring (every ``resync`` iterations: its law sweep's sums
    with q·w), two at the start (its law sweep; mean q with q·w), and the final direction's (it finds
    the residual converged).  A direction is swept again only after a pair is taken back or the
    memory reset (rare; a warm solve has neither).  A sweep whose unchecked law pass met a gap below
    g_safe is swept again, checked block by block (rare: a cold start or a trial far into contact; a
    warm solve has none).  (Before: the residual's sweep had a sync of its own, a first direction's α
    one, a re-anchoring two, and a weighted trial two: about 2.4 per iteration warm, 5.6 on the
    mirror block; before that, each block of each sweep returned 3 to 6 host floats.)"""
    import tengsim.solvers._sweep as S

    if block:
        monkeypatch.setattr(S, "BLOCK", block)
    solver, cold_solve, warm_solve = _group_a_solves(boundary, mirror)
    cold, c = _count_syncs(cold_solve)
    warm, w = _count_syncs(lambda: warm_solve(cold.state))
    resync = solver.resync
    for eq, n in ((cold, c), (warm, w)):
        it = eq.iterations
        assert eq.converged and it > 10
        redone = n["direction"] - (it + 1)  # directions swept again: a pair taken back, a memory reset
        assert 0 <= redone <= n["taken_back"] + n["reset"] - 1   # (reset: once when the solve starts)
        assert n["sync"] <= it + n["trial"] + it // resync + 3 + redone + 3 * n["checked"], (it, n)
    assert w["checked"] == 0 and w["taken_back"] == 0 and w["direction"] == warm.iterations + 1
    assert w["sync"] <= warm.iterations + w["trial"] + warm.iterations // resync + 3
    assert w["trial"] <= warm.iterations // 3 and w["sync"] <= 1.35 * warm.iterations   # measured ~1.3
    blocks = len(S.Sweeper(cold.state.q.size).groups[0])
    assert blocks > (2 if mirror else 10) if block else blocks == 1   # a mirror block: a quarter of the grid
    assert c["checked"] <= 4 * blocks   # the cold start: a few sweeps checked again


@pytest.mark.parametrize("k", [0, 2, 3], ids=["empty", "part-full", "full"])
def test_a_pair_taken_back_leaves_the_memory_as_if_never_stored(k):
    """KMetricLBFGS stores a pair unconfirmed; rollback leaves it exactly as an update without the pair:
    the old pairs' products with G moved on by x, everything else (order, small matrices, an evicted
    pair's rows, once the solver has copied them to the spare rows) as it was: the entries the active
    pairs' products read."""
    from tengsim.solvers._lbfgs import KMetricLBFGS

    rng = np.random.default_rng(1)
    m, n = 3, 40
    mem = KMetricLBFGS(m, n, 0.5)
    for _ in range(k):  # k confirmed pairs (their rows filled as the solver fills them)
        slot, _ = mem.next_slot()
        mem.coefficients()
        x = rng.standard_normal(2 * len(mem.order)) if mem.order else None
        mem.update(0.5, x, 1.0 + rng.random(), 1.0 + rng.random(), rng.standard_normal(), rng.standard_normal())
        mem.B[2 * slot:2 * slot + 2] = rng.standard_normal((2, n))
        mem.KB[2 * slot:2 * slot + 2] = rng.standard_normal((2, n))
        mem.confirm()
    mem.coefficients()
    before = [a.copy() for a in (mem.SY, mem.YY, mem.pS, mem.pY, mem.B[:2 * m], mem.KB[:2 * m])]
    order = list(mem.order)
    slot, held = mem.next_slot()
    assert (held is not None) == (k == m)
    if held is not None:  # what the residual's sweep does before writing the new pair's rows
        mem.B[2 * m:] = mem.B[2 * held:2 * held + 2]
        mem.KB[2 * m:] = mem.KB[2 * held:2 * held + 2]
    mem.B[2 * slot:2 * slot + 2] = mem.KB[2 * slot:2 * slot + 2] = 7.0
    x = rng.standard_normal(2 * k) if k else None
    assert mem.update(0.5, x, -1.0, 1.0, 0.3, 0.4) == slot and len(mem.order) == min(k + 1, m)
    mem.rollback()
    SY, YY, pS, pY, B, KB = before
    if k:
        pS[:k] += x[0::2]
        pY[:k] += x[1::2]
    assert mem.order == order and list(mem._perm) == order
    # (entries of slots beyond the k active ones are free: a later pair overwrites them before use)
    for got, want in ((mem.SY[:k, :k], SY[:k, :k]), (mem.YY[:k, :k], YY[:k, :k]), (mem.pS[:k], pS[:k]), (mem.pY[:k], pY[:k]),
                      (mem.B[:2 * k], B[:2 * k]), (mem.KB[:2 * k], KB[:2 * k])):
        assert np.array_equal(got, want)


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
