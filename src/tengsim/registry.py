"""Extension points: one protocol and one registry each for shapes, laws, kernels, solvers and observers.

Everything that lists names (config validation, CLI choices and help, result metadata, docs) reads
them from here; no other module keeps its own list.  A user extends tengsim from their own module::

    from tengsim.registry import LAWS

    @LAWS.register("mylaw", summary="my interaction law")
    class MyLaw(tengsim.laws.Law): ...

and ``law = "mylaw"`` then works in :func:`tengsim.simulate`, TOML runs and ``tengsim contact --law``.
This module imports nothing of tengsim's but :mod:`tengsim.errors`: the built-in pieces register
themselves here on import exactly as a plugin's do, and :mod:`tengsim.plugins` imports both (the
built-in packages, then the modules named in ``TENGSIM_PLUGINS`` and the ``tengsim.plugins`` entry
points).
"""
from __future__ import annotations

from typing import Any, Generic, Iterator, Protocol, TypeVar, runtime_checkable

import numpy as np

from tengsim.errors import TengsimError

T = TypeVar("T")


# ---- protocols: what a piece must offer -------------------------------------------------------

@runtime_checkable
class ShapeLike(Protocol):
    """Initial gap U0 >= 0 (in ε) of the elastic surface over a grid of its cell (paper Eq. 11)."""

    cell: float

    def gap(self, grid) -> np.ndarray: ...

    def grid(self, dx: float): ...

    def params(self) -> dict: ...


@runtime_checkable
class LawLike(Protocol):
    """Surface interaction: energy Φ(g) and pressure P(g) = −dΦ/dg of the gap g = h/ε (paper Eq. 2/8).

    A law also declares its own numbers, read by the resolution status: ``max_tension`` (W/ε),
    ``g_peak``, ``g_zero`` and ``cohesive_range`` (ε), ``work`` (W) and ``max_softening`` (W/ε²);
    subclasses of :class:`tengsim.laws.Law` inherit a numerical fallback for any they do not give.
    """

    g_safe: float

    def evaluate(self, g: np.ndarray) -> tuple[np.ndarray, np.ndarray]: ...

    def energy_pressure(self, g: np.ndarray, out: np.ndarray, work) -> float: ...

    def params(self) -> dict: ...


@runtime_checkable
class KernelLike(Protocol):
    """Elastic operator w = K p on a grid (one convolution per ``apply``, paper Eq. 9)."""

    grid: Any
    periodic: bool

    def apply(self, p: np.ndarray, out: np.ndarray | None = None) -> np.ndarray: ...

    def params(self) -> dict: ...


@runtime_checkable
class FourierKernelLike(KernelLike, Protocol):
    """A kernel that multiplies in Fourier space, which the JAX solver (tengsim.solvers.jax_fast) runs on its
    device: w = irfft2(rfft2(p, s=padded_shape) · spectrum) cropped to the grid.  ``padded_shape`` is the grid's
    shape (periodic) or the zero-padded one (free cell); ``spectrum`` the multiplier on the rfft2 layout of
    ``padded_shape``; ``pinned_mean`` True when the mean of p is not set by K (periodic half-space: K̂(0) = 0)."""

    padded_shape: tuple
    pinned_mean: bool

    @property
    def spectrum(self) -> np.ndarray: ...


@runtime_checkable
class SolverLike(Protocol):
    """Finds one stable equilibrium of a :class:`tengsim.solvers.Problem` from a start state."""

    tol: float
    name: str

    def solve(self, problem, start): ...


@runtime_checkable
class ObserverLike(Protocol):
    """Scalar observables of one equilibrium, added as columns of the result table.

    ``columns`` names what ``__call__(eq, ctx)`` returns (a dict of floats); ``ctx`` has the grid, the
    apex index and the initial gap U0.  ``units`` maps a column to its unit text (optional).
    """

    columns: tuple

    def __call__(self, eq, ctx) -> dict: ...


# ---- the registry ------------------------------------------------------------------------------

class Registry(Generic[T]):
    """Names → objects of one kind, with aliases and a one-line summary each."""

    def __init__(self, kind: str, protocol: type | None = None):
        self.kind = kind
        self.protocol = protocol
        self._items: dict[str, T] = {}
        self._aliases: dict[str, str] = {}
        self._summary: dict[str, str] = {}

    @staticmethod
    def _key(name: str) -> str:
        return str(name).strip().lower().replace("-", "_")

    def register(self, name: str, obj: T | None = None, *, aliases=(), summary: str | None = None,
                 replace: bool = False):
        """Register ``obj`` under ``name`` (usable as a decorator); returns ``obj``."""
        def add(o: T) -> T:
            key = self._key(name)
            if not replace and (key in self._items or key in self._aliases):
                raise TengsimError(f"{self.kind} {name!r} is already registered")
            for a in aliases:  # an alias may not take a name or alias of another entry (checked before any change)
                ak = self._key(a)
                owner = ak if ak in self._items else self._aliases.get(ak)
                if owner is not None and owner != key and not replace:
                    raise TengsimError(f"{self.kind} {name!r}: alias {a!r} is already "
                                       + (f"the {self.kind} {owner!r}" if ak == owner else f"an alias of {owner!r}"))
                if ak == key:
                    raise TengsimError(f"{self.kind} {name!r}: alias {a!r} is its own name")
            self._items[key] = o
            doc = (getattr(o, "__doc__", None) or "").strip().splitlines()
            self._summary[key] = summary or (doc[0].rstrip(".") if doc else "")
            for a in aliases:
                self._aliases[self._key(a)] = key
            return o
        return add if obj is None else add(obj)

    def unregister(self, name: str) -> None:
        key = self.canonical(name)
        self._items.pop(key)
        self._summary.pop(key, None)
        for a in [a for a, k in self._aliases.items() if k == key]:
            del self._aliases[a]

    def canonical(self, name: str) -> str:
        """The registered name for ``name`` or an alias of it; a TengsimError naming the choices."""
        key = self._key(name)
        key = self._aliases.get(key, key)
        if key not in self._items:
            raise TengsimError(f"unknown {self.kind} {name!r} (choose from {', '.join(self.names())})")
        return key

    def get(self, name: str) -> T:
        return self._items[self.canonical(name)]

    def name_of(self, obj) -> str:
        """The registered name of ``obj`` (a registered object, or an instance of a registered class)."""
        for k, v in self._items.items():
            if v is obj or (isinstance(v, type) and type(obj) is v):
                return k
        return type(obj).__name__

    def names(self) -> tuple[str, ...]:
        return tuple(self._items)

    def summary(self, name: str) -> str:
        return self._summary[self.canonical(name)]

    def help(self) -> str:
        """'name (summary), ...' for --help texts and docs."""
        return "; ".join(f"{k}: {s}" if s else k for k, s in self._summary.items())

    def __contains__(self, name) -> bool:
        key = self._key(name)
        return self._aliases.get(key, key) in self._items

    def __iter__(self) -> Iterator[str]:
        return iter(self._items)

    def __len__(self) -> int:
        return len(self._items)

    def __repr__(self) -> str:
        return f"Registry({self.kind!r}, {list(self._items)})"


SHAPES: Registry = Registry("shape", ShapeLike)
LAWS: Registry = Registry("law", LawLike)
KERNELS: Registry = Registry("boundary", KernelLike)
SOLVERS: Registry = Registry("solver", SolverLike)
OBSERVERS: Registry = Registry("observer", ObserverLike)
