"""``tengsim optimize``: differential evolution over a study's range axes, evaluations on Dask, resumable.

The study's ``[objective]`` names one observable to maximise or minimise (tengsim.study.observe.SCALARS)
and optional bounds on others (``subject_to = { linear_range_Pa = { min = 1e4 } }``, a penalty when violated).
scipy.optimize.differential_evolution calls its ``workers`` map once per generation; the map computes
the generation's new points on the Dask client (stored exactly like sweep points, DIR/points/<id>.nc),
then evaluates the objective from the stored results.  With a fixed ``seed`` a resumed run asks for the
same points and finds them on disk (each point file checked before it is trusted, a bad one computed
again: tengsim.study.resume.verify_points).

Only points whose run status is ``ok`` are candidates (``accept`` adds others: ``--accept
under_resolved``); any other point — another status, a failed point — counts as infeasible (a penalty),
so a grid artefact is never taken for the optimum.  The result (DIR/optimum.json) states the status of
the optimum and of its neighbours, the evaluated points nearest it in the search space.
"""
from __future__ import annotations

import json
import math
import sys
import time
from pathlib import Path

import numpy as np

from tengsim.errors import TengsimError, shown
from tengsim.resources import check_count
from tengsim.units import read_number
from tengsim.study.observe import SCALARS
from tengsim.status.levels import Status

PENALTY = 1e6
FAILED = 1e3 * PENALTY
"""Score of a point without a result (failed): worse than any computed point, whatever its penalties."""
ACCEPTABLE = ("under_resolved", "out_of_law_range", "not_converged")
"""Run statuses besides 'ok' that ``accept`` may take as candidates."""


def parse_accept(accept) -> tuple:
    """The candidate statuses: 'ok' and the ``accept`` ones (names, or one comma-separated string);
    a TengsimError naming a value that is not one of :data:`ACCEPTABLE`."""
    if accept is None:
        accept = ()
    if isinstance(accept, str):
        accept = [accept]
    names = [s.strip() for a in accept for s in str(a).split(",") if s.strip()]
    for s in names:
        if s not in ACCEPTABLE:
            raise TengsimError(f"--accept {s!r} is not a run status a candidate may have "
                               f"(choose from {', '.join(ACCEPTABLE)})")
    return (Status.OK, *dict.fromkeys(names))


