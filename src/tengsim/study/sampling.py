"""A study's points: the full grid of its axes, or n quasi-random samples of them (Latin hypercube or
scrambled Sobol', scipy.stats.qmc), or one point of the search space of ``tengsim optimize``; each
point's tables resolved ([base] < [base.shapes.<shape>] < its axis values, expressions evaluated)."""
from __future__ import annotations

import itertools
import math

from tengsim.errors import TengsimError
from tengsim.resources import check_count
from tengsim.study.expressions import evaluate
from tengsim.study.model import Point, Study, with_unit


def _resolve(base: dict, assign: dict, pressures=()) -> dict:
    """A point's tables: [base.contact] < [base.shapes.<shape>] < axis values; then expressions evaluated;
    a physical point refined automatically (resolve = 'auto') also converges A/S at the study's
    [observables] pressures (``resolve_pressures``, unless the table names its own)."""
    tables = {t: dict(v) for t, v in base.items() if t != "shapes"}
    tables.setdefault("var", {})
    for name, v in assign.items():
        t, k = name.split(".", 1)
        tables[t][k] = v
    shapes = base.get("shapes") or {}
    if shapes:
        from tengsim.registry import SHAPES

        try:
            shape = SHAPES.canonical(tables["contact"].get("shape") or "pyramid")
        except (TengsimError, KeyError, ValueError):
            shape = None  # an unknown shape: plan_contact names it
        own = {k: v for k, v in shapes.get(shape, {}).items() if f"contact.{k}" not in assign}
        tables["contact"].update(own)
    tables["contact"] = evaluate(tables["contact"], tables["var"])
    c = tables["contact"]
    if (pressures and str(c.get("resolve", "")).strip().lower() == "auto" and "resolve_pressures" not in c
            and _physical(c)):
        c["resolve_pressures"] = [f"{float(p):.6g}Pa" for p in pressures]
    return tables


def _pressures(study) -> tuple:
    return tuple(study.observables.get("pressures", ()))


def _physical(contact: dict) -> bool:
    """A [contact] table of a physical run (one that :func:`tengsim.run.keys.key_dims` gives units to)."""
    from tengsim.run.keys import key_dims

    try:
        return bool(key_dims(contact))
    except TengsimError:
        return False  # plan_contact names the problem


def expand(study: Study) -> list:
    """The study's points: the full grid of its axes, or n lhs/sobol samples of them."""
    axes = study.axes
    if study.sampling == "grid":
        for a in axes:
            if not a.values and study.objective:
                return []  # an optimisation: tengsim optimize draws the points
            if not a.values:
                raise TengsimError(f"axis {a.name!r} is a range without num (only sampling = 'lhs' or "
                                   "'sobol' may leave num out)")
        check_count(math.prod(len(a) for a in axes), "the study's grid of points ("
                    + " × ".join(f"{len(a)} {a.name}" for a in axes) + ")")
        pts = []
        for idx in itertools.product(*(range(len(a)) for a in axes)):
            assign, labels = {}, {}
            for a, k in zip(axes, idx):
                assign.update(zip(a.members, a.values[k]))
                if len(a.members) > 1:
                    labels[a.name] = a.coord()[k]
            pts.append(Point({**labels, **assign}, _resolve(study.base, assign, _pressures(study)), tuple(idx)))
        return pts
    from scipy.stats import qmc

    d = len(axes)
    if study.sampling == "lhs":
        u = qmc.LatinHypercube(d=d, seed=study.seed).random(study.n)
    else:
        u = qmc.Sobol(d=d, scramble=True, seed=study.seed).random(study.n)
    pts = []
    for i, row in enumerate(u):
        assign, labels = {}, {}
        for a, x in zip(axes, row):
            if a.continuous and len(a.members) == 1:
                lo, hi, scale, unit = a.continuous
                v = lo * (hi / lo) ** x if scale == "log" else lo + (hi - lo) * x
                assign[a.members[0]] = with_unit(v, unit)
            else:
                k = min(int(x * len(a)), len(a) - 1)
                assign.update(zip(a.members, a.values[k]))
                if len(a.members) > 1:
                    labels[a.name] = a.coord()[k]
        pts.append(Point({**labels, **assign}, _resolve(study.base, assign, _pressures(study)), (i,)))
    return pts


def point_at(study: Study, x) -> Point:
    """The point of a study of range axes at ``x``: one value per axis, log10 of the value on a log axis
    (the search space of ``tengsim optimize``); values are written as :func:`expand` writes them."""
    assign = {}
    for a, v in zip(study.axes, x):
        lo, hi, scale, unit = a.continuous
        assign[a.members[0]] = with_unit(10**v if scale == "log" else v, unit)
    return Point(assign, _resolve(study.base, assign, _pressures(study)), ())
