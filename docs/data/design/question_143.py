"""The periodic design question's smooth-sided patterns (pyramid, cone, hemisphere) on finer grids, beside the
same points stopped at 99² (question_periodic_resolved.csv, max_pixels 10000): docs/design.md, "More grids".

    python docs/data/design/question_143.py 143:A.csv 225:B.csv 245:C.csv docs/data/design

Each LABEL:CSV is a study.csv of those points with a larger max_pixels, labelled by its finest grid; a CSV
outside DIR is copied to DIR/question_periodic_resolved_<LABEL>.csv.  Writes DIR/question_143.md: the `ok`
counts, the status changes from one run to the next, and per computation each run's status and what stopped it.
The files of this repository: 143 and 225 (plain √2 refinement, commit 0334210's study files with max_pixels
21000 and 51000), 245 (edges kept in place, examples/design/question_periodic_resolved_245.toml).
"""
import csv
import re
import shutil
import sys
from collections import Counter
from pathlib import Path

KEY = ("contact.shape", "contact.pitch", "var.aspect", "contact.E_star")


def rows(path):
    seen, out = set(), []
    for r in csv.DictReader(open(path)):
        if r["id"] not in seen:  # one computation per id (points that share a table)
            seen.add(r["id"])
            out.append(r)
    return out


def why(msg):
    if msg.startswith("resolve auto: converged"):
        return re.search(r"\((\d+) grids\)", msg).group(1) + " grids"
    m = re.search(r"; (\w+) changed ([0-9.]+|inf)% between the last two grids", msg)
    if m:
        return f"{m.group(1)} {m.group(2)} %"
    if "process zone" in msg:
        return "grid: process zone"
    return msg[:60]


def main(argv):
    *specs, out = argv
    out = Path(out)
    runs = {"99": {tuple(r[k] for k in KEY): r for r in rows(out / "question_periodic_resolved.csv")}}
    labels = []
    for spec in specs:
        label, src = spec.split(":", 1)
        dest = out / f"question_periodic_resolved_{label}.csv"
        if Path(src).resolve() != dest.resolve():
            shutil.copyfile(src, dest)
        runs[label] = {tuple(r[k] for k in KEY): r for r in rows(dest)}
        labels.append(label)
    keys = list(runs[labels[0]])
    grids = ["99"] + labels
    L = ["# The periodic design question's smooth-sided patterns on finer grids (`docs/data/design/question_143.py`)",
         "",
         f"{len(keys)} computations (pyramid, cone, hemisphere; 3 pitches × 2 aspects × 3 E*; the hemisphere has no "
         "aspect); each run labelled by its finest grid (143², 225²: plain √2 refinement; 245²: the base edges kept "
         "in place, grids 45², 65², 105², 165², 245²). `ok`: "
         + ", ".join(f"{g}²: {sum(1 for k in keys if runs[g][k]['run_status'] == 'ok')}" for g in grids)
         + ". Compute summed over the runs: "
         + ", ".join(f"{g}²: {sum(float(runs[g][k]['seconds']) for k in keys):.0f} s" for g in grids)
         + " (shared 2-core VM; the 99² study's machine was more loaded).", ""]
    for a, b in zip(grids[:-1], grids[1:]):
        pairs = Counter((runs[a][k]["run_status"], runs[b][k]["run_status"]) for k in keys)
        L += [f"| status up to {a}² → up to {b}² | computations |", "|---|---|"]
        L += [f"| {x} → {y} | {n} |" for (x, y), n in sorted(pairs.items())] + [""]
    L += ["| pattern, pitch, aspect, E* | " + " | ".join(f"up to {g}²: status, why" for g in grids) + " |",
          "|---|" + "---|" * len(grids)]
    for k in keys:
        L.append(f"| {' '.join(k)} | " + " | ".join(f"{runs[g][k]['run_status']}, {why(runs[g][k]['message'])}"
                                                 for g in grids) + " |")
    (out / "question_143.md").write_text("\n".join(L) + "\n")
    print("\n".join(L[:16]))


if __name__ == "__main__":
    main(sys.argv[1:])
