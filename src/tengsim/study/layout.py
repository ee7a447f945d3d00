"""Layout of a study directory: where each file of a sweep or an optimisation lives (paths only).

::

    DIR/study.json            resolved points of the study (checked on --resume)
    DIR/points/<id>.nc        one finished contact computation (result + params, timings, the run's status,
                              version, provenance, point_id and content_digest: tengsim.study.points)
    DIR/points/<id>.failed.json   a point that raised (its message); rerun only with --retry-failed
    DIR/points/<id>.nc.bad    a point file found unsound on --resume (unreadable, another id, a digest
                              mismatch), kept aside for inspection; the point is computed again
    DIR/points/.<name>.part   a write in progress (an atomic rename gives it its final name)
    DIR/log.jsonl             one line per finished or failed point, in completion order
    DIR/study.nc, study.csv   the assembled dataset (tengsim.study.dataset), rebuilt at the end
    DIR/optimum.json          the best point found by ``tengsim optimize``
    DIR/.lock                 held (a POSIX record lock) by the one sweep or optimisation running in DIR

Both the runner (:mod:`tengsim.study.runner`, :mod:`tengsim.study.optimize`) and the assembler
(:mod:`tengsim.study.dataset`) read the directory through :class:`StudyDir`; neither imports the other
for it.
"""
from __future__ import annotations

import contextlib
import os
from dataclasses import dataclass
from pathlib import Path

_HELD: dict = {}
"""The study folders this process holds (:meth:`StudyDir.lock`): resolved lock path → descriptor."""


@dataclass
class StudyDir:
    """The files of the study directory ``root`` (nothing is created or read on construction)."""

    root: Path

    def __post_init__(self):
        self.root = Path(self.root)

    @property
    def points(self) -> Path:
        return self.root / "points"

    def nc(self, pid) -> Path:
        return self.points / f"{pid}.nc"

    def failed(self, pid) -> Path:
        return self.points / f"{pid}.failed.json"

    def drop_partial(self) -> int:
        """Remove the temporary files of writes a kill interrupted (``.<name>.part``; never a finished
        point, which only appears under its final name by an atomic rename); returns how many."""
        stale = list(self.points.glob(".*.part")) if self.points.is_dir() else []
        for f in stale:
            f.unlink(missing_ok=True)
        return len(stale)

    @contextlib.contextmanager
    def lock(self, who: str = "sweep"):
        """Hold ``DIR/.lock`` while the block runs; a second sweep or optimisation on the same folder is
        refused with one TengsimError naming the folder and the holder's pid, instead of computing every
        point twice.

        The lock is a POSIX record lock (``lockf``): it belongs to this process, is released by the OS
        when the process ends, and is *not* inherited by a child forked meanwhile (a worker a Dask nanny
        restarts) — a flock belongs to the open file and a forked copy kept the folder held after the
        sweep ended.  Record locks do not exclude the same process, so the folders this process holds are
        kept in ``_HELD`` and a second lock from within it is refused too."""
        import fcntl

        from tengsim.errors import TengsimError

        self.root.mkdir(parents=True, exist_ok=True)
        path = self.root / ".lock"
        key = os.path.realpath(path)

        def refuse(holder):
            return TengsimError(f"--out {self.root} is in use by another sweep or optimisation (pid {holder}); "
                                "wait for it to finish, or use another --out")

        if key in _HELD:
            raise refuse(os.getpid())
        fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
        try:
            try:
                fcntl.lockf(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError:
                raise refuse(os.pread(fd, 32, 0).decode(errors="replace").strip() or "unknown") from None
            os.ftruncate(fd, 0)
            os.pwrite(fd, f"{os.getpid()}\n".encode(), 0)
            _HELD[key] = fd
            try:
                # and the one lock of every command's output folder (tengsim.outfolder): a design, calibration
                # or reproduction on this folder meanwhile is refused too, and this sweep if one holds it
                from tengsim.outfolder import folder_lock

                with folder_lock(self.root, holder=f"tengsim {who}"):
                    yield path
            finally:
                _HELD.pop(key, None)
        finally:
            os.close(fd)  # closing releases the lock

    @property
    def spec(self) -> Path:
        return self.root / "study.json"

    @property
    def log(self) -> Path:
        return self.root / "log.jsonl"

    @property
    def dataset_nc(self) -> Path:
        return self.root / "study.nc"

    @property
    def dataset_csv(self) -> Path:
        return self.root / "study.csv"

    @property
    def optimum(self) -> Path:
        """The best point of ``tengsim optimize``."""
        return self.root / "optimum.json"

    def done(self) -> set:
        """Ids of the finished points (a ``<id>.nc`` under points/)."""
        if not self.points.is_dir():
            return set()
        return {f.name[:-3] for f in self.points.glob("*.nc")}

    def failures(self) -> set:
        """Ids of the failed points (a ``<id>.failed.json`` under points/)."""
        if not self.points.is_dir():
            return set()
        return {f.name[: -len(".failed.json")] for f in self.points.glob("*.failed.json")}


__all__ = ["StudyDir"]
