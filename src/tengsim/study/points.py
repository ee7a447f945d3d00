"""A study's point files: what a point's id covers, writing a point file, checking one before it is trusted.

**Provenance.**  A point's id (:func:`tengsim.study.hashing.point_id`) is a digest of its ``[contact]``
table and of :func:`provenance`, everything else that determines its result:

* ``format`` — :data:`FORMAT`, the point-file format (what a point file holds and how its status reads);
* ``tengsim`` — the tengsim version (``tengsim._version``);
* ``plugins`` — a SHA-256 of the source of each plugin module (``TENGSIM_PLUGINS`` and the
  ``tengsim.plugins`` entry points; a package: every ``.py`` file under it);
* ``inputs`` — a SHA-256 of each input file the table names: every string value that is an existing
  file (a ``topography``'s ``file``; read from the current directory, as the run reads it).

So a point computed by other code or from another file never has the id of this one, and a resumed
study never takes it for this one.  A worker checks the provenance it sees against the client's
before it computes (:func:`tengsim.study.worker.compute_point`).

**Point files.**  :func:`write_point` writes ``DIR/points/<id>.nc`` atomically (``tengsim.io.atomic_path``:
fsync of the file and of its directory), with ``point_id`` and a ``content_digest`` attribute: a SHA-256
of every variable's bytes and every other attribute, as read back from the file.  :func:`check_point`
opens a point file and checks it is readable, holds the point it is named for and matches its digest;
the assembler and a resumed study trust no other.
"""
from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path

FORMAT = "tengsim-point/2"
"""Point-file format: 2 = the point's ``status`` is the run's physical status (tengsim.status), the file
carries ``point_id``, ``provenance`` and ``content_digest``."""

DIGEST_ATTR = "content_digest"

_FILE_DIGESTS: dict = {}  # (path, size, mtime_ns, inode) -> hex digest: a file is read again only when it changed


def file_digest(path) -> str:
    """SHA-256 (hex) of a file's bytes (cached while its size, mtime and inode stay the same)."""
    p = os.path.abspath(path)
    st = os.stat(p)
    key = (p, st.st_size, st.st_mtime_ns, st.st_ino)
    got = _FILE_DIGESTS.get(key)
    if got is None:
        h = hashlib.sha256()
        with open(p, "rb") as fh:
            for chunk in iter(lambda: fh.read(1 << 20), b""):
                h.update(chunk)
        got = _FILE_DIGESTS[key] = h.hexdigest()
    return got


_ENTRY_POINTS: list = []  # [modules] once read: the installed distributions, read once per process


def _entry_point_modules() -> list:
    """Modules of the ``tengsim.plugins`` entry points (read once per process: a scan of every installed
    distribution costs ~20 ms, and an id is asked for many times per point)."""
    if not _ENTRY_POINTS:
        try:
            from importlib.metadata import entry_points

            _ENTRY_POINTS.append([ep.module for ep in entry_points(group="tengsim.plugins")])
        except Exception:  # noqa: BLE001 - load_plugins reports a broken entry point
            _ENTRY_POINTS.append([])
    return _ENTRY_POINTS[0]


def plugin_modules() -> list:
    """Names of the plugin modules: ``TENGSIM_PLUGINS`` (comma-separated), then the ``tengsim.plugins``
    entry points' modules."""
    mods = [m.strip() for m in os.environ.get("TENGSIM_PLUGINS", "").split(",") if m.strip()]
    return list(dict.fromkeys(mods + _entry_point_modules()))


def module_digest(name: str) -> str:
    """SHA-256 of a module's source (a package: of every .py file under it, with their relative paths);
    'unavailable' for a module that cannot be found."""
    import importlib.util

    try:
        spec = importlib.util.find_spec(name)
    except (ImportError, ValueError):
        spec = None
    if spec is None:
        return "unavailable"
    if spec.submodule_search_locations:
        h = hashlib.sha256()
        for root in spec.submodule_search_locations:
            files = sorted(Path(root).rglob("*.py"))
            for f in files:
                h.update(str(f.relative_to(root)).encode() + b"\0" + file_digest(f).encode())
        return h.hexdigest()
    if spec.origin and os.path.isfile(spec.origin):
        return file_digest(spec.origin)
    return f"{spec.origin or 'unknown'}"  # a built-in or frozen module: its kind


