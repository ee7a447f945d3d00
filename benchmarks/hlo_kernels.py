"""Kernels per iteration of the JAX solver's loop, counted in XLA's compiled HLO (CPU or GPU backend).

The compiled program of :class:`tengsim.solvers.jax_fast.JaxSolver` is one ``while`` over L-BFGS iterations,
with the line search a ``while`` inside it and the re-anchoring / memory write ``conditional``s.  A kernel is
an HLO instruction that runs as its own launch on a GPU: a fusion, an FFT, a dot, a reduce, a copy, a
custom call, ... (not parameter, tuple, get-tuple-element, constant, bitcast).  Per iteration (the plain
branch: no re-anchoring, the step stored, one line-search evaluation), counted recursively:

    kernels = body's own + line-search body (1 trial) + its condition + each conditional's taken branch

and each ``while`` trip and each ``conditional`` needs its predicate on the host on a GPU (XLA copies it back
from the device: a synchronisation each), counted as ``host synchronisations per iteration``.

    python benchmarks/hlo_kernels.py                   # 65² periodic and free cells, float64, JAX's CPU backend
    python benchmarks/hlo_kernels.py --n 129 --dtype float32
"""
from __future__ import annotations

import argparse
import re
import sys

NOT_KERNELS = {"parameter", "get-tuple-element", "tuple", "constant", "bitcast", "after-all", "partition-id",
               "replica-id", "opt-barrier", "add-dependency", "domain"}
_COMP = re.compile(r"^(?:ENTRY )?%?([\w.\-]+) .*\{\s*$")
_INSTR = re.compile(r"^\s*(?:ROOT )?%?[\w.\-]+ = .*?\b([a-z][a-z0-9\-]*)\(")


def computations(text: str) -> dict:
    """{name: [instruction lines]} of an HLO module's text; the entry is also under 'ENTRY'."""
    out, cur, name = {}, None, None
    for line in text.splitlines():
        if cur is None:
            m = _COMP.match(line)
            if m and "=" not in line.split("{")[0].split("(")[0]:
                name, cur = m.group(1), []
                if line.startswith("ENTRY"):
                    out["ENTRY"] = cur
            continue
        if line.strip() == "}":
            out[name], cur = cur, None
            continue
        cur.append(line)
    return out


def opcode(line: str) -> str | None:
    m = _INSTR.match(line)
    if not m:
        return None
    # the opcode is the word before the first '(' after the shape: skip the shape's own words
    rhs = line.split(" = ", 1)[1]
    m2 = re.search(r"\)?\s*([a-z][a-z0-9\-]*)\(", re.sub(r"^\([^=]*?\)\s", "", rhs) if rhs.startswith("(") else rhs)
    return m2.group(1) if m2 else m.group(1)


def _refs(line: str, key: str) -> list:
    m = re.search(key + r"=\{?([^}]*?)\}?(?:,\s*[a-z_]+=|$)", line)
    return [] if not m else [s.strip().lstrip("%") for s in m.group(1).split(",") if s.strip()]


def count(comps: dict, name: str, depth: int = 0) -> dict:
    """{'own', 'whiles', 'total'} kernels of computation ``name`` per execution (module doc)."""
    own, total, whiles, conds = 0, 0, [], 0
    for line in comps.get(name, []):
        op = opcode(line)
        if op is None or op in NOT_KERNELS:
            continue
        if op == "while":
            body, cond = _refs(line, "body")[0], _refs(line, "condition")[0]
            b, c = count(comps, body, depth + 1), count(comps, cond, depth + 1)
            whiles.append(dict(body=body, body_kernels=b["total"], cond_kernels=c["total"],
                               conditionals=b["conditionals"]))
            total += b["total"] + c["total"]  # one trip
            conds += b["conditionals"]
        elif op == "conditional":
            branches = _refs(line, "branch_computations") or (_refs(line, "true_computation")
                                                             + _refs(line, "false_computation"))
            inner = [count(comps, br, depth + 1) for br in branches]
            pick = min(inner, key=lambda c: c["total"]) if inner else dict(total=0, conditionals=0)
            total += pick["total"]  # the plain (cheaper) branch
            conds += 1 + pick["conditionals"]
        else:
            own += 1
            total += 1
    return dict(own=own, total=total, whiles=whiles, conditionals=conds)


def loop_counts(text: str) -> dict:
    """Kernels of the outer loop's iteration (its body once, inner whiles one trip) and of the line search's trial."""
    comps = computations(text)
    entry = count(comps, "ENTRY")
    outer = max(entry["whiles"], key=lambda w: w["body_kernels"])
    body = count(comps, outer["body"])
    inner = body["whiles"][0] if body["whiles"] else dict(body_kernels=0, cond_kernels=0)
    return dict(per_iteration=outer["body_kernels"] + outer["cond_kernels"], outer_own=body["own"],
                line_search_trial=inner["body_kernels"] + inner["cond_kernels"],
                host_syncs=1 + len(body["whiles"]) + outer["conditionals"])


def compiled_text(n: int, boundary: str, dtype: str) -> str:
    import numpy as np

    from tengsim.grid import Grid
    from tengsim.kernels import make_kernel
    from tengsim.laws import LJ93
    from tengsim.solvers import Problem, State
    from tengsim.solvers import jax_fast

    jax_fast.clear_cache()
    g = Grid(n, n, 0.25, 0.25)
    x = np.linspace(-1, 1, n)
    pb = Problem(10 * (x[:, None] ** 2 + x[None, :] ** 2) + 1.0, LJ93(), make_kernel(boundary, g, 0.5 ** 1.5))
    jax_fast.JaxSolver(dtype=dtype, max_iter=5).solve(pb, State.zero((n, n)))
    return list(jax_fast._CACHE.values())[0].as_text()


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=65)
    ap.add_argument("--dtype", default="float64", choices=["float64", "float32"])
    a = ap.parse_args(argv)
    import jax

    print(f"| cell | kernels per iteration (1 line-search trial) | of which the line-search trial | host "
          f"synchronisations per iteration (while trips + conditionals) | backend {jax.default_backend()}, "
          f"JAX {jax.__version__}, {a.n}², {a.dtype} |")
    print("|---|---|---|---|---|")
    for boundary in ("periodic", "free"):
        c = loop_counts(compiled_text(a.n, boundary, a.dtype))
        print(f"| {boundary} | {c['per_iteration']} | {c['line_search_trial']} | {c['host_syncs']} | |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
