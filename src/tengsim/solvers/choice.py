"""The solver ``auto``: the JAX solver (float64) where JAX sees a GPU, the NumPy fast solver everywhere else.

Which one a run uses on the grid it solves (the GPU only above its break-even) is the run layer's choice, said
where it is made (:func:`tengsim.run.choice.choose`); ``auto`` is the default of every contact run and design.
Whether JAX sees a GPU is asked without importing JAX where no GPU plugin of JAX is installed (a CPU-only
machine pays nothing); where one is, JAX is imported and asked for its GPU devices (once per process).
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


def auto_solver(tol: float = SOLVER_TOL, **kw):
    """The solver 'auto' is on a grid of any size, made with ``tol`` (API: ``make_solver('auto')``): 'gpu' where
    :func:`gpu_visible`, else 'fast'.  A run chooses on the grid it solves (:func:`tengsim.run.choice.choose`)."""
    return SOLVERS.get("gpu" if gpu_visible() else "fast")(tol=tol, **kw)


SOLVERS.register("auto", auto_solver, summary="the jax solver on a GPU when JAX sees one (float64) and the grid is over "
                 "its break-even (≈ 109²), else fast (the default; the choice is printed before the run)")


__all__ = ["GPU_PLUGINS", "auto_solver", "gpu_visible"]
