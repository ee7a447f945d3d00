"""The solver a run uses on the grid it solves: ``auto`` becomes the JAX solver (float64) where JAX sees a GPU
(:func:`tengsim.solvers.choice.gpu_visible`) and the grid has at least the GPU's break-even of points
(:func:`tengsim.resources.gpu_break_even_points`), the NumPy fast solver everywhere else; any other name is kept.

:func:`choose` gives the name and the sentence that says why, which the run prints where it solves (one grid, or
each grid of a refinement whose choice changes: :func:`tengsim.run.plan.chosen_solver`).  The plan keeps 'auto'.
"""
from __future__ import annotations

from tengsim.errors import SolverUnavailable
from tengsim.solvers import choice as _machine

NO_GPU = ("--solver gpu: JAX sees no GPU here (install JAX for CUDA: pip install 'tengsim[gpu]', CUDA 12 driver); "
          "use --solver auto or fast")
"""The refusal of a solver asked for by the name 'gpu' where JAX sees none."""


def choose(name, points=None) -> tuple:
    """(the solver a run uses, why): ``auto`` → 'gpu' where JAX sees a GPU and the run's grid has at least the
    break-even ``points`` (None: any size), else 'fast'; 'gpu' where JAX sees none: :class:`SolverUnavailable`;
    any other name (or a solver object) unchanged, with no sentence."""
    if not isinstance(name, str) or name.strip().lower() != "auto":
        if isinstance(name, str) and name.strip().lower() == "gpu" and not _machine.gpu_visible():
            raise SolverUnavailable(NO_GPU)
        return name, ""
    if not _machine.gpu_visible():
        return "fast", "solver: fast (auto: JAX sees no GPU; the NumPy fast solver on the CPU)"
    from tengsim.resources import gpu_break_even_points

    even = gpu_break_even_points()
    if points is not None and points < even:
        return "fast", (f"solver: fast (auto: JAX sees a GPU, but a grid of {int(points)} points is below its "
                        f"break-even of about {even:.0f}; the NumPy fast solver on the CPU)")
    return "gpu", "solver: gpu (auto: JAX sees a GPU; the fast solver compiled with JAX, float64)"


__all__ = ["NO_GPU", "choose"]
