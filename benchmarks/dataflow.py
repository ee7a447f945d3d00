"""Follow one contact run through the layers: which modules it enters, and how often a call climbs back up.

    OPENBLAS_NUM_THREADS=1 python benchmarks/dataflow.py [--physical]

Runs ``tengsim.contact.run_contact`` on a small [contact] table (group-A pyramid, dx 0.2, 3 D steps; with
``--physical`` the same in SI units) under ``sys.setprofile`` and records every call from one tengsim
module into another.  Each module is given its layer from the import-linter contract in pyproject.toml
(the README's layout); a call from a module into a module of a *higher* layer is a climb (a callback: the
caller was handed a function or object of a higher layer).  Prints the module sequence of the run (runs of
one module collapsed), the calls per pair of modules, and the climbs.  No timing: counts only.
"""
from __future__ import annotations

import argparse
import sys
from collections import Counter
from pathlib import Path

try:
    import tomllib
except ImportError:  # Python 3.10
    import tomli as tomllib

ROOT = Path(__file__).resolve().parents[1]


def layer_of():
    """module name → layer index (0 = top), from the project's import-linter layers contract."""
    cfg = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["importlinter"]["contracts"][0]
    table = {}
    for i, layer in enumerate(cfg["layers"]):
        for name in layer.replace("|", " ").replace(":", " ").split():
            table[name] = i

    def find(mod: str) -> int | None:
        parts = mod.split(".")
        for k in range(len(parts), 0, -1):
            if ".".join(parts[:k]) in table:
                return table[".".join(parts[:k])]
        return None
    return find


def trace(cfg: dict):
    from tengsim.contact import run_contact

    calls = []

    def prof(frame, event, arg):
        if event != "call":
            return
        callee = frame.f_globals.get("__name__", "")
        caller = frame.f_back.f_globals.get("__name__", "") if frame.f_back else ""
        if callee.startswith("tengsim") and caller.startswith("tengsim") and callee != caller:
            calls.append((caller, callee, frame.f_code.co_name))

    sys.setprofile(prof)
    try:
        res = run_contact(cfg)
    finally:
        sys.setprofile(None)
    return res, calls


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--physical", action="store_true", help="the same run in SI units (pitch, base, height, E*, W)")
    a = ap.parse_args(argv)
    cfg = {"shape": "pyramid", "dx": 0.2, "d_min": 0.0, "d_max": 1.0, "d_step": 0.5}
    if a.physical:
        cfg.update(pitch="2um", base="1um", height="0.7um", E_star="0.59MPa", W="54mJ/m2", tabor=0.5)
    else:
        cfg.update(N=0.946, cell=3.78, tabor=0.5)
    res, calls = trace(cfg)
    find = layer_of()
    seq = []
    for caller, callee, fn in calls:
        if not seq or seq[-1] != callee:
            seq.append(callee)
    pairs = Counter((c, d) for c, d, _ in calls)
    climbs = Counter()
    for c, d, fn in calls:
        lc, ld = find(c), find(d)
        if lc is not None and ld is not None and ld < lc:
            climbs[(c, d, fn)] += 1
    print(f"run status {res.status}, {len(res.table['D'])} equilibria, {len(calls)} cross-module calls")
    print("\nmodules entered, in order (first 40 changes):")
    print("  " + " → ".join(m.replace("tengsim.", "") for m in seq[:40]))
    print("\ncalls per (caller → callee):")
    for (c, d), n in sorted(pairs.items(), key=lambda kv: -kv[1]):
        print(f"  {n:6d}  {c} → {d}")
    print(f"\nclimbs (a call into a higher layer): {sum(climbs.values())} calls, {len(climbs)} distinct")
    for (c, d, fn), n in climbs.most_common():
        print(f"  {n:6d}  {c} → {d}.{fn}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
