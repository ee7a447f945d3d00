"""The periodic design question's smooth-sided patterns with one and two grids more (143², max_pixels 21000;
225², max_pixels 51000) beside the same points stopped at 99² (max_pixels 10000): docs/design.md, "One grid more".

    tengsim sweep examples/design/question_periodic_resolved_143.toml --out question_periodic_resolved_143 --workers 2
    tengsim sweep examples/design/question_periodic_resolved_225.toml --out question_periodic_resolved_225 --workers 2
    python docs/data/design/question_143.py question_periodic_resolved_143/study.csv \
        question_periodic_resolved_225/study.csv docs/data/design

Copies the study.csv files to DIR/question_periodic_resolved_143.csv and _225.csv (unless already there) and
writes DIR/question_143.md: per computation the status at 99², 143² and 225², and what stopped each run.
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
    *srcs, out = argv
    out = Path(out)
    caps = ["143", "225"][:len(srcs)]
    runs = {"99": {tuple(r[k] for k in KEY): r for r in rows(out / "question_periodic_resolved.csv")}}
    for cap, src in zip(caps, srcs):
        dest = out / f"question_periodic_resolved_{cap}.csv"
        if Path(src).resolve() != dest.resolve():
            shutil.copyfile(src, dest)
        runs[cap] = {tuple(r[k] for k in KEY): r for r in rows(dest)}
    keys = list(runs[caps[0]])
    grids = ["99"] + caps
    L = ["# The periodic design question's smooth-sided patterns: more grids (`docs/data/design/question_143.py`)", "",
         f"{len(keys)} computations (pyramid, cone, hemisphere; 3 pitches × 2 aspects × 3 E*; the hemisphere has no "
         "aspect). `ok` with the finest grid allowed: "
         + ", ".join(f"{g}²: {sum(1 for k in keys if runs[g][k]['run_status'] == 'ok')}" for g in grids)
         + ". Compute summed over the runs: "
         + ", ".join(f"{g}²: {sum(float(runs[g][k]['seconds']) for k in keys):.0f} s" for g in grids)
         + " (the 99² study ran on a more loaded machine).", ""]
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
    print("\n".join(L[:12]))


if __name__ == "__main__":
    main(sys.argv[1:])
