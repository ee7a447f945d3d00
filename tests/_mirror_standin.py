"""A slow stand-in for tengsim.kernels.mirror.MirrorKernel (unfold → full kernel → reduce), for the
solver tests; the real kernel is used when it exists."""
from __future__ import annotations

import numpy as np

from tengsim.grid import Mirror


class _Reduced:
    def __init__(self, full, mirror):
        self.full, self.m = full, mirror
        self.grid = mirror.reduced_grid
        self.periodic = getattr(full, "periodic", False)
        self.pinned_mean = getattr(full, "pinned_mean", self.periodic)

    def apply(self, p, out=None):
        r = self.m.reduce(self.full.apply(self.m.unfold(p)))
        if out is None:
            return r
        out[...] = r
        return out


class StandInMirrorKernel:
    def __init__(self, full, axes):
        self.full = full
        self.grid, self.coupling = full.grid, full.coupling
        self.periodic = getattr(full, "periodic", False)
        self.pinned_mean = getattr(full, "pinned_mean", self.periodic)
        self.mirror = Mirror(full.grid, tuple(axes))
        self.reduced = _Reduced(full, self.mirror)

    def params(self):
        return full_params(self.full)

    def apply(self, p, out=None):
        if not self.mirror.is_symmetric(p):
            raise ValueError("not symmetric")
        return self.full.apply(p, out=out)

    def __getattr__(self, name):
        if name in ("full",):
            raise AttributeError(name)
        return getattr(self.full, name)


def full_params(k):
    f = getattr(k, "params", None)
    return f() if f else {}


def mirror_kernel(boundary, grid, coupling, axes, **params):
    """The real MirrorKernel if tengsim.kernels.mirror exists, else the stand-in."""
    from tengsim.kernels import make_kernel

    try:
        from tengsim.kernels import mirror as km
    except ImportError:
        return StandInMirrorKernel(make_kernel(boundary, grid, coupling, **params), axes)
    if hasattr(km, "make_mirror_kernel"):
        return km.make_mirror_kernel(boundary, grid, coupling, tuple(axes), **params)
    return km.MirrorKernel(boundary, grid, coupling, Mirror(grid, tuple(axes)), **params)
