"""A sweep's progress line: points done of the total, failed, rate and ETA."""
from __future__ import annotations

import time

from tengsim.progress import Progress


class SweepProgress(Progress):
    """A sweep's :class:`tengsim.progress.Progress`: done/total, failed, rate and ETA, updated per point.

    Only the text is the sweep's; stream, terminal detection, writing and :meth:`close` are Progress's:
    one updating line on a TTY, a plain line per finished point otherwise."""

    def __init__(self, total, done=0, failed=0, quiet=False, stream=None):
        super().__init__(quiet=quiet, stream=stream)
        self.total, self.done, self.failed = total, done, failed
        self.start_done = done + failed

    def text(self) -> str:
        """``sweep: N/total points (k failed), R points/h, ETA h:mm:ss``."""
        n = self.done + self.failed - self.start_done
        dt = time.perf_counter() - self.t0
        rate = n / dt * 3600 if dt > 0 and n else 0.0
        left = self.total - self.done - self.failed
        eta = _hms(left / rate * 3600) if rate > 0 else "?"
        return (f"sweep: {self.done + self.failed}/{self.total} points ({self.failed} failed), "
                f"{rate:.4g} points/h, ETA {eta}")

    def update(self, status=None):
        """Count one finished point (``status``: 'failed' or another) and report; ``None`` only reports."""
        if status == "failed":
            self.failed += 1
        elif status is not None:
            self.done += 1
        if self.quiet:
            return
        if self.tty:
            self._write(f"\r{self.text():<78}")
            self.active = True
            if self.done + self.failed >= self.total:
                self.close()
        else:
            self._write(self.text() + "\n")


def _hms(s):
    s = int(round(s))
    return f"{s // 3600}:{s // 60 % 60:02d}:{s % 60:02d}"
