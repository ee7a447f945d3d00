"""cProfile of tengsim's fast solver on one pyramid curve (default group C, free kernel), and the
share of time spent in the FFTs.

    OPENBLAS_NUM_THREADS=1 python benchmarks/profile_fast.py --group C --dx 0.1 --out benchmarks/results

Writes ``profile_<group>.txt`` (top functions by own time and by cumulative time) and prints the
FFT share: own time of scipy.fft's transforms (rfft2/irfft2 and their C++ workers) over the
total, plus "wall / (convolutions × one convolution)".
"""
from __future__ import annotations

import argparse
import cProfile
import io
import pstats
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from run_benchmarks import GROUPS, ConvCounter, time_call  # noqa: E402


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--group", default="C", choices=sorted(GROUPS))
    ap.add_argument("--dx", type=float, default=0.1)
    ap.add_argument("--mu", type=float, default=0.5)
    ap.add_argument("--tol", type=float, default=1e-6)
    ap.add_argument("--d-min", type=float, default=-1.0)
    ap.add_argument("--d-max", type=float, default=None)
    ap.add_argument("--d-step", type=float, default=0.1)
    ap.add_argument("--out", type=Path, default=HERE / "results")
    a = ap.parse_args(argv)

    from tengsim import kernels
    from tengsim.continuation import PathSpec
    from tengsim.run.plan import ContactPlan
    from tengsim.run.simulate import simulate
    from tengsim.shapes import Pyramid

    g = GROUPS[a.group]
    d_max = a.d_max if a.d_max is not None else g["d_max"]
    grid = Pyramid(g["N"], g["cell"]).grid(a.dx)
    kernel = kernels.make_kernel("free", grid, a.mu ** 1.5)
    P = np.random.default_rng(0).standard_normal(grid.shape)
    t_conv = time_call(lambda: kernel.apply(P))

    cnt = ConvCounter(type(kernel))
    prof = cProfile.Profile()
    t0 = time.perf_counter()
    prof.enable()
    simulate(ContactPlan(Pyramid(g["N"], g["cell"]), a.mu, a.dx, PathSpec(a.d_min, d_max, a.d_step, refine_levels=0), boundary="free", solver="fast", solver_tol=a.tol))
    prof.disable()
    wall = time.perf_counter() - t0
    cnt.restore()

    st = pstats.Stats(prof)
    total = sum(v[2] for v in st.stats.values())  # own time of every function
    fft_own = sum(v[2] for k, v in st.stats.items()
                  if ("scipy/fft" in k[0] or "pocketfft" in k[0] or "_pocketfft" in str(k[2])
                      or k[2] in ("rfft2", "irfft2", "r2c", "c2r", "rfftn", "irfftn")))
    apply_cum = sum(v[3] for k, v in st.stats.items() if k[2] == "apply" and "kernels" in k[0])
    buf = io.StringIO()
    ps = pstats.Stats(prof, stream=buf)
    ps.sort_stats("tottime").print_stats(25)
    ps.sort_stats("cumulative").print_stats(25)
    summary = (f"group {a.group}, grid {grid.nx}x{grid.ny}, padded {kernel.padded_shape}: wall {wall:.2f} s under "
               f"cProfile, {cnt.n} convolutions, one convolution {t_conv * 1e3:.3f} ms\n"
               f"FFT own time {fft_own:.2f} s = {100 * fft_own / total:.1f} % of profiled time {total:.2f} s; "
               f"kernel.apply cumulative {apply_cum:.2f} s = {100 * apply_cum / total:.1f} %\n"
               f"wall / (conv × t_conv) = {wall / (cnt.n * t_conv):.2f}\n")
    a.out.mkdir(parents=True, exist_ok=True)
    (a.out / f"profile_{a.group}.txt").write_text(summary + "\n" + buf.getvalue())
    print(summary)
    print(buf.getvalue()[:6000])


if __name__ == "__main__":
    main()
