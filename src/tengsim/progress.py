"""Progress on stderr (no dependency); silent when ``quiet``.

On a terminal one line updates in place (``\\r``).  On anything else (a log file, a pipe) plain lines
are written at a low rate: at each further 10 % of the run and at least every ``line_interval``
seconds, never a ``\\r``.  :meth:`Progress.monitor` reports inside one long solve.
"""
from __future__ import annotations

import sys
import time


def say_to(progress, text: str) -> None:
    """``text`` to ``progress.say`` where it has one (a run's own line: which solver 'auto' chose, a range
    extended); nothing where the progress is None or only counts."""
    if progress is not None and hasattr(progress, "say"):
        progress.say(text)


def _isatty(stream) -> bool:
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError):  # no isatty, or a closed stream
        return False


class Progress:
    """Callable as ``progress(label, value, done, total)`` (the path's per-equilibrium report)."""

    def __init__(self, quiet: bool = False, stream=None, min_interval: float = 0.2, tty: bool | None = None,
                 line_interval: float = 30.0, line_fraction: float = 0.1):
        self.quiet = quiet
        self.stream = stream or sys.stderr
        self.tty = _isatty(self.stream) if tty is None else bool(tty)
        self.t0 = time.perf_counter()
        self.last = -float("inf")
        self.min_interval = min_interval
        self.line_interval = line_interval
        self.line_fraction = line_fraction
        self._next_frac = 0.0
        self.active = False

    def _write(self, text: str) -> None:
        self.stream.write(text)
        self.stream.flush()

    def __call__(self, label, value, done, total):
        if self.quiet:
            return
        now = time.perf_counter()
        frac = done / total if total else 1.0
        if self.tty:
            if done < total and now - self.last < self.min_interval:
                return
            self.last = now
            width = 28
            bar = "#" * int(width * frac) + "-" * (width - int(width * frac))
            line = f"[{bar}] {done}/{total} {label} {value:.4g}  {now - self.t0:6.1f}s"
            self._write(f"\r{line:<78}")
            self.active = True
            if done >= total:
                self.close()
            return
        if done < total and frac < self._next_frac and now - self.last < self.line_interval:
            return
        self.last = now
        while self._next_frac <= frac:
            self._next_frac += self.line_fraction
        self._write(f"tengsim: {done}/{total} ({100 * frac:3.0f} %) {label} {value:.4g}  "
                    f"{now - self.t0:.1f} s\n")

    def monitor(self, interval: float | None = None):
        """A ``monitor(iteration, max|r|, energy)`` callable for a solver (FastSolver's ``monitor``): it
        prints ``solve: iteration N, max|r| …`` at most every ``interval`` seconds (default 5 s on a
        terminal, ``line_interval`` otherwise); the first call only starts the clock."""
        every = (5.0 if self.tty else self.line_interval) if interval is None else float(interval)
        state = {"last": None}

        def report(iteration, rmax, energy=float("nan")):
            if self.quiet:
                return
            now = time.perf_counter()
            if state["last"] is None:
                state["last"] = now
                return
            if now - state["last"] < every:
                return
            state["last"] = now
            msg = f"solve: iteration {iteration}, max|r| = {rmax:.3g}, E = {energy:.8g}  {now - self.t0:.1f} s"
            if self.tty:
                self._write(f"\r{msg:<78}")
                self.active = True
            else:
                self._write(f"tengsim: {msg}\n")

        return report

    def close(self):
        if self.active and not self.quiet:
            self._write("\n")
        self.active = False
