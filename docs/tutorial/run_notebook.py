"""Execute the tutorial notebook(s) with nbclient; exit 1 on any cell error (used by CI).

    python docs/tutorial/run_notebook.py                      # docs/tutorial/*.ipynb
    python docs/tutorial/run_notebook.py NB.ipynb --out DIR   # also keep the executed copies in DIR

The kernel is the ``python3`` of the running interpreter (ipykernel), so install with ``pip install -e
'.[docs]'`` first. It runs in a temporary folder: whatever the notebook writes is thrown away.
"""
from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent


def run(path: Path, out_dir: Path | None, timeout: int) -> bool:
    import nbformat
    from nbclient import NotebookClient
    from nbclient.exceptions import CellExecutionError

    nb = nbformat.read(path, as_version=4)
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="tengsim-nb-") as work:
        client = NotebookClient(nb, timeout=timeout, kernel_name="python3",
                                resources={"metadata": {"path": work}})
        try:
            client.execute()
            ok = True
        except CellExecutionError as exc:
            print(f"{path}: a cell failed\n{exc}", file=sys.stderr)
            ok = False
    print(f"{path.name}: {'ok' if ok else 'FAILED'} in {time.perf_counter() - t0:.1f} s")
    if out_dir is not None:
        out_dir.mkdir(parents=True, exist_ok=True)
        nbformat.write(nb, out_dir / path.name)
    return ok


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("notebooks", nargs="*", type=Path, help="default: docs/tutorial/*.ipynb")
    ap.add_argument("--out", type=Path, help="write the executed notebooks here")
    ap.add_argument("--timeout", type=int, default=600, help="seconds per cell (default 600)")
    args = ap.parse_args(argv)
    os.environ.pop("MPLBACKEND", None)  # let the kernel use its inline backend, so figures are kept
    paths = args.notebooks or sorted(HERE.glob("*.ipynb"))
    if not paths:
        print("no notebooks found", file=sys.stderr)
        return 1
    results = [run(p, args.out, args.timeout) for p in paths]
    return 0 if all(results) else 1


if __name__ == "__main__":
    sys.exit(main())
