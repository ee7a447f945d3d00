"""Atomic result writing: a file appears whole or not at all, with the permissions of an ordinary write.

JSON is strict (RFC 8259): NaN and ±inf are written as ``null`` (:func:`jsonable` is the one converter).
CSV goes through the standard :mod:`csv` module (a field holding a comma, quote or newline is quoted), its
columns formatted vectorised: floats as Python's shortest round-trip ``repr``, booleans as 0/1.
"""
from __future__ import annotations

import contextlib
import csv
import io as _stdio
import json
import math
import os
import signal
import stat
import tempfile
import threading
from pathlib import Path


def _umask() -> int:
    """The process umask (read from /proc where it is shown, so it is never changed, even briefly)."""
    try:
        with open("/proc/self/status") as fh:
            for line in fh:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError, IndexError):
        pass
    mask = os.umask(0o022)  # pragma: no cover - no /proc: read it by setting it back at once
    os.umask(mask)
    return mask


def _mode_for(path: Path) -> int:
    """Mode an ordinary ``open(path, 'w')`` would leave: the existing file's, else 0666 & ~umask."""
    try:
        return stat.S_IMODE(os.stat(path).st_mode)
    except OSError:
        return 0o666 & ~_umask()


@contextlib.contextmanager
def interrupts_held():
    """Hold Ctrl-C (SIGINT) until the block ends, then deliver it to the handler that was in place.

    For short writes and reads of result files: an interrupted ``h5netcdf.File`` constructor leaves an
    object whose ``__del__`` prints a traceback at exit.  Outside the main thread (where no handler can
    be set) it holds nothing.  Nested blocks deliver to the outer one."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    got = []
    old = signal.signal(signal.SIGINT, lambda signum, frame: got.append(signum))
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, old)
        if got:
            signal.raise_signal(signal.SIGINT)


def _fsync(path, flags: int = 0) -> None:
    """Flush ``path`` (a file, or a directory with ``os.O_DIRECTORY``) to the disk."""
    fd = os.open(path, os.O_RDONLY | flags)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike):
    """Yield a temporary path beside ``path``; rename it onto ``path`` only on success.

    The file gets the mode an ordinary write would give it (the umask for a new file, the old
    file's mode when one is replaced), not mkstemp's 0600.  Its data reach the disk (fsync) before the
    rename, and the directory entry after it, so that not even an OS crash or power cut leaves an empty
    or partial file under the final name (a file system that cannot sync a directory is let be)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".part", dir=path.parent)
    try:
        with contextlib.suppress(OSError):  # a file system without modes keeps its own
            os.fchmod(fd, _mode_for(path))
    finally:
        os.close(fd)
    try:
        yield Path(tmp)
        with contextlib.suppress(OSError):  # again: the writer may have made the file at tmp anew
            os.chmod(tmp, _mode_for(path))
        _fsync(tmp)
        os.replace(tmp, path)
        with contextlib.suppress(OSError):  # the rename itself, durable (not every platform opens a directory)
            _fsync(path.parent, os.O_DIRECTORY if hasattr(os, "O_DIRECTORY") else 0)
    except OSError as exc:  # a full disk, no permission, a read-only file system: named by the final path
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise OSError(exc.errno, exc.strerror or str(exc), str(path)) from None
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


def check_writable(path) -> None:
    """Fail early (before a long run) if ``path`` could not be written: one clear TengsimError."""
    from tengsim.errors import TengsimError

    path = Path(path)
    parent = path.parent  # the nearest folder that exists: nothing is created by a check
    while not parent.exists() and parent != parent.parent:
        parent = parent.parent
    try:
        if not parent.is_dir():
            raise NotADirectoryError(20, "not a folder", str(parent))
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".check", dir=parent)
        os.close(fd)
        os.unlink(tmp)
    except OSError as exc:
        raise TengsimError(f"cannot write {path}: {exc.strerror or exc}") from None