def parse_objective(study) -> dict:
    o = dict(study.objective)
    if not o:
        raise TengsimError(f"{study.source or 'study'}: tengsim optimize needs an [objective] table")
    goal = [k for k in ("maximize", "minimize") if k in o]
    if len(goal) != 1:
        raise TengsimError("[objective] needs exactly one of maximize = '<observable>' or minimize = '<observable>'")
    name = o.pop(goal[0])
    if name not in SCALARS:
        raise TengsimError(f"[objective] {goal[0]} = {name!r} is not an observable (choose from {', '.join(SCALARS)})")
    cons = o.pop("subject_to", {}) or {}
    if not isinstance(cons, dict):
        raise TengsimError(f"[objective] subject_to must be a table, got {shown(cons)}")
    for k, b in cons.items():
        if k not in SCALARS:
            raise TengsimError(f"[objective] subject_to: {k!r} is not an observable")
        if not isinstance(b, dict) or not set(b) <= {"min", "max"} or not b:
            raise TengsimError(f"[objective] subject_to.{k} must be {{min = .., max = ..}}, got {shown(b)}")
        for side, v in b.items():  # each bound a number, read before any point is computed
            try:
                if isinstance(v, (bool, dict, list)):
                    raise ValueError
                read_number(v, f"[objective] subject_to.{k}.{side}")
            except TengsimError:
                raise
            except ValueError:
                raise TengsimError(f"[objective] subject_to.{k}.{side} = {shown(v)} is not a number") from None
            if read_number(v) != read_number(v):
                raise TengsimError(f"[objective] subject_to.{k}.{side} = {shown(v)} is not a number")
        if "min" in b and "max" in b and not read_number(b["min"]) <= read_number(b["max"]):
            raise TengsimError(f"[objective] subject_to.{k}: min = {shown(b['min'])} is above max = {shown(b['max'])}")
    cons = {k: {side: read_number(v) for side, v in b.items()} for k, b in cons.items()}
    opts = {"maxiter": 10, "popsize": 6, "seed": 0, "tol": 0.01}
    for k in list(o):
        if k not in opts:
            raise TengsimError(f"[objective] unknown key {k!r} (known: maximize, minimize, subject_to, "
                               f"{', '.join(opts)})")
        opts[k] = o.pop(k)
    for k in ("maxiter", "popsize", "seed"):
        if not isinstance(opts[k], int) or isinstance(opts[k], bool) or opts[k] < (0 if k == "seed" else 1):
            raise TengsimError(f"[objective] {k} must be a positive integer, got {shown(opts[k])}")
    if opts["seed"] >= 2**63:
        raise TengsimError(f"[objective] seed must be below 2**63, got {shown(opts['seed'])}")
    check_count(opts["popsize"] * max(1, len(study.axes)), "[objective] popsize × the number of axes (points "
                "per generation)")
    check_count(opts["popsize"] * max(1, len(study.axes)) * (opts["maxiter"] + 1),
                "[objective] popsize × axes × (maxiter + 1) (points in all)")
    bounds = []
    for a in study.axes:
        if not a.continuous or len(a.members) != 1:
            raise TengsimError(f"tengsim optimize searches range axes only; {a.name!r} is not a range "
                               "{start, stop}")
        lo, hi, scale, unit = a.continuous
        if not hi > lo:
            raise TengsimError(f"axis {a.name!r}: stop must be greater than start for optimisation")
        bounds.append((math.log10(lo), math.log10(hi)) if scale == "log" else (lo, hi))
    if not bounds:
        raise TengsimError("tengsim optimize needs at least one range axis")
    return {"sign": -1.0 if goal[0] == "maximize" else 1.0, "name": name, "goal": goal[0],
            "subject_to": cons, "bounds": bounds, **opts}


def _point(study, x):
    from tengsim.study.sampling import point_at

    return point_at(study, x)


