"""One solver over an array backend (CuPy through ``tengsim.backend``), or the compiled JAX loop?

The question is what the NumPy fast solver would cost if its arrays lived on the GPU: the same algorithm,
every NumPy call a CuPy call (one kernel launch each), every host transfer of the seam (``backend.sync`` /
``to_host``) a device-to-host copy that waits for the queue.  Three measurements, one script:

1. **record** (host, NumPy): the NumPy fast solver solves benchmarks/scaling.py's periodic rough surface
   (LJ 9-3, μ = 0.5, dx = 0.25 ε, tol 1e-6, cold) at ``--record-n``² with its workspace arrays made
   recording (an ndarray subclass: every ufunc call, operator, reduction and NumPy function on them is
   noted with its argument shapes); each convolution and each host transfer is noted as one event.
2. **replay** (GPU, CuPy): the recorded events in order, with every grid-sized length scaled to n², each
   ufunc / function called by CuPy on device arrays of those shapes, each convolution as cupy.fft
   ``irfft2(rfft2(p)·K̂)``, each transfer as a ``.get()`` of its size.  Time per solver iteration = the
   replay's time / the recorded iterations.  A lower bound of a port's cost: indexing, Python scalars
   that would become device scalars, and anything not on a workspace array are not replayed.  Also the
   floor: the convolutions and transfers alone (the time no fusing of the element-wise work can remove).
   ``--xp numpy`` replays on the host instead; its time per iteration against the NumPy solver's own
   (same n, one thread) says how much of the solver's work the record holds.
3. **JAX**: the same surface at n² solved cold by ``JaxSolver`` (float64); time per iteration, compile
   excluded.

Each row is one JSON line in OUT/cupy_vs_jax.jsonl, written when it finishes; rows projected past
``--deadline`` (seconds from the start) are skipped and say so.

    python benchmarks/cupy_vs_jax.py --out benchmarks/results/cupy_vs_jax --deadline 420   # on a GPU
    python benchmarks/cupy_vs_jax.py --xp numpy --sizes 128 256 --quick                  # CPU check
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from collections import Counter
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
DX, MU, TOL = 0.25, 0.5, 1e-6


# ---- 1. the record ----------------------------------------------------------------------------------
class Recorder:
    def __init__(self):
        self.events = []
        self.quiet = 0

    def note(self, kind, name, args, out=None):
        if self.quiet:
            return
        self.events.append((kind, name, [_spec(a) for a in args], [_spec(o) for o in (out or ())]))


REC = Recorder()


def _spec(a):
    if isinstance(a, np.ndarray):
        return ("a", tuple(a.shape), a.dtype.str)
    if isinstance(a, (list, tuple)) and a and all(isinstance(x, np.ndarray) for x in a):
        return ("l", [tuple(x.shape) for x in a], a[0].dtype.str)
    if isinstance(a, (bool, int, float, np.generic)):
        return ("s", float(a) if not isinstance(a, bool) else a)
    return ("o", None)


def _plain(x):
    if isinstance(x, Rec):
        return x.view(np.ndarray)
    if isinstance(x, (list, tuple)):
        return type(x)(_plain(v) for v in x)
    return x


def _wrap(res):
    if isinstance(res, np.ndarray) and type(res) is np.ndarray and res.ndim > 0:
        return res.view(Rec)
    return res


class Rec(np.ndarray):
    """An ndarray whose ufunc calls and NumPy functions are noted in :data:`REC`."""

    def __array_ufunc__(self, ufunc, method, *inputs, out=None, **kw):
        REC.note("ufunc", f"{ufunc.__name__}.{method}", inputs, out)
        if out is not None:
            kw["out"] = tuple(_plain(o) for o in out)
        res = getattr(ufunc, method)(*(_plain(x) for x in inputs), **kw)
        if out is not None:
            return out[0] if len(out) == 1 else out
        return _wrap(res)

    def __array_function__(self, func, types, args, kwargs):
        REC.note("func", func.__name__, args, (kwargs.get("out"),) if kwargs.get("out") is not None else None)
        res = func(*_plain(args), **{k: _plain(v) for k, v in kwargs.items()})
        if kwargs.get("out") is not None:
            return kwargs["out"]
        return _wrap(res)


def rough_problem(n):
    from scaling import rough_surface

    from tengsim.grid import Grid
    from tengsim.kernels import make_kernel
    from tengsim.laws import LJ93
    from tengsim.solvers import Problem

    h, _ = rough_surface(n, DX, seed=0)
    U0 = h.max() - h
    D0 = float(np.quantile(U0, 0.05))
    grid = Grid(n, n, DX, DX)
    return Problem(U0 - D0 + 1.0, LJ93(), make_kernel("periodic", grid, MU ** 1.5)), grid


def record(n, max_iter):
    """The NumPy fast solver's events on the rough surface at n² (module docstring, 1)."""
    import os

    threads = os.environ.get("TENGSIM_THREADS")
    os.environ["TENGSIM_THREADS"] = "1"  # one sweep group: a CuPy port would not split the grid
    try:
        return _record(n, max_iter)
    finally:
        if threads is None:
            del os.environ["TENGSIM_THREADS"]
        else:
            os.environ["TENGSIM_THREADS"] = threads


