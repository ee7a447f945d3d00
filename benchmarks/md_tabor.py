"""Maugis–Dugdale sphere over the Tabor range: 2-D engine against Maugis' theory (docs/validation.md,
section "Interaction laws").  One case per call:

    python benchmarks/md_tabor.py MU DX CELL [K] [--down-only] [--d-start D] [--tol6] [--smoothing S]

(μ = 3 as in docs/validation.md: ``3 0.035 6 1000 --down-only --d-start -1.2 --tol6 --smoothing 0.6``)

prints pull-off P̄* = −∬P/π and radius a* (vertex of F(a), tengsim.analysis.quadratic_vertex, on the
sub-pixel edge radius tengsim.analysis.edge_radius), the fine rows' best P̄, the zero-load radius,
their deviations from Maugis (tengsim.axisym.maugis_sphere) and the wall time.  The walks are
tests/test_laws.py's md_branch / md_measure.
"""
import json
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from tengsim.axisym import maugis_sphere  # noqa: E402
from test_laws import md_measure  # noqa: E402


def main(argv):
    args = [a for a in argv if not a.startswith("--")]
    opt = {}
    for name in ("--d-start", "--smoothing"):
        if name in argv:
            opt[name] = float(argv[argv.index(name) + 1])
            args.remove(argv[argv.index(name) + 1])
    d_start, smoothing = opt.get("--d-start", 0.0), opt.get("--smoothing", 0.2)
    mu, dx, cell = float(args[0]), float(args[1]), float(args[2])
    k = float(args[3]) if len(args) > 3 else 1e4
    m = maugis_sphere(mu)
    t = time.time()
    tol = 1e-6 if "--tol6" in argv else 1e-7
    r = md_measure(mu, dx, cell, k, up="--down-only" not in argv, d_start=d_start, tol=tol, smoothing=smoothing)
    rows = r.pop("rows", None)
    r = {key: float(v) for key, v in r.items()}
    dev = {key + "_%": round(100 * (r[key] / getattr(m, key) - 1), 3)
           for key in ("pull_off", "a_pull_off", "a_zero_load") if key in r}
    print(json.dumps(dict(mu=mu, dx=dx, cell=cell, k=k, tol=tol, smoothing=smoothing, seconds=round(time.time() - t, 1), **dev, **r)))
    if rows is not None:
        print("# descending rows: D, -∬P/π, edge radius, sqrt(area/π)")
        for row in rows:
            print(" ".join(f"{v:.6g}" for v in row))


if __name__ == "__main__":
    main(sys.argv[1:])
