"""Cache-blocked, optionally threaded sweeps over flat arrays: the fast solver's element-wise work.

On large grids an iteration is memory-bound: every NumPy call streams whole arrays through main
memory.  A sweep runs a function block by block (blocks of ``BLOCK`` elements stay in cache while
several operations use them), and on grids of ``THREAD_MIN_SIZE`` points or more it splits the
blocks into contiguous groups, one per thread (NumPy and BLAS release the GIL inside their loops).
Each group has its own scratch arrays and its own accumulators, reduced at the end by the caller.

``TENGSIM_THREADS`` forces the thread count (1 turns threading off).
"""
from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from tengsim import backend

BLOCK = 1 << 15          # elements per block: 8 float64 arrays × 256 KiB fit a 2 MiB cache
THREAD_MIN_SIZE = 512 * 512
_POOL: ThreadPoolExecutor | None = None
_POOL_PID = None


def blocks(n: int, block: int | None = None):
    """(slice, length) pairs covering range(n) in cache-sized blocks (one block for small n)."""
    block = BLOCK if block is None else block
    if n <= 4 * block:
        return [(slice(0, n), n)]
    return [(slice(i, min(i + block, n)), min(i + block, n) - i) for i in range(0, n, block)]


def thread_count(n: int) -> int:
    env = os.environ.get("TENGSIM_THREADS")
    if env:
        return max(1, int(env))
    return (os.cpu_count() or 1) if n >= THREAD_MIN_SIZE else 1


def _pool(workers: int) -> ThreadPoolExecutor:
    """The shared worker pool; made again in a forked child (its threads do not survive a fork)."""
    global _POOL, _POOL_PID
    if _POOL is None or _POOL_PID != os.getpid() or _POOL._max_workers < workers:
        _POOL = ThreadPoolExecutor(max_workers=workers, thread_name_prefix="tengsim-sweep")
        _POOL_PID = os.getpid()
    return _POOL


class Sweeper:
    """Runs ``fn(sl, m, scratch, acc, *args)`` over the blocks of range(n).

    ``scratch`` is the group's dict of per-name scratch arrays (``Sweeper.buf``), ``acc`` the
    group's accumulator list, ``args`` the extra arguments given to :meth:`run`; :meth:`run` returns
    the list of accumulators, one per group.
    """

    def __init__(self, n: int, threads: int | None = None, block: int | None = None):
        self.n = int(n)
        bl = blocks(self.n, block)
        t = max(1, min(thread_count(self.n) if threads is None else int(threads), len(bl)))
        per = -(-len(bl) // t)
        self.groups = [bl[i:i + per] for i in range(0, len(bl), per)]
        self.block_len = max(m for _, m in bl)
        self._scratch = [dict() for _ in self.groups]
        self._single = bl[0] if len(bl) == 1 else None

    @property
    def threads(self) -> int:
        return len(self.groups)

    def buf(self, scratch: dict, name: str, m: int) -> np.ndarray:
        a = scratch.get(name)
        if a is None:
            a = scratch[name] = backend.empty(self.block_len)
        return a[:m]

    def run(self, fn, init, *args):
        if self._single is not None:  # small grids: no loop, no threads
            acc = list(init)
            fn(self._single[0], self.n, self._scratch[0], acc, *args)
            return [acc]

        err = np.geterr()  # the caller's floating-point error handling, taken to the worker threads

        def group(i):
            acc = list(init)
            sc = self._scratch[i]
            with np.errstate(**err):
                for sl, m in self.groups[i]:
                    fn(sl, m, sc, acc, *args)
            return acc

        if len(self.groups) == 1:
            return [group(0)]
        pool = _pool(len(self.groups) - 1)
        futs = [pool.submit(group, i) for i in range(1, len(self.groups))]
        first = group(0)
        return [first] + [f.result() for f in futs]

    def sum(self, fn, init, *args):
        """:meth:`run`, accumulators summed element-wise."""
        accs = self.run(fn, init, *args)
        if len(accs) == 1:
            return accs[0]
        return [sum(a[j] for a in accs) for j in range(len(init))]