def _record(n, max_iter):
    from tengsim import backend
    from tengsim.solvers import FastSolver, State
    from tengsim.solvers import _descent

    pb, _ = rough_problem(n)
    real_sync, real_convolve, real_init = backend.sync, _descent._Descent.convolve, _descent._Descent.__init__

    def empty(shape, dtype=float):
        return np.empty(shape, dtype).view(Rec)

    def zeros(shape, dtype=float):
        return np.zeros(shape, dtype).view(Rec)

    def sync(scalars, tail=None):
        size = len(scalars) + (0 if tail is None else int(np.size(tail)))
        REC.events.append(("sync", "sync", [("s", size)], []))
        REC.quiet += 1
        try:
            return real_sync(scalars, tail)
        finally:
            REC.quiet -= 1

    def to_host(x):
        return float(sync((x,))[0])

    def convolve(self, x):
        REC.events.append(("conv", "conv", [("a", tuple(self.shape), "<f8")], []))
        REC.quiet += 1
        try:  # the kernel's own transforms take plain arrays
            self._apply(np.asarray(x).view(np.ndarray).reshape(self.shape),
                        out=self.cP.view(np.ndarray).reshape(self.shape))
            return self.cP
        finally:
            REC.quiet -= 1

    def init(self, problem, start, ws, lines=None):
        real_init(self, problem, start, ws, lines)
        for name in ("g0", "q", "w"):
            setattr(self, name, getattr(self, name).view(Rec))

    swap = {"empty": empty, "zeros": zeros, "sync": sync, "to_host": to_host}
    mods = [m for k, m in sys.modules.items() if k.startswith("tengsim.solvers")] + [backend]
    patched = [(m, name, getattr(m, name)) for m in mods for name in swap
               if getattr(m, name, None) is getattr(backend, name)]
    try:
        for m, name, _ in patched:
            setattr(m, name, swap[name])
        _descent._Descent.convolve, _descent._Descent.__init__ = convolve, init
        REC.events.clear()
        t0 = time.perf_counter()
        eq = FastSolver(tol=TOL, max_iter=max_iter).solve(pb, State.zero((n, n)))
        t_rec = time.perf_counter() - t0
    finally:
        for m, name, f in patched:
            setattr(m, name, f)
        _descent._Descent.convolve, _descent._Descent.__init__ = real_convolve, real_init
    t0 = time.perf_counter()
    ref = FastSolver(tol=TOL, max_iter=max_iter).solve(pb, State.zero((n, n)))
    t_numpy = time.perf_counter() - t0
    return dict(events=list(REC.events), iterations=eq.iterations, n_conv=eq.n_conv, converged=eq.converged,
                record_s=t_rec, numpy_s=t_numpy, numpy_iterations=ref.iterations, n=n,
                F=float(np.sum(eq.P)), numpy_F=float(np.sum(ref.P)))


def census(rec):
    """Per iteration: launches (ufunc and function events), grid passes (elements touched / n²),
    convolutions, host transfers; and the names most called."""
    n2 = rec["n"] ** 2
    it = max(rec["iterations"], 1)
    kinds = Counter(e[0] for e in rec["events"])
    touched = 0
    for kind, _, args, outs in rec["events"]:
        if kind in ("ufunc", "func"):
            for s in args + outs:
                if s[0] == "a":
                    touched += int(np.prod(s[1]))
    names = Counter(e[1] for e in rec["events"] if e[0] in ("ufunc", "func"))
    return dict(launches_per_iter=(kinds["ufunc"] + kinds["func"]) / it, passes_per_iter=touched / n2 / it,
                conv_per_iter=kinds["conv"] / it, syncs_per_iter=kinds["sync"] / it,
                top=dict(names.most_common(8)))


