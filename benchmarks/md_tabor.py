"""Maugis–Dugdale sphere over the Tabor range: 2-D engine against Maugis' theory (docs/validation.md,
section "Interaction laws").  One case per call:

    python benchmarks/md_tabor.py MU DX CELL [K] [--down-only | --up-only] [--d-start D] [--tol6] [--smoothing S]

(μ = 3 as in docs/validation.md: ``3 0.035 6 1000 --down-only --d-start -1.2 --tol6 --smoothing 0.6``)

prints pull-off P̄* = −∬P/π and radius a* (vertex of F(a), tengsim.analysis.quadratic_vertex, on the
sub-pixel edge radius tengsim.analysis.edge_radius), the fine rows' best P̄, the zero-load radius,
their deviations from Maugis (tengsim.references.axisym.maugis_sphere) and the wall time.  The walks are
tests/test_laws.py's md_branch / md_measure.
"""
import argparse
import json
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from tengsim.references.axisym import maugis_sphere  # noqa: E402
from test_laws import md_measure  # noqa: E402


def main(argv=None):
    ap = argparse.ArgumentParser(description="Maugis-Dugdale sphere: 2-D engine against Maugis' theory, one case.")
    ap.add_argument("mu", type=float, help="Tabor parameter")
    ap.add_argument("dx", type=float, help="grid spacing")
    ap.add_argument("cell", type=float, help="side of the free cell")
    ap.add_argument("k", type=float, nargs="?", default=1e4, help="wall stiffness (default 1e4)")
    walk = ap.add_mutually_exclusive_group()
    walk.add_argument("--down-only", action="store_true", help="pull-off walk only (no zero-load radius)")
    walk.add_argument("--up-only", action="store_true", help="zero-load walk only (no pull-off)")
    ap.add_argument("--d-start", type=float, default=0.0, help="start apart at this D (< 0) and walk to contact")
    ap.add_argument("--tol6", action="store_true", help="tolerance 1e-6 (default 1e-7)")
    ap.add_argument("--smoothing", type=float, default=0.2, help="MD law smoothing (default 0.2)")
    a = ap.parse_args(argv)
    for name in ("mu", "dx", "cell", "k", "smoothing"):
        if not getattr(a, name) > 0:
            ap.error(f"{name} must be > 0, got {getattr(a, name)}")
    m = maugis_sphere(a.mu)
    t = time.time()
    tol = 1e-6 if a.tol6 else 1e-7
    r = md_measure(a.mu, a.dx, a.cell, a.k, down=not a.up_only, up=not a.down_only, d_start=a.d_start, tol=tol,
                   smoothing=a.smoothing)
    rows = r.pop("rows", None)
    r = {key: float(v) for key, v in r.items()}
    dev = {key + "_%": round(100 * (r[key] / getattr(m, key) - 1), 3)
           for key in ("pull_off", "a_pull_off", "a_zero_load") if key in r}
    print(json.dumps(dict(mu=a.mu, dx=a.dx, cell=a.cell, k=a.k, tol=tol, smoothing=a.smoothing,
                          seconds=round(time.time() - t, 1), **dev, **r)))
    if rows is not None:
        print("# descending rows: D, -∬P/π, edge radius, sqrt(area/π)")
        for row in rows:
            print(" ".join(f"{v:.6g}" for v in row))


if __name__ == "__main__":
    main()
