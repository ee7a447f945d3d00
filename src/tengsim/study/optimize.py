"""``tengsim optimize``: differential evolution over a study's range axes, evaluations on Dask, resumable.

The study's ``[objective]`` names one observable to maximise or minimise (tengsim.study.observe.SCALARS)
and optional bounds on others (``subject_to = { P_sat_Pa = { min = 1e5 } }``, a penalty when violated).
scipy.optimize.differential_evolution calls its ``workers`` map once per generation; the map computes
the generation's new points on the Dask client (stored exactly like sweep points, DIR/points/<id>.nc),
then evaluates the objective from the stored results.  With a fixed ``seed`` a resumed run asks for the
same points and finds them on disk.
"""
from __future__ import annotations

import json
import math
import sys
import time
from pathlib import Path

import numpy as np

from tengsim.errors import TengsimError
from tengsim.study.observe import SCALARS

PENALTY = 1e6


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
        raise TengsimError(f"[objective] subject_to must be a table, got {cons!r}")
    for k, b in cons.items():
        if k not in SCALARS:
            raise TengsimError(f"[objective] subject_to: {k!r} is not an observable")
        if not isinstance(b, dict) or not set(b) <= {"min", "max"} or not b:
            raise TengsimError(f"[objective] subject_to.{k} must be {{min = .., max = ..}}, got {b!r}")
    opts = {"maxiter": 10, "popsize": 6, "seed": 0, "tol": 0.01}
    for k in list(o):
        if k not in opts:
            raise TengsimError(f"[objective] unknown key {k!r} (known: maximize, minimize, subject_to, "
                               f"{', '.join(opts)})")
        opts[k] = o.pop(k)
    for k in ("maxiter", "popsize", "seed"):
        if not isinstance(opts[k], int) or isinstance(opts[k], bool) or opts[k] < (0 if k == "seed" else 1):
            raise TengsimError(f"[objective] {k} must be a positive integer, got {opts[k]!r}")
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
    from tengsim.study.spec import point_at

    return point_at(study, x)


def optimize_study(study, out, *, workers=None, scheduler=None, client=None, resume=False, quiet=False,
                   stream=None) -> dict:
    """Run the optimisation; returns {'x': axis values, 'value': objective, 'evaluations': n, ...}."""
    from scipy.optimize import differential_evolution

    from tengsim.config import plan_contact
    from tengsim.io import write_json
    from tengsim.load import load_result
    from tengsim.study.dataset import build_study
    from tengsim.study.execute import PointRunner
    from tengsim.study.layout import StudyDir
    from tengsim.study.observe import observe

    from tengsim.plugins import load_plugins

    load_plugins()
    stream = stream or sys.stderr
    obj = parse_objective(study)
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
    history = []
    with PointRunner(sd, workers=workers, scheduler=scheduler, client=client) as runner:
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
            nc = sd.nc(p.id)
            if not nc.exists():
                return PENALTY
            _, res = load_result(nc)
            s = observe(res, p.tables["device"], study.observables)["scalars"]
            v = s[obj["name"]]
            pen = 0.0
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
                return PENALTY + pen
            return obj["sign"] * v + pen

        def mapper(func, xs):
            xs = [np.asarray(x, float) for x in xs]
            pts = [_point(study, x) for x in xs]
            valid, todo = {}, []
            for p in pts:
                evaluated.setdefault(json.dumps(p.axes, sort_keys=True), p)
                if p.id in valid or sd.nc(p.id).exists() or sd.failed(p.id).exists():
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
    best = _point(study, r.x)
    result = {"objective": obj["name"], "goal": obj["goal"], "x": best.axes, "id": best.id,
              "value": float(obj["sign"] * r.fun) if r.fun < PENALTY / 2 else math.nan,
              "feasible": bool(r.fun < PENALTY / 2), "evaluations": len(evaluated),
              "generations": len(history), "seconds": seconds, "message": str(r.message)}
    write_json(sd.optimum, result)
    say(f"optimize: best {obj['name']} = {result['value']:.5g} at "
        + ", ".join(f"{k} = {v}" for k, v in best.axes.items()) + f"; wrote {sd.optimum}")
    return result