# ---- 2. the replay ----------------------------------------------------------------------------------
def _scale(shape, n_rec, n):
    out = []
    for d in shape:
        out.append(d // (n_rec * n_rec) * n * n if d and d % (n_rec * n_rec) == 0 else
                   (n if d == n_rec else d))
    return tuple(out)


REDUCE = {"maximum.reduce": "max", "minimum.reduce": "min", "add.reduce": "sum"}


def compile_replay(rec, n, xp):
    """The events as a list of zero-argument calls on ``xp`` arrays at n² (plus the names that failed)."""
    pool, calls, failed = {}, [], Counter()
    n_rec = rec["n"]

    def arr(shape, dtype, slot):
        key = (shape, dtype, slot)
        if key not in pool:
            pool[key] = xp.full(shape, 1.5, dtype=np.dtype(dtype))
        return pool[key]

    def arg(s, slot):
        if s[0] == "a":
            return arr(_scale(s[1], n_rec, n), s[2], slot)
        if s[0] == "l":
            return [arr(_scale(sh, n_rec, n), s[2], (slot, j)) for j, sh in enumerate(s[1])]
        if s[0] == "s":
            return s[1]
        raise TypeError("unreplayable argument")

    shape = (n, n)
    spec = xp.full((n, n // 2 + 1), 0.5 + 0.0j)
    conv_out = xp.empty(shape)
    host = (lambda a: a.get()) if xp.__name__ == "cupy" else (lambda a: np.asarray(a))
    small = {}
    for kind, name, args, outs in rec["events"]:
        if kind == "conv":
            src = arr(shape, "<f8", "conv")
            calls.append(lambda s=src: xp.copyto(conv_out, xp.fft.irfft2(xp.fft.rfft2(s) * spec, s=shape)))
            continue
        if kind == "sync":
            size = int(args[0][1])
            a = small.setdefault(size, xp.ones(size))
            calls.append(lambda a=a: host(a))
            continue
        try:
            fn_name = REDUCE.get(name, name.split(".")[0])
            fn = getattr(xp, fn_name)
            a = [arg(s, i) for i, s in enumerate(args)]
            kw = {}
            if name.endswith(".reduce"):
                a = a[:1]
            elif outs and outs[0][0] == "a":
                kw["out"] = arg(outs[0], "out")
            try:  # once now: an argument CuPy refuses is found here, not in the timed loop
                fn(*a, **kw)
            except Exception:  # noqa: BLE001 - e.g. an ``out=`` not taken: the call without it
                if not kw:
                    raise
                kw = {}
                fn(*a)
                failed[name + " (without out=)"] += 1
            calls.append(lambda fn=fn, a=a, kw=kw: fn(*a, **kw))
        except Exception:  # noqa: BLE001 - counted and reported: the replay's gaps
            failed[name] += 1
    return calls, failed


def replay(rec, n, xp, repeat=2):
    calls, failed = compile_replay(rec, n, xp)
    sync = (lambda: xp.cuda.Device().synchronize()) if xp.__name__ == "cupy" else (lambda: None)
    best = None
    for _ in range(repeat):
        sync()
        t0 = time.perf_counter()
        for c in calls:
            c()
        sync()
        t = time.perf_counter() - t0
        best = t if best is None else min(best, t)
    return best, len(calls), failed


def replay_floor(rec, n, xp, repeat=2):
    """Only the convolutions and transfers of the record (the floor of any port)."""
    sub = dict(rec, events=[e for e in rec["events"] if e[0] in ("conv", "sync")])
    t, k, _ = replay(sub, n, xp, repeat=repeat)
    return t, k


# ---- 3. JAX -----------------------------------------------------------------------------------------
def jax_row(n, device, max_iter):
    from tengsim.solvers import State
    from tengsim.solvers.jax_fast import JaxSolver, compile_stats

    pb, grid = rough_problem(n)
    JaxSolver(tol=TOL, max_iter=3, device=device).solve(pb, State.zero((n, n)))  # compiled (max_iter is traced)
    c0 = compile_stats()["compile_seconds"]
    t0 = time.perf_counter()
    eq = JaxSolver(tol=TOL, max_iter=max_iter, device=device).solve(pb, State.zero((n, n)))
    wall = time.perf_counter() - t0
    comp = compile_stats()["compile_seconds"] - c0
    return dict(jax_iterations=eq.iterations, jax_converged=bool(eq.converged), jax_s=wall - comp,
                jax_compile_s=comp, jax_ms_per_iter=1e3 * (wall - comp) / max(eq.iterations, 1),
                F=float(eq.P.sum()) * grid.area)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default="benchmarks/results/cupy_vs_jax")
    ap.add_argument("--sizes", type=int, nargs="+", default=[256, 512, 1024, 2048, 4096])
    ap.add_argument("--record-n", type=int, default=256)
    ap.add_argument("--xp", choices=("cupy", "numpy"), default="cupy")
    ap.add_argument("--device", default="gpu", help="JAX device: gpu, cpu or auto")
    ap.add_argument("--deadline", type=float, default=420.0)
    ap.add_argument("--max-iter", type=int, default=20000)
    ap.add_argument("--quick", action="store_true", help="record at 64², no JAX above 256²")
    a = ap.parse_args(argv)
    t_start = time.perf_counter()
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    log = (out / "cupy_vs_jax.jsonl").open("w")

    def emit(row):
        row["elapsed_s"] = round(time.perf_counter() - t_start, 2)
        print(json.dumps(row), flush=True)
        log.write(json.dumps(row) + "\n")
        log.flush()

    if a.xp == "cupy":
        import cupy as xp
    else:
        xp = np
    import platform

    head = dict(row="machine", python=platform.python_version(), numpy=np.__version__, xp=a.xp)
    if a.xp == "cupy":
        head.update(cupy=xp.__version__, gpu=xp.cuda.runtime.getDeviceProperties(0)["name"].decode())
    try:
        import jax

        head.update(jax=jax.__version__, jax_devices=[str(d) for d in jax.devices()])
    except Exception as exc:  # noqa: BLE001 - said in the row
        head["jax"] = f"not importable: {exc}"
    emit(head)
    n_rec = 64 if a.quick else a.record_n
    rec = record(n_rec, a.max_iter)
    emit(dict(row="record", n=n_rec, iterations=rec["iterations"], n_conv=rec["n_conv"],
              converged=rec["converged"], numpy_s=rec["numpy_s"],
              numpy_ms_per_iter=1e3 * rec["numpy_s"] / max(rec["numpy_iterations"], 1),
              events=len(rec["events"]), **census(rec)))
    # the record's completeness: its replay on the host against the NumPy solver's own time, same n
    t_host, k_host, failed_host = replay(rec, n_rec, np)
    emit(dict(row="replay on NumPy at the record's size", n=n_rec, calls=k_host,
              ms_per_iter=1e3 * t_host / max(rec["iterations"], 1),
              numpy_solver_ms_per_iter=1e3 * rec["numpy_s"] / max(rec["numpy_iterations"], 1),
              failed=dict(failed_host)))
    last = None
    for n in a.sizes:
        left = a.deadline - (time.perf_counter() - t_start)
        if last is not None and last * (n / last_n) ** 2 * 1.3 > left:
            emit(dict(row="skipped", n=n, why=f"projected {last * (n / last_n) ** 2:.0f} s, {left:.0f} s left"))
            continue
        t0 = time.perf_counter()
        row = dict(row="compare", n=n, xp=a.xp)
        t, k, failed = replay(rec, n, xp)
        tf, kf = replay_floor(rec, n, xp)
        row.update(replay_ms_per_iter=1e3 * t / max(rec["iterations"], 1), replay_calls=k, failed=dict(failed),
                   floor_ms_per_iter=1e3 * tf / max(rec["iterations"], 1))
        if a.xp == "cupy":  # the replay's arrays given back before JAX takes its share of the card
            xp.get_default_memory_pool().free_all_blocks()
        if not (a.quick and n > 256):
            row.update(jax_row(n, a.device, a.max_iter))
            row["replay_over_jax"] = row["replay_ms_per_iter"] / row["jax_ms_per_iter"]
            row["floor_over_jax"] = row["floor_ms_per_iter"] / row["jax_ms_per_iter"]
        emit(row)
        last, last_n = time.perf_counter() - t0, n
    log.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
