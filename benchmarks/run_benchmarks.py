"""Side-by-side benchmark: tengsim fast vs tengsim VSR vs ContactMechanics/Adhesion (issue 6).

    OPENBLAS_NUM_THREADS=1 python benchmarks/run_benchmarks.py --groups A C --dx 0.1 \\
        --vsr-mode full full --out benchmarks/results          (full paths, ~27 min on 2 cores)

(tengsim's FFTs run on 1 thread at these sizes, below 512² points, like the peer's.)

Every solver solves the paper's Eq. (9) (pyramid groups at μ = 0.5, free kernel) on the same grid
(tengsim's ``Pyramid(N, cell).grid(dx)``) and the same D steps (d_min → d_max → d_min in d_step),
warm-started step to step, to the same tolerance on the Eq. (9) residual max|r|.  Writes
``results.md`` / ``results.csv`` (the table) and ``curves_<group>.csv`` (F and Λc per step and
solver) under ``--out``.

* tengsim fast: ``simulate(ContactPlan(Pyramid(N, cell), ..., solver="fast"))`` on the full path (``refine_levels`` 0 by
  default so it solves exactly the peer's D steps; its secant predictor stays on).
* tengsim VSR: by default *sampled*: every ``--vsr-every``-th step of the full path is solved by VSR
  from the very state the fast solver started that step from, and the fast solve of that step is
  timed alongside; the ratio is then per equilibrium (sum of VSR seconds / sum of fast seconds on the
  same solves).  ``--vsr-mode full`` runs the same with ``solver="vsr"`` on the whole path;
  one mode per group is accepted (``--groups A C --vsr-mode full sampled``).
* ContactMechanics/Adhesion (``benchmarks/peer_contactmechanics.py``): skipped with a note when the
  packages are not installed (``pip install -e .[bench]``).

Convolutions are counted by wrapping the kernel's ``apply`` (tengsim) and the FFT engine's
``ifft`` (peer); "wall / (conv × t_conv)" divides the wall time by the number of convolutions times
the median time of one convolution on that grid: near 1 means the FFTs are the cost.
"""
from __future__ import annotations

import argparse
import csv
import json
import os
import platform
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import peer_contactmechanics as peer  # noqa: E402

GROUPS = {
    # N = n/(2ε), cell = L̄, and a d_max past the paper's full-contact transition
    "A": dict(N=0.946, cell=3.78, d_max=4.0),
    "B": dict(N=2.37, cell=9.46, d_max=8.0),
    "C": dict(N=4.73, cell=18.9, d_max=14.0),
}


def _symmetric_fast(args, name, g, d_max, grid, reps, wall_fast, cpu_fast, fast_ref, log):
    """tengsim fast with symmetry = 'auto' (the X+Y block): its row, ratios to the full-grid fast run, and its
    largest |ΔF| from it relative to max|F|."""
    from tengsim.continuation import PathSpec
    from tengsim.run.plan import ContactPlan
    from tengsim.run.simulate import simulate
    from tengsim.shapes import Pyramid
    from tengsim.grid import Mirror
    from tengsim.kernels import FreeKernel
    from tengsim.kernels.mirror import MirrorKernel, ReducedKernel

    mk = MirrorKernel("free", grid, args.mu ** 1.5, Mirror(grid, (0, 1)))
    pb = np.random.default_rng(0).standard_normal(mk.mirror.reduced_shape)
    t_conv = time_call(lambda: mk.reduced.apply(pb))
    wall = cpu = np.inf
    for _ in range(reps):
        cnt = ConvCounter(FreeKernel, ReducedKernel)
        try:
            t0, c0 = time.perf_counter(), time.process_time()
            res = simulate(ContactPlan(Pyramid(g["N"], g["cell"]), args.mu, args.dx, PathSpec(args.d_min, d_max, args.d_step, refine_levels=args.refine_levels), boundary="free", solver="fast", solver_tol=args.tol, symmetry="auto"))
            wall, cpu = min(wall, time.perf_counter() - t0), min(cpu, time.process_time() - c0)
        finally:
            cnt.restore()
    T = res.table
    nconv = np.asarray(T["n_conv"])
    keys = [_key(b, D) for b, D in zip(np.asarray(T["branch"]).astype(str), T["D"])]
    common = [(F, fast_ref[k][0]) for k, F in zip(keys, T["F"]) if k in fast_ref]
    scale = max(abs(f) for _, f in common) if common else np.nan
    dF = max(abs(a - b) for a, b in common) / scale if common else np.nan
    row = dict(group=name, solver="tengsim fast, symmetry", path=f"full, block {res.params.get('block_nx')}²",
               n_eq=len(nconv), wall_s=wall, ratio_vs_fast=wall / wall_fast, cpu_s=cpu,
               cpu_ratio_vs_fast=cpu / cpu_fast, conv_median=float(np.median(nconv[1:])), conv_max=int(nconv.max()),
               conv_total=cnt.n, t_conv_ms=t_conv * 1e3, fft_share_ratio=wall / (cnt.n * t_conv),
               max_residual=float(np.max(T["residual"])), all_converged=bool(np.all(T["converged"])),
               note=f"symmetry {res.params.get('symmetry')}; max|ΔF|/max|F| vs full grid {dF:.1e}")
    log(f"   fast, symmetry: {wall:.2f} s ({wall_fast / wall:.2f}x faster than the full grid), {cnt.n} conv, "
        f"t_conv {t_conv * 1e3:.3f} ms, max|dF|/max|F| {dF:.1e}")
    return row


