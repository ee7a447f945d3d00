"""Writing a run's rows as it goes (``OUT.partial.csv``, maps in ``OUT.partial.maps.npz``), resuming
such a file, and the paths beside an output a run keeps while it works."""
from __future__ import annotations

import json

import numpy as np

from tengsim.results.columns import CURVE_COLUMNS

PARTIAL_SUFFIX = ".partial.csv"
_STREAM_KEYS = ("complete", "partial_of", "run_digest")  # the stream's own header lines
_RESUME_RTOL = 1e-5  # a re-solved row and the file's row agree in F to this, relative to max(1, |F|)
_PATH_ENDS = ("d_max", "f_max")  # a resumed run may raise these: the same path, longer (its start is kept)


def _longer_path(now: dict, header: dict) -> bool:
    """True when the run ``now`` differs from the partial file's run only by a longer path (a larger d_max
    or f_max), so the file's rows up to where the paths part are this run's too."""
    keys = {k for k in [*now, *header] if k not in _STREAM_KEYS}
    diff = [k for k in keys if now.get(k) != header.get(k)]
    try:
        return bool(diff) and all(k in _PATH_ENDS and float(now[k]) >= float(header[k]) for k in diff)
    except (KeyError, TypeError, ValueError):
        return False


def partial_path(out):
    """The file a run writes its rows to as they are computed: ``OUT.partial.csv`` beside ``OUT``."""
    from pathlib import Path

    return Path(str(out) + PARTIAL_SUFFIX)


def checkpoint_path(out):
    """Where a refinement (``resolve = 'auto'``) writing ``OUT`` keeps its finished grids, the finest one's
    result and the levels so far: ``OUT.resolve.nc`` beside it (:class:`tengsim.run.resolve.Checkpoint`)."""
    from pathlib import Path

    return Path(str(out) + ".resolve.nc")


def partial_maps_path(out):
    """The maps of a run writing to a NetCDF ``OUT``, kept as they are computed: ``OUT.partial.maps.npz``."""
    from pathlib import Path

    return Path(str(out) + ".partial.maps.npz")


def run_digest(params: dict) -> str:
    """SHA-256 of the run's parameters (strict JSON, sorted keys): a partial file resumes only under the
    run that wrote it (same parameters, same tengsim version)."""
    import hashlib

    from tengsim.io import jsonable

    return hashlib.sha256(json.dumps(jsonable(params), sort_keys=True).encode()).hexdigest()


