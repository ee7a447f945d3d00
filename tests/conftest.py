"""Fixtures shared by test modules."""
import pytest

import tengsim.plugins  # noqa: F401,E402  (the built-ins registered in their own order before any test imports one alone)


def solver_or_skip(name: str, **kw):
    """The registered solver ``name`` (tengsim.registry.SOLVERS) made with ``kw``, or the test skipped with
    the solver's own reason when it cannot run here (its one-line TengsimError: JAX not installed, no GPU,
    ...).  Tests parametrised over ``SOLVERS.names()`` call this, so a new solver is tested without
    editing a list."""
    from tengsim.errors import TengsimError
    from tengsim.solvers import make_solver

    try:
        return make_solver(name, **kw)
    except TengsimError as e:
        pytest.skip(f"solver {name!r} cannot run here: {e}")


def registered(kind: str):
    """pytest parameters over every registered name of ``kind`` ('solver', 'law', 'boundary', 'shape'), the
    registries filled as a run fills them (tengsim.plugins).  A solver that compiles before its first
    solve (``compiles``: the JAX ones, seconds per grid) is marked slow; one that cannot be made here is
    skipped by :func:`solver_or_skip` with its reason."""
    from tengsim import plugins

    reg = {"solver": plugins.SOLVERS, "law": plugins.LAWS, "boundary": plugins.KERNELS, "shape": plugins.SHAPES}[kind]
    out = []
    for name in reg.names():
        slow = kind == "solver" and getattr(reg.get(name), "compiles", False)
        out.append(pytest.param(name, id=name, marks=(pytest.mark.slow,) if slow else ()))
    return out


@pytest.fixture(scope="module")
def study_client():
    """A 2-worker LocalCluster (the one `tengsim sweep --workers 2` starts), one per test module that asks
    for it (started by the fixture, closed when the module's tests are done: no cluster outlives its
    module)."""
    from tengsim.study.runner import connect

    c, cluster = connect(workers=2)
    try:
        yield c
    finally:
        try:
            c.close()
        finally:
            cluster.close()


def rough_cell(n: int, seed: int):
    """A periodic self-affine rough cell (Hurst 0.8, wavenumbers 2..n/4, 30 ε rms) pressed onto a hard wall 70 ε
    below its highest summit: (grid, gap g0, the periodic kernel at κ = 3), for the constrained solver's tests."""
    import numpy as np

    from tengsim.grid import Grid
    from tengsim.kernels import PeriodicKernel

    rng = np.random.default_rng(seed)
    k = np.fft.fftfreq(n, 1.0 / n)
    kk = np.hypot(*np.meshgrid(k, k, indexing="ij"))
    c = np.where((kk >= 2) & (kk <= n / 4), np.maximum(kk, 1e-9) ** -1.8, 0.0) * np.exp(2j * np.pi * rng.random((n, n)))
    h = np.real(np.fft.ifft2(c))
    h *= 30.0 / h.std()
    grid = Grid(n, n, 1.0, 1.0)
    return grid, h.max() - h - 70.0 + 1.0, PeriodicKernel(grid, 3.0)
