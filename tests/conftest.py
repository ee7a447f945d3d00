"""Fixtures shared by test modules."""
import pytest


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
