"""A study directory's state (the layout: :mod:`tengsim.study.layout`): one study per directory, a
resumed study only adds points computed by the same code from the same input, every stored point file
checked before it is trusted, and the run's log."""
from __future__ import annotations

import json
import os
import time

from tengsim.errors import TengsimError
from tengsim.study.layout import StudyDir


def check_resume(study, sd: StudyDir, resume: bool) -> None:
    """Refuse to mix two studies in one directory; on --resume the new study may only add points, and
    its points must be computed by the same code from the same input as the stored ones (the same ids:
    :mod:`tengsim.study.points`)."""
    if not sd.spec.exists():
        if sd.points.is_dir() and any(sd.points.iterdir()):
            raise TengsimError(f"{sd.root} holds points but no study.json; use another --out")
        return
    if not resume:
        raise TengsimError(f"{sd.root} already holds a study; add --resume to continue it, or use another --out")
    try:
        old = json.loads(sd.spec.read_text(encoding="utf-8"))
        old_ids = {p["id"] for p in old["points"]}
        old_axes = {json.dumps(p["axes"], sort_keys=True) for p in old["points"]}
    except (OSError, ValueError, KeyError, TypeError) as exc:
        raise TengsimError(f"cannot read {sd.spec}: {exc}") from None
    new_ids = {p.id for p in study.points}
    new_axes = {json.dumps(p.axes, sort_keys=True) for p in study.points}
    lost = old_ids - new_ids
    if lost and old_axes <= new_axes:
        # the same axis values give other ids: the table changed (the base), or what else the id covers
        _check_same_code(old["points"], lost, study, sd)
    if lost or not old_axes <= new_axes:
        n = len(lost) or len(old_axes - new_axes)
        raise TengsimError(f"the study file changed: {n} point(s) of {sd.spec} are not in it any more "
                           "(a resumed study may only add points); use another --out")


def _check_same_code(old_points, lost, study, sd) -> None:
    """Stored points whose table is unchanged but whose id is not: computed by other code or from other
    input.  One TengsimError saying what changed (a resumed study never mixes their results)."""
    from tengsim.study.points import provenance, provenance_difference
    from tengsim.study.hashing import canonical

    new = {json.dumps(p.axes, sort_keys=True): p for p in study.points}
    n, why = 0, ""
    for o in old_points:
        if o["id"] not in lost:
            continue
        p = new.get(json.dumps(o["axes"], sort_keys=True))
        if p is None or canonical(o["tables"]["contact"]) != canonical(p.contact):
            return  # the table itself changed: the study file changed
        n += 1
        if not why:
            why = (provenance_difference(o["provenance"], provenance(p.contact)) if o.get("provenance")
                   else "written by an older tengsim, before point ids covered the code and input files")
    raise TengsimError(f"{n} point(s) in {sd.points} were computed by other code or from other input "
                       f"({why or 'their ids differ'}); a resumed study never mixes their results with new "
                       "ones: use another --out")


def resolved_with_provenance(study) -> dict:
    """:meth:`Study.resolved` with each point's provenance (what its id covers besides its table), so
    that a refused resume can say what changed."""
    from tengsim.study.points import provenance

    spec = study.resolved()
    for p in spec["points"]:
        p["provenance"] = provenance(p["tables"]["contact"])
    return spec


def verify_points(sd: StudyDir, ids, say=None, who: str = "sweep") -> dict:
    """Open and check every point file of ``ids`` under ``sd`` (:func:`tengsim.study.points.check_point`).
    Returns {id: run status} of the sound ones.  A bad one (unreadable, empty, another point's, not
    matching its content digest) is reported through ``say``, logged, and moved aside to
    ``points/<id>.nc.bad`` (kept for inspection), so that it is computed again."""
    from tengsim.study.points import check_point

    out = {}
    for pid in sorted(sd.done() & set(ids)):
        status, why = check_point(sd.nc(pid), pid)
        if status is not None:
            out[pid] = status
            continue
        bad = sd.points / f"{pid}.nc.bad"
        os.replace(sd.nc(pid), bad)
        if say is not None:
            say(f"{who}: point file {sd.nc(pid)} {why}: moved to {bad.name}, computing the point again")
        append_log(sd, {"event": "bad_point_file", "id": pid, "problem": why, "moved_to": bad.name,
                         "time": time.time()})
    return out


def append_log(sd, entry):
    with open(sd.log, "a", encoding="utf-8") as fh:
        fh.write(json.dumps(entry, default=str) + "\n")
        fh.flush()
