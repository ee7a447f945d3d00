"""Atomic result writing: a file appears whole or not at all."""
from __future__ import annotations

import contextlib
import json
import os
import tempfile
from pathlib import Path


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike):
    """Yield a temporary path beside ``path``; rename it onto ``path`` only on success."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".part", dir=path.parent)
    os.close(fd)
    try:
        yield Path(tmp)
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise


def check_writable(path) -> None:
    """Fail early (before a long run) if ``path`` could not be written: one clear TengsimError."""
    from tengsim.errors import TengsimError

    path = Path(path)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".check", dir=path.parent)
        os.close(fd)
        os.unlink(tmp)
    except OSError as exc:
        raise TengsimError(f"cannot write {path}: {exc.strerror or exc}") from None


def write_text(path, text: str) -> None:
    with atomic_path(path) as tmp:
        tmp.write_text(text)


def write_json(path, obj) -> None:
    write_text(path, json.dumps(obj, indent=2, default=_jsonable) + "\n")


def _jsonable(x):
    try:
        import numpy as np

        if isinstance(x, np.generic):
            return x.item()
        if isinstance(x, np.ndarray):
            return x.tolist()
    except ImportError:  # pragma: no cover
        pass
    return str(x)


def write_dataset(ds, path) -> None:
    """Write an xarray Dataset to NetCDF (h5netcdf engine) atomically."""
    with atomic_path(path) as tmp:
        ds.to_netcdf(tmp, engine="h5netcdf")


def write_csv(path, columns: dict, header: dict | None = None) -> None:
    """Write equal-length columns as CSV; ``header`` goes in as '# key: value' lines."""
    import numpy as np

    names = list(columns)
    arrays = [np.asarray(columns[k]) for k in names]
    lines = []
    for k, v in (header or {}).items():
        lines.append(f"# {k}: {json.dumps(v, default=_jsonable)}")
    lines.append(",".join(names))
    n = len(arrays[0]) if arrays else 0
    for i in range(n):
        row = []
        for a in arrays:
            x = a[i]
            if isinstance(x, (float, np.floating)):
                row.append(repr(float(x)))
            elif isinstance(x, (bool, np.bool_)):
                row.append(str(int(x)))
            else:
                row.append(str(x))
        lines.append(",".join(row))
    write_text(path, "\n".join(lines) + "\n")
