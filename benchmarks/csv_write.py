"""CSV writer speed: tengsim.io.write_csv against the per-cell loop it replaced, measured in one run.

CPU time (``time.process_time``) of 100 000 rows × 6 mixed columns, the two writers alternating
``--repeat`` times; prints best-of and the ratio.  Not a test: the ratio moves with the host (the test
suite checks instead that the writer makes no Python call per row, tests/test_io_ux.py).

    OPENBLAS_NUM_THREADS=1 python benchmarks/csv_write.py --rows 100000 --repeat 5
"""
import argparse
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from test_io_ux import _per_cell_csv, _table  # noqa: E402  (the old writer is kept there as the reference)

from tengsim import io  # noqa: E402


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rows", type=int, default=100_000)
    ap.add_argument("--repeat", type=int, default=5)
    a = ap.parse_args(argv)
    cols = _table(a.rows, seed=1)
    new, old = [], []
    with tempfile.TemporaryDirectory() as d:
        for _ in range(a.repeat):
            t = time.process_time()
            io.write_csv(Path(d) / "t.csv", cols)
            new.append(time.process_time() - t)
            t = time.process_time()
            _per_cell_csv(cols, {})
            old.append(time.process_time() - t)
    print(f"{a.rows} rows x {len(cols)} columns, {a.repeat} alternating runs (CPU s)")
    print(f"  write_csv      best {min(new):.3f}  runs {' '.join(f'{x:.3f}' for x in new)}")
    print(f"  per-cell loop  best {min(old):.3f}  runs {' '.join(f'{x:.3f}' for x in old)}")
    print(f"  ratio (loop / write_csv, best-of): {min(old) / min(new):.2f}x")


if __name__ == "__main__":
    main()
