"""The periodic design question's smooth-sided patterns with one grid more (143², max_pixels 21000) beside the
same points stopped at 99² (max_pixels 10000): docs/design.md, "One grid more".

    tengsim sweep examples/design/question_periodic_resolved_143.toml --out question_periodic_resolved_143 --workers 2
    python docs/data/design/question_143.py question_periodic_resolved_143/study.csv docs/data/design

Copies the study.csv to DIR/question_periodic_resolved_143.csv (if it is not already there) and writes
DIR/question_143.md: per computation the status at 99² and at 143², and what stopped the finer run.
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
    src, out = Path(argv[0]), Path(argv[1])
    dest = out / "question_periodic_resolved_143.csv"
    if src.resolve() != dest.resolve():
        shutil.copyfile(src, dest)
    new = {tuple(r[k] for k in KEY): r for r in rows(dest)}
    old = {tuple(r[k] for k in KEY): r for r in rows(out / "question_periodic_resolved.csv")}
    pairs = Counter((old[k]["run_status"], r["run_status"]) for k, r in new.items())
    L = ["# The periodic design question's smooth-sided patterns: one grid more (`docs/data/design/question_143.py`)", "",
         f"{len(new)} computations (pyramid, cone, hemisphere; 3 pitches × 2 aspects × 3 E*; the hemisphere has no aspect): "
         f"`ok` at 99² (max_pixels 10000) {sum(1 for k in new if old[k]['run_status'] == 'ok')}, "
         f"at 143² (max_pixels 21000) {sum(1 for r in new.values() if r['run_status'] == 'ok')}. "
         f"Compute summed over the runs: {sum(float(r['seconds']) for r in new.values()):.0f} s with 143² "
         f"(the 99² study's same points: {sum(float(old[k]['seconds']) for k in new):.0f} s, on a more loaded machine).", "",
         "| status at 99² → at 143² | computations |", "|---|---|"]
    L += [f"| {a} → {b} | {n} |" for (a, b), n in sorted(pairs.items())]
    L += ["", "| pattern, pitch, aspect, E* | 99²: status, why | 143²: status, why |", "|---|---|---|"]
    for k, r in new.items():
        o = old[k]
        L.append(f"| {' '.join(k)} | {o['run_status']}, {why(o['message'])} | {r['run_status']}, {why(r['message'])} |")
    (out / "question_143.md").write_text("\n".join(L) + "\n")
    print("\n".join(L[:9]))


if __name__ == "__main__":
    main(sys.argv[1:])