# ----------------------------------------------------------------------------------------------
class ConvCounter:
    """Counts calls of the ``apply`` of one or more kernel classes (one convolution each): the full grid's
    kernel and, for a symmetry-reduced run, the block's (tengsim.kernels.mirror.ReducedKernel)."""

    def __init__(self, *classes):
        self.n = 0
        self._orig = [(cls, cls.apply) for cls in classes]
        counter = self
        for cls, orig in self._orig:
            def apply(self_, p, *a, _orig=orig, **k):
                counter.n += 1
                return _orig(self_, p, *a, **k)

            cls.apply = apply

    def restore(self):
        for cls, orig in self._orig:
            cls.apply = orig


def vsr_conv_total(counted: int, n_conv) -> int:
    """The convolutions of a run: the kernel calls ``counted`` by :class:`ConvCounter`, or, where none reached the
    counted classes (a kernel of another class, e.g. the mirror block's), the solver's own count summed over
    its equilibria (the table's ``n_conv``: one convolution each, every solver counts its own)."""
    return int(counted) if counted else int(np.sum(np.asarray(n_conv)))


def time_call(fn, repeat=30, min_time=0.2):
    """Median seconds of ``fn()``."""
    fn()
    ts = []
    t_end = time.perf_counter() + min_time
    while len(ts) < repeat or (time.perf_counter() < t_end and len(ts) < 2000):
        t0 = time.perf_counter()
        fn()
        ts.append(time.perf_counter() - t0)
    return float(np.median(ts))


def environment():
    cpu = platform.processor() or ""
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    import scipy

    import tengsim

    env = {
        "cpu": cpu, "cores": os.cpu_count(), "python": platform.python_version(),
        "numpy": np.__version__, "scipy": scipy.__version__, "tengsim": tengsim.__version__,
        "OPENBLAS_NUM_THREADS": os.environ.get("OPENBLAS_NUM_THREADS"),
        "TENGSIM_FFT_WORKERS": os.environ.get("TENGSIM_FFT_WORKERS"),
    }
    if peer.available():
        env.update({k: v for k, v in peer.versions().items() if v})
    return env


def _key(branch, D):
    return (str(branch), round(float(D), 9))


def compare(ref_rows, rows):
    """Largest |ΔF| (absolute and relative to max|F| of the branch) and |ΔΛc| per branch."""
    out = {}
    for br in ("approach", "retraction"):
        dF, dL, Fmax = [], [], 0.0
        for k, (F0, L0) in ref_rows.items():
            if k[0] != br or k not in rows:
                continue
            F1, L1 = rows[k]
            dF.append(abs(F1 - F0))
            Fmax = max(Fmax, abs(F0))
            if np.isfinite(L0) and np.isfinite(L1):
                dL.append(abs(L1 - L0))
        out[br] = dict(n=len(dF), dF=max(dF) if dF else np.nan,
                       dF_rel=(max(dF) / Fmax) if dF and Fmax > 0 else np.nan,
                       dLc=max(dL) if dL else np.nan)
    return out