def check_output(path, inputs=(), *, folder: bool = False, what: str = "--out") -> Path:
    """The one place an output path is chosen: refuse, before any work, a ``path`` that resolves to one of
    ``inputs`` (a topography read as g.csv and written to g.csv would destroy it), a file where a folder
    is wanted (or a folder where a file is), an existing folder that cannot be written, or a place that
    cannot be written at all (:func:`check_writable`).  Strings of ``inputs`` that are not existing files
    are ignored (a config's other values may be passed as they are).  Returns ``path`` as a Path."""
    from tengsim.errors import TengsimError, shown

    path = Path(path)
    target = path.resolve()
    for inp in inputs:
        if not isinstance(inp, (str, os.PathLike)) or len(str(inp)) > 4096:
            continue
        try:
            same = Path(inp).is_file() and (Path(inp).resolve() == target or
                                            (path.exists() and os.path.samefile(inp, path)))
        except (OSError, ValueError):
            continue
        if same:
            raise TengsimError(f"{what} {shown(str(path), 300)[1:-1]} is also an input ({shown(str(inp), 300)[1:-1]}): "
                               "writing it would destroy the input; choose another output")
    if folder:
        if path.exists() and not path.is_dir():
            raise TengsimError(f"{what} {path} is a file, not a folder: choose a folder (it is created)")
        if path.is_dir() and not os.access(path, os.W_OK | os.X_OK):
            raise TengsimError(f"cannot write {path}: permission denied")
        check_writable(path)  # its parent: the folder itself is made when the results are
    else:
        if path.is_dir():
            raise TengsimError(f"{what} {path} is a folder, not a file")
        check_writable(path)
    return path


def check_outputs(paths, inputs=(), *, what: str = "--out") -> list:
    """:func:`check_output` for every file a command will write (a main output and its sidecars, figures):
    none may be an input, each must be writable.  Returns them as Paths."""
    return [check_output(p, inputs, what=what) for p in paths]


def safe_name(name: str, taken: set, reserved=()) -> str:
    """A folder name made from a user's label that stays inside its parent: only letters, digits, '.', '_'
    and '-', never '.' or '..' or a hidden name (leading dots dropped), at most 64 characters, not one of
    ``reserved`` (a sibling file's name) nor one already in ``taken`` (then '_2', '_3', ... appended);
    added to ``taken``."""
    import re

    s = re.sub(r"[^A-Za-z0-9._-]+", "_", str(name)[:256]).strip("_.")[:64].strip("_.") or "design"
    low = {r.lower() for r in reserved}
    base, i = s, 2
    while s in taken or s.lower() in low:
        s, i = f"{base}_{i}", i + 1
    taken.add(s)
    return s


def save_figure(fig, path, **kw) -> None:
    """Save a matplotlib figure atomically (format from the suffix): a full disk or a refused write is an
    OSError naming ``path``, and no partial file is left under it."""
    path = Path(path)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format=path.suffix.lstrip(".") or "png", **kw)


def write_text(path, text: str) -> None:
    """Write ``text`` atomically, UTF-8 whatever the locale (LC_ALL=C with PYTHONUTF8=0 wrote ASCII only)."""
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")


def write_bytes(path, data) -> None:
    """Write ``data`` (bytes) to ``path`` atomically: a write error (ENOSPC, EACCES, EROFS) is an OSError
    naming ``path``, and no temporary file is left."""
    with atomic_path(path) as tmp:
        with open(tmp, "wb") as fh:
            fh.write(data)


def _plain_text_attrs(ds):
    """``ds`` with every attribute that is a ``str`` subclass (an enum such as
    :class:`tengsim.status.Status`) as a plain ``str``, which the NetCDF engine writes; ``ds`` itself when
    there is none (a shallow copy otherwise)."""
    def odd(attrs):
        return any(isinstance(v, str) and type(v) is not str for v in attrs.values())

    if not hasattr(ds, "variables") or not (odd(ds.attrs) or any(odd(v.attrs) for v in ds.variables.values())):
        return ds  # (an object that only makes NetCDF bytes passes as it is)
    ds = ds.copy(deep=False)
    for attrs in (ds.attrs, *(v.attrs for v in ds.variables.values())):
        for k, v in attrs.items():
            if isinstance(v, str) and type(v) is not str:
                attrs[k] = str(v)
    return ds