def input_files(contact: dict) -> dict:
    """{key: path} of the table's values that name an existing file (not an expression)."""
    out = {}
    for k, v in contact.items():
        if isinstance(v, str) and v and not v.startswith("=") and os.path.isfile(v):
            out[k] = v
    return out


def provenance(contact: dict) -> dict:
    """What besides the [contact] table determines a point's result (module docstring)."""
    from tengsim._version import __version__

    return {"format": FORMAT, "tengsim": __version__,
            "plugins": {m: module_digest(m) for m in plugin_modules()},
            "inputs": {k: file_digest(p) for k, p in input_files(contact).items()}}


def provenance_difference(a: dict, b: dict) -> str:
    """What differs between two provenances, in words ('' if nothing): 'tengsim 0.1 → 0.2', ..."""
    out = []
    for k in ("format", "tengsim"):
        if a.get(k) != b.get(k):
            out.append(f"{k} {a.get(k)} → {b.get(k)}")
    for group, what in (("plugins", "plugin module"), ("inputs", "input file of key")):
        x, y = a.get(group) or {}, b.get(group) or {}
        for name in sorted(set(x) | set(y)):
            if x.get(name) != y.get(name):
                state = "added" if name not in x else "removed" if name not in y else "changed"
                out.append(f"{what} {name!r} {state}")
    return ", ".join(out)


# ---- point files --------------------------------------------------------------------------------

def _text(v):
    if isinstance(v, bytes):
        return v.decode("utf-8", "replace")
    if hasattr(v, "tolist"):
        v = v.tolist()
        return v.decode("utf-8", "replace") if isinstance(v, bytes) else v
    return v


def _digest(f) -> str:
    """SHA-256 of an open h5py File: every dataset (name, dtype, shape, bytes) and every attribute but
    the digest itself, in name order."""
    import h5py
    import numpy as np

    h = hashlib.sha256()
    names = []
    f.visititems(lambda name, obj: names.append(name) if isinstance(obj, h5py.Dataset) else None)
    for name in sorted(names):
        a = np.asarray(f[name][()])
        h.update(f"{name}\0{a.dtype.str}\0{a.shape}\0".encode())
        if a.dtype.kind == "O":
            for x in a.ravel().tolist():
                h.update((x if isinstance(x, bytes) else str(x).encode()) + b"\0")
        else:
            h.update(np.ascontiguousarray(a).tobytes())
    attrs = {k: _text(v) for k, v in f.attrs.items() if k != DIGEST_ATTR}
    h.update(json.dumps(attrs, sort_keys=True, default=str).encode())
    return h.hexdigest()


def write_point(ds, path) -> None:
    """Write a point's Dataset (attrs ``point_id`` set) to ``path`` atomically, with its content digest.

    The file appears under its name only whole and synced to the disk (``tengsim.io.atomic_path``);
    Ctrl-C waits for the write."""
    from tengsim.io import interrupts_held, netcdf_bytes, write_bytes

    def sign(f):
        f.attrs[DIGEST_ATTR] = _digest(f)

    with interrupts_held():  # made in memory, then written: a full disk is an OSError naming the path
        write_bytes(path, netcdf_bytes(ds, sign))


def check_point(path, pid: str) -> tuple:
    """(status, None) for a sound point file of point ``pid``: its run status (tengsim.status); or
    (None, why) naming what is wrong: unreadable, another point's, no or a mismatching digest."""
    import h5py

    from tengsim.io import interrupts_held
    from tengsim.status import SEVERITY

    try:
        with interrupts_held(), h5py.File(path, "r") as f:
            got = _text(f.attrs.get("point_id"))
            if got != pid:
                return None, ("has no point id" if got is None else f"holds point {got}, not {pid}")
            stored = f.attrs.get(DIGEST_ATTR)
            if stored is None:
                return None, "has no content digest (written before format " + FORMAT + ")"
            if _text(stored) != _digest(f):
                return None, "does not match its content digest (changed or damaged since it was written)"
            status = _text(f.attrs.get("status"))
    except (OSError, ValueError, KeyError, TypeError, RuntimeError) as exc:
        first = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        return None, f"is unreadable ({first})"
    if status not in SEVERITY:
        return None, f"has an unknown status {status!r}"
    return status, None


__all__ = ["FORMAT", "check_point", "file_digest", "input_files", "module_digest", "plugin_modules",
           "provenance", "provenance_difference", "write_point"]
