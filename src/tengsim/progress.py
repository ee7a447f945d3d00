"""A small stderr progress bar (no dependency); silent when ``quiet``."""
from __future__ import annotations

import sys
import time


class Progress:
    """Callable as ``progress(label, value, done, total)``; prints one updating line on stderr."""

    def __init__(self, quiet: bool = False, stream=None, min_interval: float = 0.2):
        self.quiet = quiet
        self.stream = stream or sys.stderr
        self.t0 = time.perf_counter()
        self.last = 0.0
        self.min_interval = min_interval
        self.active = False

    def __call__(self, label, value, done, total):
        if self.quiet:
            return
        now = time.perf_counter()
        if done < total and now - self.last < self.min_interval:
            return
        self.last = now
        width = 28
        frac = done / total if total else 1.0
        bar = "#" * int(width * frac) + "-" * (width - int(width * frac))
        self.stream.write(f"\r[{bar}] {done}/{total} {label} {value:.4g}  {now - self.t0:6.1f}s ")
        self.stream.flush()
        self.active = True
        if done >= total:
            self.close()

    def close(self):
        if self.active and not self.quiet:
            self.stream.write("\n")
            self.stream.flush()
        self.active = False