def netcdf_bytes(ds, edit=None) -> bytes:
    """``ds`` as NetCDF-4 bytes (h5netcdf engine), made in memory: the HDF5 library never writes to the
    disk, so a full disk cannot fail inside it (where it fails without an OSError, and its objects
    crash the interpreter at exit); the bytes then go through :func:`write_bytes`.  ``edit(h5py.File)``,
    if given, may change the file (attributes) before it is closed."""
    try:  # a local write in this process: no distributed lock, even with a dask Client about
        import dask

        local = dask.config.set(scheduler="synchronous")
    except ImportError:  # pragma: no cover - dask is a dependency
        local = contextlib.nullcontext()
    import warnings

    ds = _plain_text_attrs(ds)
    with local, warnings.catch_warnings():
        # dask < 2023.4 warns that a Client is active: this write is local on purpose
        warnings.filterwarnings("ignore", message="Running on a single-machine scheduler")
        try:
            data = bytes(ds.to_netcdf(engine="h5netcdf"))
        except ValueError:  # xarray < 2023.4 makes bytes with the scipy engine only: a scratch file in the
            # temp folder instead (there a full temp disk is not kept from HDF5: the floors' price)
            with tempfile.TemporaryDirectory(prefix="tengsim-nc-") as scratch:
                tmp = Path(scratch) / "scratch.nc"
                ds.to_netcdf(tmp, engine="h5netcdf")
                data = tmp.read_bytes()
    if edit is None:
        return data
    import h5py

    buf = _stdio.BytesIO(data)
    with h5py.File(buf, "r+") as f:
        edit(f)
    return buf.getvalue()


