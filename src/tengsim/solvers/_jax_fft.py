"""The convolution w = K x of the JAX loop on one device or split over several (a slab FFT with all-to-all).

One device: ``irfft2(rfft2(x, s=padded) · K̂)`` cropped to the grid.  Several (``mesh`` with one axis
:data:`AXIS` of D devices): each device holds nx/D whole rows of the grid (a slab), and inside
``jax.shard_map``

1. the real transform along y (the rows it holds, zero padded to py for the free cell),
2. an all-to-all: each device gives every other its share of the y frequencies and gets all rows of its own
   share (columns padded to a multiple of D),
3. the transform along x (zero padded to px), the product with its columns of K̂ (sharded the same way), the
   inverse along x, cropped to nx,
4. the all-to-all back and the inverse real transform along y, cropped to ny.

Mathematically the same product as on one device (the same separable transform in the other order of
sums), equal to it to round-off.  Every other array of the loop stays in the global view, its rows split the
same way (``jax.jit`` with :func:`field_sharding`): XLA partitions the element-wise work and turns the
reductions into all-reduces.  Device memory per point: the one-device figure over D, plus the spectrum's
share and two all-to-all buffers of the half spectrum.
"""
from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np
from jax.sharding import Mesh, NamedSharding, PartitionSpec as P

AXIS = "rows"


def make_mesh(devices) -> Mesh:
    """A one-axis mesh over ``devices`` (the grid's rows split over them)."""
    return Mesh(np.asarray(devices), (AXIS,))


def spectrum_columns(half: int, d: int) -> int:
    """Columns of the half spectrum padded to a multiple of the device count ``d``."""
    return -(-half // d) * d


def pad_spectrum(spec, d: int):
    """The kernel's half spectrum (rows px, columns py/2 + 1) with zero columns up to a multiple of ``d``."""
    spec = np.asarray(spec)
    half = spec.shape[1]
    cols = spectrum_columns(half, d)
    return spec if cols == half else np.pad(spec, ((0, 0), (0, cols - half)))


def field_sharding(mesh: Mesh, ndim: int = 1, axis: int = 0):
    """The sharding of a flattened field (ndim 1: its rows of the grid are contiguous blocks) or of a stack of
    them (ndim 2, ``axis`` 1: the point axis split)."""
    spec = [None] * ndim
    spec[axis] = AXIS
    return NamedSharding(mesh, P(*spec))


def spectrum_sharding(mesh: Mesh):
    return NamedSharding(mesh, P(None, AXIS))


def replicated(mesh: Mesh):
    return NamedSharding(mesh, P())


def convolution(shape, padded, periodic: bool, dt, mesh: Mesh | None = None):
    """conv(x, spec) → K x, both flattened fields of ``shape`` in dtype ``dt`` (module doc)."""
    nx, ny = shape
    px, py = (nx, ny) if periodic else padded
    if mesh is None:
        def conv(x, spec):
            if periodic:
                return jnp.fft.irfft2(jnp.fft.rfft2(x.reshape(shape)) * spec, s=shape).astype(dt).ravel()
            y = jnp.fft.irfft2(jnp.fft.rfft2(x.reshape(shape), s=padded) * spec, s=padded)
            return y[:nx, :ny].astype(dt).ravel()

        return conv

    d = mesh.devices.size
    if nx % d:
        raise ValueError(f"{nx} rows do not split over {d} devices")
    half = py // 2 + 1
    cols = spectrum_columns(half, d)

    def local(x, spec):  # x: (nx/d, ny) rows of this device; spec: (px, cols/d) columns of this device
        a = jnp.fft.rfft(x, n=py, axis=1)
        if cols > half:
            a = jnp.pad(a, ((0, 0), (0, cols - half)))
        a = jax.lax.all_to_all(a, AXIS, split_axis=1, concat_axis=0, tiled=True)   # (nx, cols/d)
        a = jnp.fft.ifft(jnp.fft.fft(a, n=px, axis=0) * spec, axis=0)[:nx]
        a = jax.lax.all_to_all(a, AXIS, split_axis=0, concat_axis=1, tiled=True)   # (nx/d, cols)
        return jnp.fft.irfft(a[:, :half], n=py, axis=1)[:, :ny].astype(dt)

    slab = jax.shard_map(local, mesh=mesh, in_specs=(P(AXIS, None), P(None, AXIS)), out_specs=P(AXIS, None))

    def conv(x, spec):
        return slab(x.reshape(shape), spec).ravel()

    return conv


__all__ = ["AXIS", "convolution", "field_sharding", "make_mesh", "pad_spectrum", "replicated",
           "spectrum_columns", "spectrum_sharding"]
