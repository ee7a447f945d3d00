"""The one guard of an output folder, for every command that writes one (design, calibrate, reproduce, run):

* :func:`check_folder`, before any work: the folder can be written, and the run's inputs are safe from it: no
  input file is the folder, lies inside it (a run writes its files and subfolders there: ``report.md``,
  ``fit.csv``, ``designs/``, ``material.toml``), or is one of the files it writes (a hard link too);
* :func:`folder_lock`, for the whole run: an exclusive lock (``OUT/.tengsim.lock``, an ``flock``) that a second run
  on the same folder (a design and a calibration, two calibrations) finds at once and is refused by, in one line
  naming the folder and the run that holds it, instead of mixing its files with ours or deleting the first run's
  checkpoints under it;
* :func:`output_folder`: both, as one block.

Refusals are :class:`tengsim.errors.TengsimError` (one line, exit 2); nothing is written by a refused run (a folder
made only for the lock is removed again).
"""
from __future__ import annotations

import contextlib
import os
import time
from pathlib import Path

from tengsim.errors import TengsimError, shown

LOCK_NAME = ".tengsim.lock"


def _files(inputs) -> list:
    """(as given, resolved) of every input that is an existing file (strings that are not are ignored: a design
    table's other values may be passed as they are)."""
    out = []
    for inp in inputs:
        if not isinstance(inp, (str, os.PathLike)) or not 0 < len(str(inp)) < 4096:
            continue
        try:
            if Path(inp).is_file():
                out.append((str(inp), Path(inp).resolve()))
        except (OSError, ValueError):
            continue
    return out


def check_folder(out, inputs=(), writes=(), what: str = "--out") -> Path:
    """Refuse, before any work, an output folder ``out`` that is a file or cannot be written
    (:func:`tengsim.io.check_output`), or that would replace or hold one of ``inputs`` (module doc); ``writes``:
    the files the run will write (checked against the inputs by identity too, a hard link included).  Returns
    ``out`` as a Path."""
    from tengsim.io import check_output

    out = Path(out)
    check_output(out, inputs, folder=True, what=what)
    root = out.resolve()
    for given, real in _files(inputs):
        if root == real or root in real.parents:
            raise TengsimError(f"{what} {shown(str(out), 200)[1:-1]} holds the input {shown(given, 200)[1:-1]}: "
                               "the run writes its files there and could replace it; choose another folder (or "
                               "move the input out of it)")
        for f in writes:
            f = Path(f)
            with contextlib.suppress(OSError):
                if f.exists() and os.path.samefile(f, given):
                    raise TengsimError(f"{what} {shown(str(out), 200)[1:-1]}: {f.name} there is the input "
                                       f"{shown(given, 200)[1:-1]} (a link to it); choose another folder")
    return out


def _holder_text(holder: str) -> str:
    return f"pid {os.getpid()}{f', {holder}' if holder else ''}, since {time.strftime('%Y-%m-%d %H:%M:%S')}"


@contextlib.contextmanager
def folder_lock(folder, what: str = "--out", holder: str = ""):
    """Hold an exclusive lock on output folder ``folder`` (a file ``.tengsim.lock`` in it, which names the holder:
    its pid, ``holder`` (e.g. 'tengsim calibrate') and since when) for the block: a second run on the same folder,
    from another process or this one, is refused at once with one line naming the folder and the holder."""
    folder = Path(folder)
    made = [p for p in (folder, *folder.parents) if not p.exists()]  # removed again if left empty
    folder.mkdir(parents=True, exist_ok=True)
    lock = folder / LOCK_NAME
    try:
        fh = open(lock, "a+", encoding="utf-8")
    except OSError as exc:
        raise TengsimError(f"cannot write {folder}: {exc.strerror or exc}") from None
    try:
        try:
            import fcntl

            fcntl.flock(fh.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
            if os.fstat(fh.fileno()).st_ino != os.stat(lock).st_ino:  # removed by its holder as we locked it
                raise OSError
        except ImportError:  # pragma: no cover - no fcntl (Windows): no lock
            pass
        except OSError:
            who = ""
            with contextlib.suppress(OSError, ValueError):
                fh.seek(0)
                who = " ".join(fh.read(300).split())
            fh.close()
            raise TengsimError(f"{what} {shown(str(folder), 200)[1:-1]} is in use by another tengsim run"
                               f"{f' ({who})' if who else ''}; wait for it or choose another folder") from None
        with contextlib.suppress(OSError):  # who holds it, for the run that is refused
            fh.seek(0)
            fh.truncate()
            fh.write(_holder_text(holder) + "\n")
            fh.flush()
        try:
            yield folder
        finally:
            with contextlib.suppress(OSError):
                lock.unlink()  # before the unlock: a run that opens it now finds another file and retries
            for p in made:  # a run refused or stopped before writing anything leaves no empty folder
                with contextlib.suppress(OSError):
                    p.rmdir()
    finally:
        fh.close()


@contextlib.contextmanager
def output_folder(out, inputs=(), writes=(), what: str = "--out", holder: str = ""):
    """:func:`check_folder` then :func:`folder_lock` for the block: the one guard of a command's output folder."""
    path = check_folder(out, inputs, writes, what)
    with folder_lock(path, what, holder):
        yield path