def jsonable(x):
    """``x`` as plain JSON types, so that it is strict JSON: every float that is not finite (NaN, ±inf;
    Python or numpy) to None, other numpy scalars and arrays to Python numbers, bools and lists, tuples to
    lists, non-str dict keys to ``str``, any other object (a Path, ...) to ``str``."""
    if isinstance(x, float):  # numpy float64 too (a float subclass): a plain float
        return float(x) if math.isfinite(x) else None
    if x is None or isinstance(x, (str, bool, int)):
        return x
    if isinstance(x, dict):
        return {k if isinstance(k, str) else str(k): jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [jsonable(v) for v in x]
    import numpy as np

    if isinstance(x, (np.generic, np.ndarray)):
        return jsonable(x.tolist())
    return str(x)


def dumps(obj, indent: int | None = None) -> str:
    """Strict JSON text of ``obj`` (see :func:`jsonable`); never contains NaN or Infinity."""
    return json.dumps(jsonable(obj), indent=indent, allow_nan=False)


def write_json(path, obj) -> None:
    """Write ``obj`` as strict JSON (NaN and ±inf become null), atomically."""
    write_text(path, dumps(obj, indent=2) + "\n")


PAPER = ('"On the contact behavior of micro-/nano-structured interface used in vertical-contact-mode TENGs", '
         'Nano Energy (2016)')


def cf_conventions(ds, title: str):
    """``ds`` by the CF-1.10 conventions' file rules: the global attributes Conventions, title, source,
    history (no time stamp: the same result gives the same file) and references first, then its own;
    no _FillValue on a coordinate variable (a 1-D variable named as its dimension).  Returns ``ds``."""
    from tengsim._version import __version__

    ds.attrs = {"Conventions": "CF-1.10", "title": title, "source": f"tengsim {__version__}",
                "history": f"written by tengsim {__version__}", "references": PAPER, **ds.attrs}
    for name in ds.dims:
        if name in ds.variables and ds.variables[name].dtype.kind == "f":
            ds.variables[name].encoding["_FillValue"] = None
    return ds


def write_dataset(ds, path) -> None:
    """Write an xarray Dataset to NetCDF (h5netcdf engine) atomically; Ctrl-C waits for the write."""
    with interrupts_held():
        write_bytes(path, netcdf_bytes(ds))


def read_dataset(path):
    """Load a NetCDF file (h5netcdf engine) whole into memory; Ctrl-C waits for the read."""
    import xarray as xr

    with interrupts_held():
        return xr.load_dataset(path, engine="h5netcdf")


def _column_text(a, missing: str | None = None) -> list[str]:
    """One column as strings: floats by ``repr`` (shortest exact round-trip), bools as 0/1, else str.

    With ``missing`` given, None and non-finite floats are written as it ('' for an empty cell)."""
    import numpy as np

    kind = a.dtype.kind
    if kind == "b":
        return np.where(a, "1", "0").tolist()
    if kind == "f":
        a = a.astype(float, copy=False)
        text = list(map(float.__repr__, a.tolist()))
        bad = np.flatnonzero(~np.isfinite(a)) if missing is not None else ()
        if len(bad):
            out = np.array(text, dtype=object)
            out[bad] = missing
            text = out.tolist()
        return text
    if kind in "iuUS":
        return list(map(str, a.tolist()))
    out = []  # object or mixed columns: element by element
    for x in a.tolist():
        if isinstance(x, (bool, np.bool_)):
            out.append(str(int(x)))
        elif isinstance(x, (float, np.floating)):
            out.append(missing if missing is not None and not math.isfinite(x) else repr(float(x)))
        elif x is None and missing is not None:
            out.append(missing)
        else:
            out.append(str(x))
    return out


def csv_text(columns: dict, header: dict | None = None, missing: str | None = None) -> str:
    """Equal-length columns as CSV text: ``header`` first as '# key: json' lines (strict JSON), then the
    column names and one row per index, through :func:`csv.writer` (a field holding a comma, quote or
    newline is quoted, ``\n`` ends a line).  Columns are formatted whole (:func:`_column_text`, with
    ``missing`` for None and non-finite floats when given), so no Python code runs per row."""
    import numpy as np

    from tengsim.errors import TengsimError

    names = list(columns)
    arrays = [np.asarray(columns[k]).ravel() for k in names]
    lengths = {len(a) for a in arrays}
    if len(lengths) > 1:
        raise TengsimError(f"CSV columns of unequal length: "
                           f"{', '.join(f'{k}={len(a)}' for k, a in zip(names, arrays))}")
    buf = _stdio.StringIO()
    buf.writelines([f"# {k}: {dumps(v)}\n" for k, v in (header or {}).items()])
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(names)
    if arrays and len(arrays[0]):
        w.writerows(zip(*[_column_text(a, missing) for a in arrays]))
    return buf.getvalue()


def csv_row(values) -> str:
    """One CSV line (ending in a newline) of ``values``, each formatted as :func:`csv_text` formats a column
    of its kind (floats by ``repr``, booleans 0/1): a row appended to a file as it is computed reads back
    exactly as the same row written whole."""
    import numpy as np

    buf = _stdio.StringIO()
    csv.writer(buf, lineterminator="\n").writerow([_column_text(np.asarray([v]))[0] for v in values])
    return buf.getvalue()


def header_lines(header: dict) -> str:
    """'# key: json' lines (strict JSON) of ``header``, as :func:`csv_text` writes them."""
    return "".join(f"# {k}: {dumps(v)}\n" for k, v in header.items())


def write_csv(path, columns: dict, header: dict | None = None) -> None:
    """Write equal-length columns as CSV (:func:`csv_text`) atomically; ``header`` goes in as
    '# key: json' lines (strict JSON)."""
    write_text(path, csv_text(columns, header))
