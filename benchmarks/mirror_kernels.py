"""Symmetry-reduced kernels (issue 22): one convolution on the irreducible block vs the full kernel's.

    OPENBLAS_NUM_THREADS=1 python benchmarks/mirror_kernels.py [--repeat 7] [--quick]

For each grid, times the full kernel's ``apply`` and the mirror kernel's ``reduced.apply`` interleaved in
the same run (best of ``--repeat`` rounds, each round long enough to time; CPU time of the process, which
other jobs on a shared machine disturb far less than the wall clock; the FFTs run on one thread here), and the peak Python-heap
memory (tracemalloc: spectra, coefficient tables, per-thread buffers after one apply) of building the
kernel and applying it once.  Prints a markdown table; ratios are the numbers to read.
"""
from __future__ import annotations

import argparse
import gc
import time
import tracemalloc

import numpy as np

from tengsim import backend
from tengsim.grid import Grid, Mirror
from tengsim.kernels import make_kernel
from tengsim.kernels.mirror import MirrorKernel

CASES = [  # (label, boundary, n, dx, film params)
    ("A free dx0.1", "free", 39, 0.1, {}),
    ("B free dx0.1", "free", 77, 0.1, {}),
    ("C free dx0.1", "free", 189, 0.1, {}),
    ("A free dx0.05", "free", 77, 0.05, {}),
    ("C free dx0.05", "free", backend.fast_odd_len(379), 0.05, {}),
    ("free film (bonded 0.3)", "free", 77, 0.1, {"thickness": 1.0, "poisson": 0.3}),
    ("periodic", "periodic", backend.fast_odd_len(255), 0.1, {}),
    ("periodic", "periodic", backend.fast_odd_len(1023), 0.1, {}),
    ("periodic film (bonded 0.49)", "periodic", backend.fast_odd_len(255), 0.1, {"thickness": 5.0, "poisson": 0.49}),
]


def mem(build, apply_shape):
    gc.collect()
    tracemalloc.start()
    k = build()
    apply = k.reduced.apply if hasattr(k, "reduced") else k.apply
    apply(np.ones(apply_shape))
    cur, pk = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    return k, pk, cur


def best(f, x, rounds):
    n = 1
    while True:
        t = time.process_time()
        for _ in range(n):
            f(x)
        dt = time.process_time() - t
        if dt > 0.05:
            break
        n *= 2
    return dt / n


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--quick", action="store_true", help="skip the 1023² periodic case")
    a = ap.parse_args()
    print("| case | grid | axes | full conv | reduced conv | speed-up | full kernel: peak / kept | reduced: peak / kept "
          "| ratio peak / kept |")
    print("|---|---|---|---|---|---|---|---|---|")
    for label, b, n, dx, fp in CASES:
        if a.quick and n > 1000:
            continue
        g = Grid(n, n, dx, dx)
        for axes in ((0, 1), (1,)):
            m = Mirror(g, axes)
            if fp:  # the film's correction table is cached on first use: build it outside the measurement
                make_kernel(b, Grid(5, 5, dx, dx), 0.35, **fp)
            full, pf, kf = mem(lambda: make_kernel(b, g, 0.35, **fp), g.shape)
            red, pr, kr = mem(lambda: MirrorKernel(b, g, 0.35, m, **fp), m.reduced_shape)
            x = np.random.default_rng(0).standard_normal(g.shape)
            xb = m.reduce(x)
            tf, tr = [], []
            for _ in range(a.repeat):  # interleaved: the same machine load for both
                tf.append(best(full.apply, x, 1))
                tr.append(best(red.reduced.apply, xb, 1))
            tf, tr = min(tf), min(tr)
            print(f"| {label} | {n}² | {axes} | {tf * 1e3:.3f} ms | {tr * 1e3:.3f} ms | {tf / tr:.2f}× | "
                  f"{pf / 2**20:.1f} / {kf / 2**20:.1f} MiB | {pr / 2**20:.1f} / {kr / 2**20:.1f} MiB | "
                  f"{pr / pf:.2f} / {kr / kf:.2f} |", flush=True)
            del full, red


if __name__ == "__main__":
    main()
