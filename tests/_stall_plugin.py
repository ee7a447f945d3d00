"""Test plugin (loaded through TENGSIM_PLUGINS by tests/test_streaming.py): an observer whose column
counts the rows; while TENGSIM_TEST_STALL_AFTER=k is set it blocks before the (k+1)-th row is recorded,
so a test can kill the run at a known point.  Without the variable it only counts."""
import os
import time

from tengsim.registry import OBSERVERS


@OBSERVERS.register("test_stall")
class Stall:
    columns = ("stall_count",)

    def __init__(self):
        self.n = 0

    def __call__(self, eq, ctx):
        self.n += 1
        k = int(os.environ.get("TENGSIM_TEST_STALL_AFTER") or 0)
        if k and self.n > k:
            time.sleep(600)  # the test kills the process here
        return {"stall_count": float(self.n)}