# ----------------------------------------------------------------------------------------------
def run_group(name, args, log):
    from tengsim import kernels
    from tengsim.analysis import apex_index
    from tengsim.analysis import contact_length as ts_contact_length
    from tengsim.continuation import PathSpec
    from tengsim.run.plan import ContactPlan
    from tengsim.run.simulate import simulate
    from tengsim.shapes import Pyramid
    from tengsim.laws import LJ93
    from tengsim.solvers import Problem, State, make_solver

    g = GROUPS[name]
    d_max = args.d_max if args.d_max is not None else g["d_max"]
    shape = Pyramid(g["N"], g["cell"])
    grid = shape.grid(args.dx)
    U0 = shape.gap(grid)
    apex = apex_index(U0)
    kernel = kernels.make_kernel("free", grid, args.mu ** 1.5)
    D_path, br_path = peer.path_D(args.d_min, d_max, args.d_step)
    n_eq = D_path.size  # distinct equilibria solved on the path (turning point once)
    log(f"== group {name}: N={g['N']} cell={g['cell']} grid {grid.nx}x{grid.ny} dx={grid.dx:.5f}; "
        f"D {args.d_min} -> {d_max} -> {args.d_min} step {args.d_step}: {n_eq} equilibria")

    rows_out, curves = [], {}
    # one convolution on this grid
    P_typ = np.random.default_rng(0).standard_normal(grid.shape)
    t_conv = time_call(lambda: kernel.apply(P_typ))
    log(f"   one tengsim convolution ({kernel.padded_shape[0]}x{kernel.padded_shape[1]} padded): {t_conv*1e3:.3f} ms")

    # ---- tengsim fast, full path ---------------------------------------------------------------
    reps = args.repeat[min(args.groups.index(name), len(args.repeat) - 1)]
    rep_note = f"; fastest of {reps} runs" if reps > 1 else ""
    wall_fast = cpu_fast = np.inf
    for _ in range(reps):  # every solver's path is run ``reps`` times; the fastest run counts
        cnt = ConvCounter(type(kernel))
        try:
            t0 = time.perf_counter()
            c0 = time.process_time()
            res = simulate(ContactPlan(Pyramid(g["N"], g["cell"]), args.mu, args.dx, PathSpec(args.d_min, d_max, args.d_step, refine_levels=args.refine_levels), boundary="free", solver="fast", solver_tol=args.tol, symmetry="off"))
            wall_fast = min(wall_fast, time.perf_counter() - t0)
            cpu_fast = min(cpu_fast, time.process_time() - c0)
        finally:
            cnt.restore()
    T = res.table
    on = np.asarray(T["on_grid"], bool) if "on_grid" in T else np.ones(len(T["D"]), bool)
    # the retraction's first row repeats the approach's last state (no solve): drop it
    solved = np.ones(len(T["D"]), bool)
    br = np.asarray(T["branch"]).astype(str)
    for i in range(1, len(br)):
        if br[i] != br[i - 1] and br[i] == "retraction":
            solved[i] = False
    nconv_rows = np.asarray(T["n_conv"])[solved]
    fast_ref = {_key(b, D): (F, L) for b, D, F, L, o in zip(br, T["D"], T["F"], T["contact_length"], on) if o}
    curves["fast"] = fast_ref
    curves["fast_solve"] = {_key(b, D): (s_, r_) for b, D, s_, r_ in zip(br, T["D"], T["seconds"], T["residual"])}
    conv_total = cnt.n
    row = dict(group=name, solver="tengsim fast", path=f"full ({n_eq} eq)", n_eq=int(solved.sum()),
               wall_s=wall_fast, ratio_vs_fast=1.0, cpu_s=cpu_fast, cpu_ratio_vs_fast=1.0,
               conv_median=float(np.median(nconv_rows[1:])), conv_max=int(nconv_rows.max()),
               conv_total=conv_total, t_conv_ms=t_conv * 1e3,
               fft_share_ratio=wall_fast / (conv_total * t_conv),
               max_residual=float(np.max(T["residual"])), all_converged=bool(np.all(T["converged"])),
               note=f"refine_levels={args.refine_levels}; predictor on{rep_note}")
    rows_out.append(row)
    log(f"   fast: {wall_fast:.2f} s, {conv_total} conv, median {row['conv_median']:.0f}/eq (warm), "
        f"max {row['conv_max']}, wall/(conv*t_conv) = {row['fft_share_ratio']:.2f}")
    if args.symmetry:
        rows_out.append(_symmetric_fast(args, name, g, d_max, grid, reps, wall_fast, cpu_fast, fast_ref, log))

    # ---- tengsim VSR -------------------------------------------------------------------------
    vsr_mode = args.vsr_mode[min(args.groups.index(name), len(args.vsr_mode) - 1)]
    if vsr_mode != "none":
        law = LJ93()
        vsr = make_solver("vsr", tol=args.tol, max_iter=args.vsr_max_iter)
        fast = make_solver("fast", tol=args.tol)
        if vsr_mode == "sampled":
            every = args.vsr_every
            state = State.zero(grid.shape)
            t_v = t_f = 0.0
            nconv_v, nconv_f, conv_ok = [], [], []
            vsr_rows = {}
            for i, (D, b) in enumerate(zip(D_path, br_path)):
                prob = Problem(U0 - D + 1.0, law, kernel)
                eqf = fast.solve(prob, state)
                if i % every == 0 and i > 0:
                    t0 = time.perf_counter()
                    eqv = vsr.solve(prob, state)
                    t_v += time.perf_counter() - t0
                    t_f += eqf.seconds
                    nconv_v.append(eqv.n_conv)
                    nconv_f.append(eqf.n_conv)
                    conv_ok.append(eqv.converged)
                    from tengsim.analysis import force
                    vsr_rows[_key(b, D)] = (force(eqv.P, grid), ts_contact_length(eqv.P, grid, apex))
                    if args.verbose:
                        log(f"     vsr {b:10s} D={D:+.2f} conv {eqv.n_conv} ({eqv.seconds:.3f} s) vs fast "
                            f"{eqf.n_conv} ({eqf.seconds:.4f} s) converged={eqv.converged}")
                state = eqf.state
            ratio = t_v / t_f if t_f > 0 else np.nan
            cmpv = compare(fast_ref, vsr_rows)
            row = dict(group=name, solver="tengsim VSR",
                       path=f"sampled: every {every}th step ({len(nconv_v)} eq), same warm starts as fast",
                       n_eq=len(nconv_v), wall_s=t_v, ratio_vs_fast=ratio,
                       conv_median=float(np.median(nconv_v)) if nconv_v else np.nan,
                       conv_max=int(max(nconv_v)) if nconv_v else 0, conv_total=int(sum(nconv_v)),
                       t_conv_ms=t_conv * 1e3,
                       fft_share_ratio=t_v / (sum(nconv_v) * t_conv) if nconv_v else np.nan,
                       all_converged=bool(all(conv_ok)),
                       note=(f"ratio per equilibrium (VSR {t_v:.2f} s vs fast {t_f:.3f} s on the same solves); "
                             f"{sum(not c for c in conv_ok)} of {len(conv_ok)} hit max_iter={args.vsr_max_iter}"),
                       **_cmp_cols(cmpv))
            curves["vsr"] = vsr_rows
        else:
            t_v = cpu_v = np.inf
            for _ in range(reps):
                cntv = ConvCounter(type(kernel))
                try:
                    t0 = time.perf_counter()
                    c0 = time.process_time()
                    resv = simulate(ContactPlan(Pyramid(g["N"], g["cell"]), args.mu, args.dx, PathSpec(args.d_min, d_max, args.d_step, refine_levels=args.refine_levels), boundary="free", solver=vsr, solver_tol=args.tol, symmetry="off"))   # the fast run's grid (not the mirror block's kernel)
                    t_v = min(t_v, time.perf_counter() - t0)
                    cpu_v = min(cpu_v, time.process_time() - c0)
                finally:
                    cntv.restore()
            Tv = resv.table
            brv = np.asarray(Tv["branch"]).astype(str)
            vsr_rows = {_key(b, D): (F, L) for b, D, F, L, o in
                        zip(brv, Tv["D"], Tv["F"], Tv["contact_length"], Tv["on_grid"]) if o}
            cmpv = compare(fast_ref, vsr_rows)
            nc = np.asarray(Tv["n_conv"])
            n_total = vsr_conv_total(cntv.n, nc)
            row = dict(group=name, solver="tengsim VSR", path=f"full ({n_eq} eq)", n_eq=len(nc),
                       wall_s=t_v, ratio_vs_fast=t_v / wall_fast, cpu_s=cpu_v,
                       cpu_ratio_vs_fast=cpu_v / cpu_fast, conv_median=float(np.median(nc[1:])),
                       conv_max=int(nc.max()), conv_total=n_total, t_conv_ms=t_conv * 1e3,
                       fft_share_ratio=t_v / (n_total * t_conv) if n_total else np.nan,
                       max_residual=float(np.max(Tv["residual"])),
                       all_converged=bool(np.all(Tv["converged"])),
                       note=f"{int((~np.asarray(Tv['converged'], bool)).sum())} not converged "
                            f"(max_iter={args.vsr_max_iter}){rep_note}", **_cmp_cols(cmpv))
            curves["vsr"] = vsr_rows
        rows_out.append(row)
        log(f"   vsr: {row['wall_s']:.2f} s, ratio {row['ratio_vs_fast']:.1f}x, median {row['conv_median']:.0f} "
            f"conv/eq, max {row['conv_max']}; {row['note']}")

    # ---- ContactMechanics / Adhesion ---------------------------------------------------------
    if args.no_peer:
        rows_out.append(dict(group=name, solver="ContactMechanics/Adhesion", path="-", note="skipped (--no-peer)"))
    elif not peer.available():
        rows_out.append(dict(group=name, solver="ContactMechanics/Adhesion", path="-",
                             note="skipped: contactmechanics/adhesion not installed (pip install -e .[bench])"))
        log("   peer: not installed, skipped")
    else:
        k_peer = args.peer_max_eq[min(args.groups.index(name), len(args.peer_max_eq) - 1)] if args.peer_max_eq else 0
        k_peer = n_eq if k_peer <= 0 else min(n_eq, k_peer)
        D_peer, br_peer = D_path[:k_peer], br_path[:k_peer]
        pr = None
        for _ in range(reps):
            pr_i = peer.solve_path(U0, grid.dx, args.mu, D_peer, tol=args.tol, branch=br_peer, dy=grid.dy,
                                   length_fn=lambda P: ts_contact_length(P, grid, apex), verbose=args.verbose)
            if pr is None or pr_i.wall_time < pr.wall_time:
                pr = pr_i
        ok_p = np.asarray(pr.converged, bool)
        # only converged peer answers are compared; the failed ones are listed in the curves file
        peer_rows = {_key(b, D): (F, L) for b, D, F, L, o in
                     zip(pr.branch, pr.D, pr.F, pr.contact_length, ok_p) if o}
        # the retraction's first row (D = d_max) is the approach's last state
        k_top = _key("approach", D_path.max())
        if k_peer == n_eq and k_top in peer_rows:
            peer_rows[_key("retraction", D_path[np.argmax(D_path)])] = peer_rows[k_top]
        curves["peer_solve"] = {_key(b, D): (t_, r_) for b, D, t_, r_ in zip(pr.branch, pr.D, pr.time, pr.residual)}
        fast_s_by_key = {_key(b, D): s_ for b, D, s_ in zip(br, T["D"], T["seconds"])}
        # tengsim fast's own seconds on the same equilibria (the whole run's wall time on a full path)
        if k_peer == n_eq:
            fast_ref_s, fast_ref_cpu = wall_fast, cpu_fast
        else:
            keys_p = {_key(b, D) for b, D in zip(br_peer, D_peer)}
            fast_ref_s = float(sum(s_ for k_, s_ in fast_s_by_key.items() if k_ in keys_p))
            fast_ref_cpu = fast_ref_s * cpu_fast / wall_fast
        # the same ratio on the equilibria the peer solved (both codes' own solve seconds)
        keys_ok = [_key(b, D) for b, D, o in zip(pr.branch, pr.D, ok_p) if o]
        t_peer_ok = float(np.sum(np.asarray(pr.time)[ok_p]))
        t_fast_ok = float(sum(fast_s_by_key.get(k_, 0.0) for k_ in keys_ok))
        n_fail = int((~ok_p).sum())
        fail_note = ""
        if n_fail:
            first = int(np.argmax(~ok_p))
            n_inf = int(np.isinf(np.asarray(pr.residual)[~ok_p]).sum())
            fail_note = (f"; NOT converged on {n_fail} of {k_peer} equilibria (first: {pr.branch[first]} "
                         f"D = {pr.D[first]:g}, max|r| = {pr.residual[first]:.1e}; {n_inf} of them with "
                         f"min g <= 0, i.e. interpenetrated, the others above tol after 8 gtol refinements), "
                         f"excluded from ΔF; ratio on the {len(keys_ok)} converged ones "
                         f"{t_peer_ok / t_fast_ok:.1f}× (peer {t_peer_ok:.1f} s vs fast {t_fast_ok:.2f} s of solve time)")
        cmpp = compare(fast_ref, peer_rows)
        # one peer convolution on its padded grid: evaluate_force is one FFT + one inverse FFT
        from ContactMechanics import FreeFFTElasticHalfSpace
        sub = FreeFFTElasticHalfSpace(grid.shape, young=args.mu ** -1.5,
                                      physical_sizes=(grid.lx, grid.ly))
        d_typ = np.random.default_rng(0).standard_normal(sub.nb_subdomain_grid_pts)
        t_conv_p = time_call(lambda: sub.evaluate_force(d_typ))
        path_p = (f"full ({n_eq} eq)" if k_peer == n_eq else
                  f"cut: first {k_peer} eq (D {D_peer[0]:g} -> {D_peer[-1]:g}); ratio vs fast's seconds on them "
                  f"({fast_ref_s:.2f} s)")
        row = dict(group=name, solver="ContactMechanics/Adhesion", path=path_p, n_eq=k_peer,
                   wall_s=pr.wall_time, ratio_vs_fast=pr.wall_time / fast_ref_s,
                   cpu_s=pr.info["cpu_s"], cpu_ratio_vs_fast=pr.info["cpu_s"] / fast_ref_cpu,
                   conv_median=float(np.median(pr.n_conv[1:])), conv_max=int(pr.n_conv.max()),
                   conv_total=int(pr.n_conv.sum()), t_conv_ms=t_conv_p * 1e3,
                   fft_share_ratio=pr.wall_time / (pr.n_conv.sum() * t_conv_p),
                   max_residual=float(pr.residual[ok_p].max()) if ok_p.any() else np.nan,
                   all_converged=bool(pr.converged.all()),
                   n_failed=n_fail, ratio_converged=t_peer_ok / t_fast_ok if t_fast_ok > 0 else np.nan,
                   note=(f"L-BFGS-B (maxcor {pr.info['maxcor']}), ftol=0, gtol adapted to max|r|<=tol: "
                         f"{pr.gtol.min():.1e}..{pr.gtol.max():.1e}; FFT grid {pr.info['fft_grid']}{fail_note}{rep_note}"),
                   **_cmp_cols(cmpp))
        curves["peer"] = peer_rows
        sym = next((r for r in rows_out if r.get("solver") == "tengsim fast, symmetry"), None)
        if sym is not None and k_peer == n_eq:  # the peer on the whole path: its ratio to the symmetric run too
            row["note"] += f"; {pr.wall_time / sym['wall_s']:.1f}x tengsim fast with symmetry"
            log(f"   peer / tengsim fast with symmetry: {pr.wall_time / sym['wall_s']:.1f}x")
        rows_out.append(row)
        log(f"   peer: {pr.wall_time:.2f} s ({row['ratio_vs_fast']:.1f}x fast), median {row['conv_median']:.0f} conv/eq,"
            f" max {row['conv_max']}; max dF {row['dF_approach']:.2e}/{row['dF_retraction']:.2e}"
            f" (rel {row['dF_rel_approach']:.2e}/{row['dF_rel_retraction']:.2e}), max dLc "
            f"{row['dLc_approach']:.3f}/{row['dLc_retraction']:.3f}{fail_note}")
    for r in rows_out:
        r.setdefault("grid", f"{grid.nx}x{grid.ny}")
        r.setdefault("dx", grid.dx)
        r.setdefault("tol", args.tol)
    return rows_out, curves, dict(grid=(grid.nx, grid.ny), dx=grid.dx, d_max=d_max)


