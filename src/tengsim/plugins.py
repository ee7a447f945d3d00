"""The registries, filled: the built-in pieces and the user's plugins, treated alike.

Each built-in package (:mod:`tengsim.shapes`, :mod:`tengsim.laws`, :mod:`tengsim.kernels`,
:mod:`tengsim.solvers`, :mod:`tengsim.observers`) registers its pieces into :mod:`tengsim.registry`
when imported, exactly as a third-party plugin module does; this module imports them (the one place
that does), and :func:`load_plugins` then imports the modules named in the environment variable
``TENGSIM_PLUGINS`` (comma-separated) and the ``tengsim.plugins`` entry-point group.  A module that
reads a registry by name imports this one.
"""
from __future__ import annotations

import importlib
import os

import tengsim.kernels  # noqa: F401  (registers 'free', 'periodic')
import tengsim.laws  # noqa: F401  (registers 'lj93', 'repulsive', 'md', 'exp')
import tengsim.observers  # noqa: F401  (registers 'summary', 'array_area')
import tengsim.shapes  # noqa: F401  (registers every built-in shape)
import tengsim.solvers  # noqa: F401  (registers 'fast', 'vsr')
import tengsim.solvers.homotopy  # noqa: F401  (registers 'homotopy')
import tengsim.solvers.jax_fast  # noqa: F401  (registers 'jax', 'gpu'; imports JAX only when one is made)
from tengsim.errors import TengsimError
from tengsim.registry import KERNELS, LAWS, OBSERVERS, SHAPES, SOLVERS

__all__ = ["KERNELS", "LAWS", "OBSERVERS", "SHAPES", "SOLVERS", "load_plugins"]

_LOADED: set = set()


def load_plugins() -> None:
    """Import the modules named in ``TENGSIM_PLUGINS`` and the ``tengsim.plugins`` entry points (each once)."""
    for mod in filter(None, (m.strip() for m in os.environ.get("TENGSIM_PLUGINS", "").split(","))):
        if mod in _LOADED:
            continue
        try:
            importlib.import_module(mod)
        except ImportError as exc:
            raise TengsimError(f"TENGSIM_PLUGINS: cannot import {mod!r}: {exc}") from None
        _LOADED.add(mod)
    try:
        from importlib.metadata import entry_points

        for ep in entry_points(group="tengsim.plugins"):
            if ep.value not in _LOADED:
                ep.load()
                _LOADED.add(ep.value)
    except Exception as exc:  # noqa: BLE001 - a broken plugin is reported, not a traceback
        raise TengsimError(f"tengsim.plugins entry point failed: {exc}") from None