def optimize_study(study, out, *, workers=None, scheduler=None, client=None, resume=False, quiet=False,
                   stream=None, accept=()) -> dict:
    """Run the optimisation; returns {'x': axis values, 'value': objective, 'status': the optimum's run
    status, 'neighbours': [...], 'evaluations': n, 'feasible': ..., ...}.

    ``accept``: run statuses besides 'ok' whose points are candidates (:data:`ACCEPTABLE`).  With no
    candidate satisfying the constraints, 'feasible' is False, 'value' NaN and 'x' the best point of
    any status (the message says so)."""
    from scipy.optimize import differential_evolution

    from tengsim.run.plan import plan_contact
    from tengsim.io import write_json
    from tengsim.results.read import load_result
    from tengsim.study.dataset import build_study
    from tengsim.study.resume import verify_points
    from tengsim.study.runner import PointRunner
    from tengsim.study.layout import StudyDir
    from tengsim.study.observe import observe

    from tengsim.plugins import load_plugins

    load_plugins()
    stream = stream or sys.stderr
    obj = parse_objective(study)
    candidates = parse_accept(accept)
    say = (lambda m: None) if quiet else (lambda m: print(m, file=stream, flush=True))
    sd = StudyDir(Path(out))
    if sd.spec.exists() and not resume:
        raise TengsimError(f"{sd.root} already holds a study; add --resume to continue it, or use another --out")
    # the corners of the box must plan (a bad base is a study error, found before anything runs)
    for corner in (np.array([b[0] for b in obj["bounds"]]), np.array([b[1] for b in obj["bounds"]])):
        try:
            plan_contact(dict(_point(study, corner).contact))
        except TengsimError as exc:
            raise TengsimError(f"{study.source or 'study'}: {exc}") from None
    evaluated: dict = {}
    scored: dict = {}  # id -> (objective + penalty, run status or 'failed', objective value)
    history = []
    with PointRunner(sd, workers=workers, scheduler=scheduler, client=client) as runner, sd.lock("optimize"):
        say(f"optimize: {obj['goal']} {obj['name']} over {', '.join(a.name for a in study.axes)}; "
            f"dashboard {runner.client.dashboard_link}")
        sd.points.mkdir(parents=True, exist_ok=True)
        runner.warm_up()

        def save_spec():
            spec = study.resolved()
            spec["sampling"] = "optimize"
            spec["objective"] = {k: v for k, v in obj.items() if k != "bounds"}
            spec["points"] = [{"id": p.id, "axes": p.axes, "index": [i], "tables": p.tables}
                              for i, p in enumerate(evaluated.values())]
            write_json(sd.spec, spec)

        def value(p):
            if p.id not in scored:
                scored[p.id] = score(p)
            return scored[p.id][0]

        def score(p):
            """(objective + penalties, status, objective value) of a computed point."""
            nc = sd.nc(p.id)
            if not nc.exists():
                return FAILED, "failed", math.nan
            _, res = load_result(nc)
            status = res.status
            s = observe(res, p.tables["device"], study.observables)["scalars"]
            v = s[obj["name"]]
            pen = 0.0 if status in candidates else PENALTY  # not a candidate: infeasible, ranked by v
            for k, b in obj["subject_to"].items():
                x = s[k]
                if not math.isfinite(x):
                    pen += PENALTY
                    continue
                if "min" in b and x < b["min"]:
                    pen += PENALTY * (b["min"] - x) / max(abs(b["min"]), 1e-300)
                if "max" in b and x > b["max"]:
                    pen += PENALTY * (x - b["max"]) / max(abs(b["max"]), 1e-300)
            if not math.isfinite(v):
                return PENALTY + pen, status, v
            return obj["sign"] * v + pen, status, v

        def mapper(func, xs):
            xs = [np.asarray(x, float) for x in xs]
            pts = [_point(study, x) for x in xs]
            valid, todo = {}, []
            fresh = [p.id for p in pts if p.id not in scored]
            sound = verify_points(sd, fresh, say, "optimize")  # a bad file (a resumed run) is computed again
            for p in pts:
                evaluated.setdefault(json.dumps(p.axes, sort_keys=True), p)
                if p.id in valid or p.id in scored or p.id in sound or sd.failed(p.id).exists():
                    continue
                try:
                    plan_contact(dict(p.contact))
                except TengsimError as exc:
                    write_json(sd.failed(p.id), {"id": p.id, "status": "failed", "stage": "validation",
                                                 "message": str(exc), "contact": p.contact})
                    continue
                valid[p.id] = p.contact
                todo.append(p.id)
            save_spec()
            runner.compute(valid, todo)
            vals = [value(p) for p in pts]
            history.append(min(vals))
            say(f"optimize: generation {len(history)}: {len(todo)} new point(s), {len(evaluated)} evaluated, "
                f"best of this generation {obj['name']} = {obj['sign'] * min(vals):.5g}" if min(vals) < PENALTY / 2 else
                f"optimize: generation {len(history)}: {len(todo)} new point(s), no feasible point yet")
            return vals

        t0 = time.perf_counter()
        r = differential_evolution(lambda x: 0.0, obj["bounds"], workers=mapper, updating="deferred",
                                   maxiter=obj["maxiter"], popsize=obj["popsize"], seed=obj["seed"],
                                   tol=obj["tol"], polish=False, init="sobol")
        seconds = time.perf_counter() - t0
    import dask

    with dask.config.set(scheduler="synchronous"):
        build_study(sd.root)
    pts = list(evaluated.values()) or [_point(study, r.x)]
    best, result = pick_optimum(study, obj, pts, scored, candidates)
    result.update(evaluations=len(evaluated), generations=len(history), seconds=seconds,
                  message=result["message"] or str(r.message))
    status, feasible = result["status"], result["feasible"]
    write_json(sd.optimum, result)
    near = result["neighbours"]
    near_text = ", ".join(f"{n} {s}" for s, n in sorted(_count(q["status"] for q in near).items()))
    where = ", ".join(f"{k} = {v}" for k, v in best.axes.items())
    if feasible:
        say(f"optimize: best {obj['name']} = {result['value']:.5g} at {where} (status {status}); "
            f"its {len(near)} nearest evaluated point(s): {near_text or 'none'}; wrote {sd.optimum}")
        if any(q["status"] != Status.OK for q in near) or status != Status.OK:
            say("optimize: the optimum is or borders on points whose status is not ok: check them (refine dx "
                "for under_resolved) before trusting it")
    else:
        say(f"optimize: {result['message']}; wrote {sd.optimum}")
    return result


