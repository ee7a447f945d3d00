"""Calling a kernel's ``apply``: into the solver's own output array when it accepts ``out=``."""
from __future__ import annotations

import functools
import inspect


def takes_out(fn) -> bool:
    """Does ``fn`` accept an ``out=`` keyword (the package's kernels do)?  Asked once per function
    (``inspect.signature`` is slow next to a warm equilibrium on a small grid)."""
    func = getattr(fn, "__func__", fn)  # a bound method's function: the same answer for every instance
    try:
        return _signature_takes_out(func)
    except TypeError:  # an unhashable callable: not cached
        return _signature_takes_out.__wrapped__(func)


@functools.lru_cache(maxsize=64)
def _signature_takes_out(fn) -> bool:
    try:
        params = inspect.signature(fn).parameters.values()
    except (TypeError, ValueError):
        return False
    return any(p.name == "out" or p.kind is p.VAR_KEYWORD for p in params)
