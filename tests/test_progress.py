"""Progress output: no carriage returns in logs, few lines, and reports from inside a long solve."""
import io

import pytest

from tengsim.run.plan import ContactPlan
from tengsim.progress import Progress


def _run(bar, total=1000):
    for i in range(1, total + 1):
        bar("approach", 0.01 * i, i, total)
    bar.close()


def test_log_stream_gets_plain_lines_at_a_low_rate():
    s = io.StringIO()  # not a terminal, like a log file or a pipe
    _run(Progress(stream=s, min_interval=0.0))
    text = s.getvalue()
    assert "\r" not in text
    lines = text.splitlines()
    assert 10 <= len(lines) <= 12  # every 10 % (and the end), not once per equilibrium
    assert lines[-1].startswith("tengsim: 1000/1000 (100 %) approach 10")


def test_log_stream_line_every_interval_even_without_10_percent():
    s = io.StringIO()
    bar = Progress(stream=s, line_interval=0.0)  # a slow run: every call is "30 s later"
    for i in range(1, 6):
        bar("retraction", 1.0, i, 1000)
    assert len(s.getvalue().splitlines()) == 5


def test_terminal_gets_one_updating_line():
    s = io.StringIO()
    _run(Progress(stream=s, tty=True, min_interval=0.0), total=20)
    text = s.getvalue()
    assert text.count("\r") == 20 and text.endswith("\n") and text.count("\n") == 1


def test_quiet_writes_nothing():
    s = io.StringIO()
    bar = Progress(quiet=True, stream=s, tty=False, line_interval=0.0)
    _run(bar, total=10)
    bar.monitor(0.0)(5, 1e-3, -1.0)
    assert s.getvalue() == ""


@pytest.mark.parametrize("tty", [False, True])
def test_monitor_reports_inside_a_solve_at_most_every_interval(tty):
    s = io.StringIO()
    bar = Progress(stream=s, tty=tty)
    slow = bar.monitor(interval=3600.0)
    for it in range(0, 1000, 10):
        slow(it, 1e-2, -3.0)
    assert s.getvalue() == ""  # rate-limited
    fast = bar.monitor(interval=0.0)
    fast(0, 1.0, 0.0)   # starts the clock
    fast(20, 2.5e-4, -1.25)
    assert "solve: iteration 20, max|r| = 0.00025" in s.getvalue()
    assert ("\r" in s.getvalue()) == tty


def test_simulate_reports_inside_long_solves(monkeypatch):
    """contact.simulate hands the progress's monitor to the fast solver on large grids (threshold
    lowered here so that a small grid counts as large)."""
    from tengsim.run import simulate as contact
    from tengsim.shapes import Paraboloid
    from tengsim.continuation import PathSpec

    monkeypatch.setattr(contact, "MONITOR_MIN_POINTS", 0)
    s = io.StringIO()
    bar = Progress(stream=s, line_interval=0.0)
    contact.simulate(ContactPlan(Paraboloid(1.0, 6.0), 1.0, 0.3, PathSpec(-0.5, 0.0, 0.5)), progress=bar)
    text = s.getvalue()
    assert "tengsim: solve: iteration" in text and "\r" not in text
    # a plain callable (no .monitor) still works, and small grids are not monitored by default
    monkeypatch.setattr(contact, "MONITOR_MIN_POINTS", 1024**2)
    s2 = io.StringIO()
    contact.simulate(ContactPlan(Paraboloid(1.0, 6.0), 1.0, 0.3, PathSpec(-0.5, 0.0, 0.5)), progress=Progress(stream=s2, line_interval=0.0))
    assert "solve:" not in s2.getvalue()
