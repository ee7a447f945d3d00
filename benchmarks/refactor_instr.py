"""Instruction counts of the old and new fast solver (issue 13): a measure the machine's load cannot blur.

    OPENBLAS_NUM_THREADS=1 valgrind --tool=cachegrind --cache-sim=no --cachegrind-out-file=/dev/null \\
        python benchmarks/refactor_instr.py old 0 A    # and: old 3 A, new 3 A, old 3 rough, new 3 rough,
                                                       # old 1 path, new 1 path

Sets up group A (dx 0.1, D = 1.5, tol 1e-8, cold) and the 128² rough surface of the tests (tol 1e-8,
cold), warms both solvers up once on both, then solves one of them (``A`` or ``rough``) ``k`` times with
the chosen solver (``path``: group A's whole path at dx 0.1, tol 1e-6, as in refactor_ab.py, one
solver object for the path).  The difference of valgrind's instruction totals (I refs) between k = 3 and k = 0,
over 3, is the instructions of one solve; the NumPy/FFT work is the same in both solvers, so the
old/new difference is the Python code of the solver itself.
"""
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from _fast_before import FastSolver as Old  # noqa: E402
from refactor_check import _group_a, _rough  # noqa: E402
from tengsim.laws import LJ93  # noqa: E402
from tengsim.solvers import FastSolver as New, Problem, State  # noqa: E402

which, k, case = sys.argv[1], int(sys.argv[2]), sys.argv[3]
grid, U0, K = _group_a(0.1)
probs = [Problem(U0 - 1.5 + 1.0, LJ93(), K), _rough(128)]
for S in (Old, New):  # the same warm-up in every run: imports, plans, first touch
    for p in probs:
        S(1e-8).solve(p, State.zero(p.g0.shape))
S = Old if which == "old" else New
if case == "path":
    from tengsim.path import PathSpec, run_path
    for _ in range(k):
        assert run_path(U0, LJ93(), K, S(1e-6), PathSpec(-1.0, 4.0, 0.1, refine_levels=0)).all_converged
else:
    p = probs[0 if case == "A" else 1]
    for _ in range(k):
        eq = S(1e-8).solve(p, State.zero(p.g0.shape))
        assert eq.converged
