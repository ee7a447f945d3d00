"""The solver ``auto``: the JAX solver (float64) where JAX sees a GPU and the grid is large enough to gain from it,
the NumPy fast solver everywhere else.

:func:`choose` turns a solver name into the one a run uses and the sentence that says why (printed before the
run); ``auto`` is the default of every contact run and design.  Whether JAX sees a GPU is asked without
importing JAX where no GPU plugin of JAX is installed (a CPU-only machine pays nothing); where one is,
JAX is imported and asked for its GPU devices (once per process).
"""
from __future__ import annotations

import functools
import importlib.util

from tengsim.registry import SOLVERS
from tengsim.solvers.types import SOLVER_TOL

#: the distributions that give JAX a GPU backend (CUDA or ROCm plugins; old jaxlib CUDA builds)
GPU_PLUGINS = ("jax_cuda12_plugin", "jax_cuda13_plugin", "jax_cuda11_plugin", "jax_rocm60_plugin",
               "jax_rocm7_plugin", "jax_plugins")


@functools.lru_cache(maxsize=1)
def gpu_visible() -> bool:
    """True when JAX is installed and sees at least one GPU."""
    if importlib.util.find_spec("jax") is None:
        return False
    if not any(_has_module(m) for m in GPU_PLUGINS):
        return False
    try:
        from tengsim.solvers.jax_fast import prepare_environment

        prepare_environment()  # before JAX starts: the share of the GPU's memory it may take
        import jax

        return bool(jax.devices("gpu"))
    except Exception:  # noqa: BLE001 — no backend, a broken CUDA: no GPU
        return False


def _has_module(name: str) -> bool:
    try:
        return importlib.util.find_spec(name) is not None
    except (ImportError, ValueError):
        return False


def choose(name, points=None) -> tuple:
    """(the solver a run uses, why): ``auto`` → 'gpu' when :func:`gpu_visible` and the run's grid has at least
    :func:`tengsim.resources.gpu_break_even_points` ``points`` (None: any size), else 'fast'; any other name
    (or a solver object) unchanged."""
    if not isinstance(name, str) or name.strip().lower() != "auto":
        if isinstance(name, str) and name.strip().lower() == "gpu" and not gpu_visible():
            from tengsim.errors import SolverUnavailable

            raise SolverUnavailable("--solver gpu: JAX sees no GPU here (install JAX for CUDA: pip install "
                               "'tengsim[gpu]', CUDA 12 driver); use --solver auto or fast")
        return name, ""
    if gpu_visible():
        from tengsim.resources import gpu_break_even_points

        even = gpu_break_even_points()
        if points is not None and points < even:
            return "fast", (f"solver: fast (auto: JAX sees a GPU, but a grid of {int(points)} points is below its "
                            f"break-even of about {even:.0f}; the NumPy fast solver on the CPU)")
        return "gpu", "solver: gpu (auto: JAX sees a GPU; the fast solver compiled with JAX, float64)"
    return "fast", "solver: fast (auto: JAX sees no GPU; the NumPy fast solver on the CPU)"


def auto_solver(tol: float = SOLVER_TOL, **kw):
    """The solver :func:`choose` picks for 'auto', made with ``tol`` (API: ``make_solver('auto')``)."""
    return SOLVERS.get(choose("auto")[0])(tol=tol, **kw)


SOLVERS.register("auto", auto_solver, summary="the jax solver on a GPU when JAX sees one (float64) and the grid is over "
                 "its break-even (≈ 109²), else fast (the default; the choice is printed before the run)")


__all__ = ["GPU_PLUGINS", "auto_solver", "choose", "gpu_visible"]
