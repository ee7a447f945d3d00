"""What a viscoelastic time step costs against a warm-started static solve (docs/benchmarks.md, "Viscoelastic").

The same paraboloid (R = 0.025, κ = 10, Repulsive wall, dx = 0.2, 45² points) and the same indentation
history D: 0 → 360 → 0 ε in 40 steps: the static drive (an elastic material, no branch) and a standard linear
solid (E0 = 2 E∞, τ = the loading time).  Both warm-start each step from the previous state; the ratio is of
the convolutions (the unit of cost) and of the wall time per step.

    OPENBLAS_NUM_THREADS=1 PYTHONPATH=src python benchmarks/visco_step_cost.py
"""
from __future__ import annotations

import time

from tengsim.laws import Repulsive
from tengsim.relaxation import Prony, sls
from tengsim.shapes import Paraboloid
from tengsim.visco import FixedTimeSteps, simulate_history, triangle


def one(material):
    t0 = time.perf_counter()
    r = simulate_history(Paraboloid(0.025, 9.0), 10 ** (2 / 3), 0.2, material, triangle(0.0, 360.0, 1.0, 1.0),
                         FixedTimeSteps(0.05), law=Repulsive(), tol=1e-5)
    return r, time.perf_counter() - t0


if __name__ == "__main__":
    (rs, ts), (rv, tv) = one(Prony(1.0)), one(sls(1.0, 1.0, 1.0))
    ns, nv = rs["n_conv"][1:].mean(), rv["n_conv"][1:].mean()
    print(f"static:  {len(rs.t) - 1} steps, {ns:.1f} convolutions/step, {ts / (len(rs.t) - 1) * 1e3:.1f} ms/step")
    print(f"visco:   {len(rv.t) - 1} steps, {nv:.1f} convolutions/step, {tv / (len(rv.t) - 1) * 1e3:.1f} ms/step")
    print(f"ratio:   {nv / ns:.2f} in convolutions, {tv / ts:.2f} in time")
