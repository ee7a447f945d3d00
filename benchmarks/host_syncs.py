"""Host transfers per L-BFGS iteration of the NumPy fast solver through the array seam (tengsim.backend's
``sync`` and ``to_host``): what an array backend on a GPU (CuPy through ``backend/``) would pay per iteration in
device-to-host round trips, against the JAX loop's none.  One cold LJ 9-3 solve, paraboloid, periodic 128².

    python benchmarks/host_syncs.py
"""
import numpy as np
from tengsim import backend
import tengsim.solvers._lbfgs as L, tengsim.solvers.fast as F
import tengsim.plugins
from tengsim.grid import Grid
from tengsim.kernels import PeriodicKernel
from tengsim.laws import LJ93
from tengsim.shapes import Paraboloid
from tengsim.solvers import Problem, State, make_solver
counts = {"sync": 0, "to_host": 0}
for mod in list(__import__("sys").modules.values()):
    if getattr(mod, "__name__", "").startswith("tengsim.solvers"):
        for name in ("sync", "to_host"):
            f = getattr(mod, name, None)
            if f is getattr(backend, name):
                def wrap(*a, _f=f, _n=name, **k):
                    counts[_n] += 1
                    return _f(*a, **k)
                setattr(mod, name, wrap)
for name in ("sync", "to_host"):
    f = getattr(backend, name)
    def wrap(*a, _f=f, _n=name, **k):
        counts[_n] += 1
        return _f(*a, **k)
    setattr(backend, name, wrap)
g = Grid(128, 128, 0.1, 0.1)
shape = Paraboloid(radius=1.0, cell=12.8)
K = PeriodicKernel(g, 1.0)
prob = Problem(g0=shape.gap(g) - 0.5 + 1.0, law=LJ93(), kernel=K)
s = make_solver("fast", tol=1e-8)
eq = s.solve(prob, State.zero(g.shape))
print("iterations", eq.iterations, "n_conv", eq.n_conv, counts, "per iteration", {k: v / max(eq.iterations, 1) for k, v in counts.items()})