def _cmp_cols(c):
    return {"dF_approach": c["approach"]["dF"], "dF_retraction": c["retraction"]["dF"],
            "dF_rel_approach": c["approach"]["dF_rel"], "dF_rel_retraction": c["retraction"]["dF_rel"],
            "dLc_approach": c["approach"]["dLc"], "dLc_retraction": c["retraction"]["dLc"]}


COLUMNS = ["group", "solver", "grid", "dx", "tol", "path", "n_eq", "wall_s", "ratio_vs_fast", "cpu_s",
           "cpu_ratio_vs_fast", "conv_median",
           "conv_max", "conv_total", "t_conv_ms", "fft_share_ratio", "max_residual", "all_converged",
           "dF_approach", "dF_retraction", "dF_rel_approach", "dF_rel_retraction", "dLc_approach",
           "dLc_retraction", "note"]


def _fmt(v, spec):
    if v is None or (isinstance(v, float) and not np.isfinite(v)):
        return "–"
    return format(v, spec)


def write_outputs(out, rows, curves_by_group, env, args):
    out.mkdir(parents=True, exist_ok=True)
    with open(out / "results.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=COLUMNS, extrasaction="ignore")
        w.writeheader()
        for r in rows:
            w.writerow({k: r.get(k, "") for k in COLUMNS})
    for gname, curves in curves_by_group.items():
        keys = sorted(set().union(*[set(c) for c in curves.values()]),
                      key=lambda k: (k[0] != "approach", k[1] if k[0] == "approach" else -k[1]))
        with open(out / f"curves_{gname}.csv", "w", newline="") as f:
            w = csv.writer(f)
            names = list(curves)
            # "<solver>_solve" entries hold (solve seconds, Eq. 9 residual max|r|) per equilibrium
            w.writerow(["branch", "D"] + [f"{n}_{q}" for n in names
                                          for q in (("s", "residual") if n.endswith("_solve") else ("F", "Lc"))])
            for k in keys:
                vals = []
                for n in names:
                    F, L = curves[n].get(k, (np.nan, np.nan))
                    vals += [F, L]
                w.writerow([k[0], k[1]] + [f"{v:.8g}" for v in vals])
    lines = ["# Benchmark results: tengsim fast vs tengsim VSR vs ContactMechanics/Adhesion", "",
             f"Command: `{' '.join(['python', 'benchmarks/run_benchmarks.py'] + sys.argv[1:])}`", "",
             "Environment: " + ", ".join(f"{k} {v}" for k, v in env.items() if v is not None), "",
             f"Problem: paper Eq. (9), pyramid groups at μ = {args.mu}, free kernel, LJ 8-2 law "
             f"(Adhesion `Lj82(1, 1)`, E* = μ^-3/2), tolerance max|r| ≤ {args.tol:g} on Eq. (9) for every solver, "
             f"D from {args.d_min} up to d_max and back in steps of {args.d_step}, warm starts.", "",
             "| group | solver | grid | path | wall [s] | × fast | CPU × fast | conv/eq median | conv/eq max | "
             "t_conv [ms] | wall/(conv·t_conv) | max ΔF appr. / retr. (rel.) | max ΔΛc appr. / retr. | max r | note |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        if "wall_s" not in r:
            lines.append(f"| {r['group']} | {r['solver']} | {r.get('grid', '')} | – | – | – | – | – | – | – | – | – | – | {r['note']} |")
            continue
        dF = "–" if "dF_approach" not in r else (
            f"{_fmt(r['dF_approach'], '.1e')} / {_fmt(r['dF_retraction'], '.1e')} "
            f"({_fmt(100 * r['dF_rel_approach'], '.2g')} % / {_fmt(100 * r['dF_rel_retraction'], '.2g')} %)")
        dL = "–" if "dLc_approach" not in r else f"{_fmt(r['dLc_approach'], '.3f')} / {_fmt(r['dLc_retraction'], '.3f')}"
        lines.append(
            f"| {r['group']} | {r['solver']} | {r['grid']} | {r['path']} | {r['wall_s']:.2f} | "
            f"{r['ratio_vs_fast']:.1f} | {_fmt(r.get('cpu_ratio_vs_fast'), '.1f')} | {_fmt(r['conv_median'], '.0f')} | {r['conv_max']} | {r['t_conv_ms']:.3f} | "
            f"{_fmt(r['fft_share_ratio'], '.2f')} | {dF} | {dL} | {_fmt(r.get('max_residual'), '.1e')} | {r['note']} |")
    lines += ["", "Columns: *× fast* is wall time / tengsim fast wall time on the same path (for a sampled VSR "
              "row: per equilibrium, VSR seconds / fast seconds on the same solves from the same starts); "
              "*CPU × fast* the same with process CPU time (robust to other load on the machine); *conv/eq* counts convolutions (FFT pairs) per equilibrium, the median over warm-started ones; "
              "*wall/(conv·t_conv)* is wall time over (convolutions × median time of one convolution on that "
              "grid), 1 = pure FFT; ΔF, ΔΛc are the largest differences from tengsim fast at equal (branch, D), "
              "relative ΔF = max|ΔF| / max|F| of the branch. Λc is measured by tengsim.analysis for every solver.", ""]
    (out / "results.md").write_text("\n".join(lines))
    (out / "results.json").write_text(json.dumps({"env": env, "rows": rows}, indent=1, default=float))


def main(argv=None):
    ap = argparse.ArgumentParser(description="tengsim fast vs VSR vs ContactMechanics/Adhesion")
    ap.add_argument("--groups", nargs="+", default=["A", "C"], choices=sorted(GROUPS))
    ap.add_argument("--dx", type=float, default=0.1)
    ap.add_argument("--mu", type=float, default=0.5)
    ap.add_argument("--tol", type=float, default=1e-6)
    ap.add_argument("--d-min", type=float, default=-1.0)
    ap.add_argument("--d-max", type=float, default=None, help="default: per group (A 4, B 8, C 14)")
    ap.add_argument("--d-step", type=float, default=0.1)
    ap.add_argument("--refine-levels", type=int, default=0)
    ap.add_argument("--vsr-mode", nargs="+", choices=["sampled", "full", "none"], default=["sampled"],
                    help="per group, in the order of --groups (the last one repeats): e.g. --groups A C "
                         "--vsr-mode full sampled")
    ap.add_argument("--vsr-every", type=int, default=10)
    ap.add_argument("--repeat", type=int, nargs="+", default=[1],
                    help="runs of every solver's path per group (one value per group); the fastest counts")
    ap.add_argument("--vsr-max-iter", type=int, default=20000)
    ap.add_argument("--no-peer", action="store_true")
    ap.add_argument("--symmetry", action="store_true",
                    help="also tengsim fast on the symmetry-reduced block (symmetry = auto; the first row is the full grid)")
    ap.add_argument("--peer-max-eq", type=int, nargs="+", default=None,
                    help="per group like --vsr-mode (0 = full path): solve only the first K equilibria of the "
                         "path with the peer (a cut path; its ratio is then against tengsim fast's own seconds "
                         "on those equilibria)")
    ap.add_argument("--out", type=Path, default=HERE / "results")
    ap.add_argument("-v", "--verbose", action="store_true")
    args = ap.parse_args(argv)

    def log(msg):
        print(msg, flush=True)

    env = environment()
    log("environment: " + json.dumps(env))
    rows, curves = [], {}
    for gname in args.groups:
        r, c, _ = run_group(gname, args, log)
        rows += r
        curves[gname] = c
        write_outputs(args.out, rows, curves, env, args)  # keep what is done
    log(f"wrote {args.out}/results.md, results.csv")
    print((args.out / "results.md").read_text())


if __name__ == "__main__":
    main()
