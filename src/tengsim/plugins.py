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
import re

import tengsim.kernels
import tengsim.laws
import tengsim.observers
import tengsim.shapes
import tengsim.solvers
import tengsim.solvers.homotopy
import tengsim.solvers.pk
import tengsim.solvers.ram
import tengsim.solvers.jax_fast
import tengsim.solvers.choice
from tengsim.errors import TengsimError
from tengsim.registry import KERNELS, LAWS, OBSERVERS, SHAPES, SOLVERS

BUILT_IN = (
    tengsim.kernels,  # registers 'free', 'periodic'
    tengsim.laws,  # registers 'lj93', 'repulsive', 'md', 'exp'
    tengsim.observers,  # registers 'summary', 'array_area'
    tengsim.shapes,  # registers every built-in shape
    tengsim.solvers,  # registers 'fast', 'vsr'
    tengsim.solvers.homotopy,  # registers 'homotopy'
    tengsim.solvers.pk,  # registers 'pk'
    tengsim.solvers.ram,  # registers 'ram'
    tengsim.solvers.jax_fast,  # registers 'jax', 'gpu'; imports JAX only when one is made
    tengsim.solvers.choice,  # registers 'auto': gpu where JAX sees one, else fast
)
"""The built-in modules whose import fills the registries (each registers its pieces when imported)."""

__all__ = ["BUILT_IN", "KERNELS", "LAWS", "OBSERVERS", "SHAPES", "SOLVERS", "load_plugins"]

_LOADED: set = set()


_MODULE = re.compile(r"[A-Za-z_][A-Za-z0-9_]*(\.[A-Za-z_][A-Za-z0-9_]*)*")


def _guarded(what: str, load) -> None:
    """Run ``load()`` (one plugin's import) inside the one guard every plugin passes: whatever it raises
    (an ImportError, any exception, a ``sys.exit``) becomes one TengsimError naming ``what``."""
    from tengsim.errors import shown

    try:
        load()
    except TengsimError as exc:  # e.g. a name or alias clashing with a built-in one
        raise TengsimError(f"plugin {what}: {exc}") from None
    except ImportError as exc:
        raise TengsimError(f"plugin {what}: cannot import it: {shown(str(exc), 200)[1:-1]}") from None
    except SystemExit as exc:
        raise TengsimError(f"plugin {what} called sys.exit({shown(exc.code)}) while loading") from None
    except Exception as exc:  # noqa: BLE001 - a broken plugin is named, never a traceback or exit 70
        msg = " ".join(str(exc).split()) or "(no message)"
        raise TengsimError(f"plugin {what} failed to load: {type(exc).__name__}: {shown(msg, 200)[1:-1]}") from None


def load_plugins() -> None:
    """Import the modules named in ``TENGSIM_PLUGINS`` and the ``tengsim.plugins`` entry points (each once),
    each inside :func:`_guarded`: a module name that is not a dotted Python name ('../../x') is refused."""
    from tengsim.errors import shown

    for mod in filter(None, (m.strip() for m in os.environ.get("TENGSIM_PLUGINS", "").split(","))):
        if mod in _LOADED:
            continue
        if not _MODULE.fullmatch(mod):
            raise TengsimError(f"TENGSIM_PLUGINS: {shown(mod)} is not a module name (dotted Python names, "
                               "comma-separated, e.g. mypkg.shapes)")

        _guarded(f"{mod!r} (TENGSIM_PLUGINS)", lambda mod=mod: importlib.import_module(mod))
        _LOADED.add(mod)
    try:
        from importlib.metadata import entry_points

        eps = list(entry_points(group="tengsim.plugins"))
    except Exception as exc:  # noqa: BLE001 - broken package metadata
        raise TengsimError(f"tengsim.plugins entry points cannot be listed: {exc}") from None
    for ep in eps:
        if ep.value not in _LOADED:
            _guarded(f"{ep.name!r} (entry point {ep.value})", ep.load)
            _LOADED.add(ep.value)
