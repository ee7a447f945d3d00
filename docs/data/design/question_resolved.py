"""Summary of the design question on converged grids (docs/design.md, "The design question on converged grids").

    tengsim sweep examples/design/question_resolved.toml --out question_resolved --workers 2
    tengsim sweep examples/design/question_periodic_resolved.toml --out question_periodic_resolved --workers 2
    python docs/data/design/question_resolved.py question_resolved question_periodic_resolved docs/data/design

Copies each study.csv to DIR/<name>.csv and writes DIR/question_resolved_exceptions.md (every computation that is
not ``ok``: its finest grid, the grid criterion that fires, the observable that moved most on the last grid) and
DIR/question_resolved_summary.md (the status counts by reason, the S ranking beside the coarse study's).
"""
import csv
import re
import shutil
import sys
from collections import Counter
from pathlib import Path

KEY = ("contact.shape", "contact.pitch", "var.aspect", "contact.E_star")
COARSE = {"question_resolved": "question.csv", "question_periodic_resolved": "question_periodic.csv"}


def rows(path):
    seen, out = set(), []
    for r in csv.DictReader(open(path)):
        if r["id"] in seen:  # one computation per id (points that share a table)
            continue
        seen.add(r["id"])
        out.append(r)
    return out


def label(r):
    return f"{r['contact.shape']} {r['contact.pitch']}, {r['var.aspect']}, {r['contact.E_star']}"


def finest(msg):
    m = re.search(r"at dx = ([0-9.e-]+) \((\d+)×(\d+);", msg)
    return (m.group(1), f"{m.group(2)}²") if m else ("–", "–")


def moved(msg):
    m = re.search(r"; (\w+) changed ([0-9.]+|inf)% between the last two grids", msg)
    if m:
        return m.group(1), float(m.group(2))
    m = re.search(r"; (\w+) exists on one of the last two grids only", msg)
    return (m.group(1), float("inf")) if m else (None, None)


def grid_reasons(msg):
    out = []
    if "process zone" in msg:
        out.append("process zone")
    if "pixel" in msg and "snap" in msg or "pixels snap" in msg:
        out.append("pixel snap")
    if "flat face bounded by walls" in msg:
        out.append("face")
    return out


def reason(r):
    """('ok' | 'out_of_law_range' | 'grid' | 'A/S' | 'other observable', detail)."""
    st, msg = r["status"], r["message"]
    if st == "ok":
        return "ok", ""
    if st != "under_resolved":
        return st, msg.split(";")[0][:80]
    g = grid_reasons(msg)
    obs, ch = moved(msg)
    if g:
        return "grid", ", ".join(g) + (f"; {obs} {ch:.2f}%" if obs else "")
    if obs and obs.startswith("A_S_at"):
        return "A/S", f"{obs} {ch:.2f}%"
    if obs:
        return "other observable", f"{obs} {ch:.2f}%"
    return "other", msg[:80]


def number(x):
    try:
        return float(x)
    except (TypeError, ValueError):
        return float("nan")


def ranking(res, coarse, n=10):
    """Top n by S (V/kPa) among points not in adhesive full contact at zero load, with the coarse S and rank."""
    def top(rs):
        ok = [r for r in rs if number(r["adhesive_full_contact"]) != 1.0 and number(r["S_V_per_kPa"]) == number(r["S_V_per_kPa"])]
        return sorted(ok, key=lambda r: -number(r["S_V_per_kPa"]))
    cr = top(coarse)
    crank = {tuple(r[c] for c in KEY): (i + 1, number(r["S_V_per_kPa"])) for i, r in enumerate(cr)}
    lines = ["| rank | pattern, pitch, aspect, E* | S (V/kPa) | coarse S (rank) | linear range (kPa) | status |",
             "|---|---|---|---|---|---|"]
    for i, r in enumerate(top(res)[:n]):
        k = tuple(r[c] for c in KEY)
        cs = crank.get(k)
        lines.append(f"| {i + 1} | {label(r)} | {number(r['S_V_per_kPa']):.3g} | "
                     + (f"{cs[1]:.3g} ({cs[0]})" if cs else "–")
                     + f" | {number(r['linear_range_Pa']) / 1e3:.3g} | {r['status']} ({reason(r)[0]}) |")
    return lines


def main(argv):
    *names, out = argv
    out = Path(out)
    exc = ["# Exceptions of the converged design question (docs/design.md, \"The design question on converged grids\")",
           "",
           "Every computation of the resolved design studies that did not finish `ok` under `resolve = \"auto\"`",
           "(resolve_tol 0.01, max_pixels 10000: grids 45², 65², 99²; observables pull-off F, jump-in/out D, transition D",
           "and A/S at 1, 10 and 100 kPa), with the finest grid, the grid criterion that still fires and the observable",
           "that moved most between the last two grids.  Written by `docs/data/design/question_resolved.py`; full",
           "messages in the `message` column of the study.csv copies next to this file.", ""]
    summ = ["# The design question on converged grids: summary (`docs/data/design/question_resolved.py`)", ""]
    for name in names:
        src = Path(name) / "study.csv"
        shutil.copy(src, out / f"{Path(name).name}.csv")
        rs = rows(src)
        counts = Counter(reason(r)[0] for r in rs)
        obs = Counter(moved(r["message"])[0] for r in rs if reason(r)[0] in ("A/S", "other observable"))
        summ += [f"## {Path(name).name} ({len(rs)} computations)", "",
                 "| ok | under_resolved: grid criterion | under_resolved: A/S moved > 1 % | under_resolved: other "
                 "observable moved > 1 % | out_of_law_range | other |", "|---|---|---|---|---|---|",
                 f"| {counts['ok']} | {counts['grid']} | {counts['A/S']} | {counts['other observable']} | "
                 f"{counts['out_of_law_range']} | {counts['other'] + counts['not_converged'] + counts['failed']} |", "",
                 "Observable that stopped the refinement (under_resolved by an observable only): "
                 + ", ".join(f"{k} {v}" for k, v in obs.most_common()), ""]
        coarse = out / COARSE.get(Path(name).name, "")
        if coarse.is_file():
            summ += ["Top ten by S beside the coarse study:", "", *ranking(rs, rows(coarse)), ""]
        exc += [f"## {Path(name).name}", "", "| pattern, pitch, aspect, E* | status | finest dx (grid) | why |",
                "|---|---|---|---|"]
        for r in sorted(rs, key=label):
            kind, detail = reason(r)
            if kind == "ok":
                continue
            dx, grid = finest(r["message"])
            exc.append(f"| {label(r)} | {r['status']} | {dx} ({grid}) | {kind}: {detail} |")
        exc.append("")
    (out / "question_resolved_exceptions.md").write_text("\n".join(exc) + "\n")
    (out / "question_resolved_summary.md").write_text("\n".join(summ) + "\n")
    print("\n".join(summ))


if __name__ == "__main__":
    main(sys.argv[1:])
