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
