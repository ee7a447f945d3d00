"""What a design keeps between runs: the identity of its grids and the refinement's checkpoint file.

A run of the same design (:func:`identity`: the plan, its input files' content, tengsim's version, the plugins) and
path takes its finished grids back from the file ``keep`` instead of computing them again (:func:`checkpoint`); a
run killed in its second pass (a longer path) resumes on that path (:func:`kept_path`).
"""
from __future__ import annotations

import dataclasses

from tengsim.progress import say_to as _say

def identity(plan) -> str:
    """What a design's kept grids belong to: the plan (every key as given but the budget), the content of every
    input file it names (a topography's heights: the file's bytes, not its name), tengsim's version and the
    plugins loaded (a user's shape or law changed between runs gives other grids).  16 hex digits."""
    import hashlib
    from pathlib import Path

    from tengsim import plugins
    from tengsim._version import __version__

    same = dataclasses.replace(plan, budget_s=0.0)  # a larger --budget goes on from the grids a budget stopped
    h = hashlib.sha256(f"{same!r}|{__version__}|{sorted(plugins._LOADED)!r}".encode())
    for v in (plan.contact_table or {}).values():
        if isinstance(v, str) and len(v) < 4096 and Path(v).is_file():
            with open(v, "rb") as fh:
                for block in iter(lambda: fh.read(1 << 20), b""):
                    h.update(block)
    return h.hexdigest()[:16]


def kept_path(keep, base: str) -> float | None:
    """The D range (ε) of the grids ``keep`` holds for this design (``base``: :func:`identity`), or None: a run
    killed in its second pass (a longer path) resumes on that path, not on the first pass's."""
    if keep is None:
        return None
    from tengsim.run.checkpoint import Checkpoint

    found = Checkpoint(keep, "").stored_digest() or ""
    head, _, d = found.partition("@")
    try:
        return float(d) if head == base else None
    except ValueError:
        return None


def checkpoint(keep, base, d_max, progress):
    """The refinement's checkpoint in the file ``keep`` for this design (``base``, :func:`identity`) and path
    (None without ``keep``): :func:`tengsim.run.checkpoint.open_checkpoint`, its lines said on ``progress``."""
    if keep is None:
        return None
    from tengsim.run.checkpoint import open_checkpoint

    return open_checkpoint(keep, base, d_max, lambda text: _say(progress, text))