class RowStream:
    """Writes a contact run's rows to ``OUT.partial.csv`` as each equilibrium finishes, so a run that is
    killed (even by SIGKILL) keeps every finished equilibrium.

    Pass it as ``sink`` to :func:`tengsim.run.simulate.simulate`.  The first row writes the
    file, whole (atomically): the header (``# complete: false``, ``# partial_of``, ``# run_digest`` and the
    run's parameters given to :meth:`begin`, as '# key: json' lines) and the column names, so a run that
    fails before its first equilibrium leaves nothing; each row is then appended as one CSV line (the
    format of :meth:`ContactResult.save`) and flushed to the operating system, so it survives the process
    being killed; ``os.fsync`` runs at
    most every ``fsync_seconds`` (against a machine crash, kept cheap).  For a NetCDF output (``maps=True``)
    the maps go to ``OUT.partial.maps.npz`` (written whole, atomically, when a map is added).  Once the
    whole result is saved, :meth:`finish` removes both.  A partial file is a readable result
    (:func:`tengsim.results.read.load_result`), marked incomplete by its ``complete: false`` header.

    ``resume=(header, columns)`` (:func:`tengsim.results.read.read_partial`) continues such a file: :meth:`begin`
    refuses it unless its run digest is this run's (the first differing parameter is named), and the rows
    it holds are solved again and each checked against the file (branch, D, on_grid and jump equal, F
    within 1e-5 of max(1, |F|)) instead of being written; later rows are appended.  The path is walked
    from its start again because each equilibrium is warm-started from the states before it, which the
    file does not hold: a resumed file is the uninterrupted run's, and resuming costs the finished part's
    solves once more.
    """

    def __init__(self, out, resume=None, maps: bool = False, fsync_seconds: float = 10.0):
        self.out, self.path = out, partial_path(out)
        self.maps_path = partial_maps_path(out) if maps else None
        self.resume = resume
        self.fsync_seconds = fsync_seconds
        self.fh, self.columns, self.n, self.maps = None, None, 0, []
        self._old, self._head, self._longer = {}, None, False
        if resume is not None:
            header, cols = resume
            self._old = cols
            self.columns = list(cols) or None
        self.n_old = len(next(iter(self._old.values()))) if self._old else 0
        self._synced = 0.0

    @property
    def n_written(self) -> int:
        """Rows the partial file holds now."""
        return max(self.n, self.n_old)

    def begin(self, params: dict) -> None:
        import time

        from tengsim import io
        from tengsim.errors import TengsimError

        digest = run_digest(params)
        if self.resume is not None:
            header = self.resume[0]
            self._truncate_torn_line()
            now = io.jsonable(params)
            self._longer = header.get("run_digest") != digest and _longer_path(now, header)
            if self._longer:  # the file takes this run's header; its rows are checked as they come
                self._head = {"complete": False, "partial_of": str(self.out), "run_digest": digest, **params}
                self._rewrite(self.n_old)
            elif header.get("run_digest") != digest:
                keys = [k for k in [*now, *header] if k not in _STREAM_KEYS]
                diff = next((k for k in keys if now.get(k) != header.get(k)), None)
                what = (f"{diff}: {header.get(diff)!r} there, {now.get(diff)!r} now" if diff
                        else "its run digest differs")
                raise TengsimError(f"--resume: {self.path} was written by another run ({what}); "
                                   "delete it to start afresh")
            if self.fh is None:
                self.fh = open(self.path, "a", newline="", encoding="utf-8")
        else:  # written with the first row: a run that fails before it leaves nothing behind
            self._head = {"complete": False, "partial_of": str(self.out), "run_digest": digest, **params}
        self._synced = time.monotonic()

    def _rewrite(self, keep: int) -> None:
        """The partial file again, whole (atomically): this run's header, the column names and its first
        ``keep`` rows (a longer path resumed: the rows past where the paths part are dropped)."""
        from tengsim import io

        if self.fh is not None:
            self.fh.close()
        with open(self.path, newline="", encoding="utf-8") as fh:
            lines = [ln for ln in fh.read().splitlines(keepends=True) if not ln.startswith("#")]
        body = "".join(lines[:1 + keep]) if lines else ""
        io.write_text(self.path, io.header_lines(self._head) + body)
        self.fh = open(self.path, "a", newline="", encoding="utf-8")

    def _truncate_torn_line(self) -> None:
        """Cut a last line that a kill left half written (no newline): the reader skipped it too."""
        with open(self.path, "rb+") as fh:
            data = fh.read()
            if data and not data.endswith(b"\n"):
                fh.truncate(data.rfind(b"\n") + 1)

    def __call__(self, row: dict, maps=()) -> None:
        import os
        import time

        from tengsim import io
        from tengsim.errors import TengsimError

        cols = [*[k for k in CURVE_COLUMNS if k in row], *[k for k in row if k not in CURVE_COLUMNS]]
        if self.fh is None:  # a new file: header and column names appear whole, then rows are appended
            io.write_text(self.path, io.header_lines(self._head) + io.csv_row(cols))
            self.fh = open(self.path, "a", newline="", encoding="utf-8")
        if self.columns is None:
            if self.resume is not None:  # a partial file that had no row yet
                self.fh.write(io.csv_row(cols))
            self.columns = cols
        elif cols != self.columns:
            raise TengsimError(f"--resume: {self.path} has columns {', '.join(self.columns)}; this run "
                               f"has {', '.join(cols)}; delete it to start afresh")
        i, self.n = self.n, self.n + 1
        if maps and self.maps_path is not None:
            self.maps.extend(maps)
            self._write_maps()
        if i < self.n_old:
            self._check(i, row)
            return
        self.fh.write(io.csv_row([row[k] for k in self.columns]))
        self.fh.flush()  # in the operating system's hands: survives the process being killed
        if time.monotonic() - self._synced >= self.fsync_seconds:
            os.fsync(self.fh.fileno())
            self._synced = time.monotonic()

    def _check(self, i: int, row: dict) -> None:
        from tengsim.errors import TengsimError

        old = {k: self._old[k][i] for k in ("branch", "D", "F", "on_grid", "jump")}
        same = (str(old["branch"]) == str(row["branch"]) and float(old["D"]) == float(row["D"])
                and bool(float(old["on_grid"])) == bool(row["on_grid"])
                and bool(float(old["jump"])) == bool(row["jump"])
                and abs(float(old["F"]) - float(row["F"])) <= _RESUME_RTOL * max(1.0, abs(float(row["F"]))))
        if not same and self._longer:  # the longer path parts from the file's here: the rest is solved anew
            self._rewrite(i)
            self.n_old = i
            from tengsim import io

            self.fh.write(io.csv_row([row[k] for k in self.columns]))
            self.fh.flush()
            return
        if not same:
            raise TengsimError(
                f"--resume: row {i + 1} of {self.path} ({old['branch']}, D={float(old['D']):.10g}, "
                f"F={float(old['F']):.10g}) is not what this run gives ({row['branch']}, D={float(row['D']):.10g}, "
                f"F={float(row['F']):.10g}); delete it to start afresh")

    def _write_maps(self) -> None:
        from tengsim import io

        with io.atomic_path(self.maps_path) as tmp, open(tmp, "wb") as fh:
            np.savez(fh, map_branch=np.array([m["branch"] for m in self.maps]),
                     map_D=np.array([m["D"] for m in self.maps], dtype=float),
                     P=np.stack([m["P"] for m in self.maps]), H=np.stack([m["H"] for m in self.maps]))

    def close(self) -> None:
        """Flush, sync and close the partial file (it stays: a readable, incomplete result)."""
        import os

        if self.fh is not None and not self.fh.closed:
            self.fh.flush()
            os.fsync(self.fh.fileno())
            self.fh.close()

    def finish(self) -> None:
        """The whole result is saved: close and remove the partial file (and maps)."""
        self.close()
        for p in (self.path, self.maps_path, checkpoint_path(self.out)):  # a refinement's grids too
            if p is not None:
                p.unlink(missing_ok=True)