def pick_optimum(study, obj, pts, scored, candidates) -> tuple:
    """(best point, result fields) over the evaluated points ``pts``, ``scored`` mapping each id to
    (objective + penalties, status, objective value): the best point whose status is one of
    ``candidates`` and within the constraints; when none is, the best of any (``feasible`` False, value
    NaN, a message naming the statuses found and the --accept that would take them)."""
    best = min(pts, key=lambda p: scored.get(p.id, (FAILED, "failed", math.nan))[0])
    fun, status, v = scored.get(best.id, (FAILED, "failed", math.nan))
    feasible = bool(fun < PENALTY / 2)
    counts = _count(scored.get(p.id, (0, "failed"))[1] for p in pts)
    result = {"objective": obj["name"], "goal": obj["goal"], "x": best.axes, "id": best.id,
              "value": float(v) if feasible else math.nan, "status": status, "feasible": feasible,
              "accepted_statuses": list(candidates), "statuses": counts,
              "neighbours": neighbours(study, obj, best, pts, scored), "message": ""}
    if not feasible:
        tally = ", ".join(f"{n} {s}" for s, n in sorted(counts.items()))
        could = [s for s in counts if s in ACCEPTABLE and s not in candidates]
        result["message"] = (f"no evaluated point is a candidate (status {' or '.join(candidates)}"
                             + (" and within subject_to" if obj["subject_to"] else "") + f"; evaluated: {tally})"
                             + (f"; --accept {could[0]} would take the {could[0]} points as candidates"
                                if could else ""))
    return best, result


def _count(items) -> dict:
    out = {}
    for s in items:
        out[s] = out.get(s, 0) + 1
    return out


def neighbours(study, obj, best, pts, scored, k=None) -> list:
    """The evaluated points nearest ``best`` in the search space (each axis scaled to [0, 1] over its
    bounds, log axes in log10): 2 × (number of axes) of them, each {'x', 'id', 'status', 'value',
    'distance'}, nearest first."""
    import re

    lo = np.array([b[0] for b in obj["bounds"]])
    span = np.array([b[1] - b[0] for b in obj["bounds"]])
    number = re.compile(r"\s*[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")

    def pos(p):
        xs = []
        for a in study.axes:  # the value in the axis' own unit, as its bounds are ('1.5MPa' -> 1.5)
            v = p.axes[a.members[0]]
            x = float(v) if not isinstance(v, str) else float(number.match(v).group())
            xs.append(math.log10(x) if a.continuous[2] == "log" and x > 0 else x)
        return (np.array(xs) - lo) / span

    k = k if k is not None else 2 * len(study.axes)
    x0 = pos(best)
    near = sorted(((float(np.linalg.norm(pos(p) - x0)), p) for p in pts if p.id != best.id),
                  key=lambda t: t[0])[:k]
    none = (math.nan, "failed", math.nan)
    return [{"x": p.axes, "id": p.id, "status": scored.get(p.id, none)[1],
             "value": float(scored.get(p.id, none)[2]), "distance": d} for d, p in near]
