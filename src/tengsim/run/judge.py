"""What automatic refinement (:mod:`tengsim.run.resolve`) judges and how: the observables of a grid, their change
between grids, the Richardson error estimate of the finest grid, and the line saying why a refinement stopped
short (the criteria and the formulas: :mod:`tengsim.run.resolve`'s module doc)."""
from __future__ import annotations

import math
from dataclasses import dataclass, field

from tengsim.results.result import TRANSITION_LENGTH_FRACTION

P_MIN, P_MAX = 0.5, 4.0
"""Range the observed order is clipped to."""
FLOORS = {"D": 1.0, "F": 0.01, "fraction": 0.01, "V": 0.01}
"""Absolute floor of the relative change of an observable by kind (D in ε, F of Eq. 10, A/S, V_OC in V):
|Δf| <= tol · max(|f|, floor)."""


@dataclass(frozen=True)
class GridRecord:
    """One finished grid of a refinement: its spacing ``dx`` (X units) and pixels, the wall ``seconds`` of its
    walk, the ``convolutions`` it spent, its ``status``, its observables ``obs`` {name: value} and the names among
    them recorded but not judged (``watched``).  Kept in a checkpoint as :meth:`as_dict` (:meth:`of` reads it
    back)."""

    dx: float
    nx: int
    ny: int
    seconds: float
    convolutions: int
    status: str
    obs: dict = field(default_factory=dict)
    watched: tuple = ()

    def as_dict(self) -> dict:
        """The record as the checkpoint file keeps it."""
        return {"dx": self.dx, "nx": self.nx, "ny": self.ny, "seconds": self.seconds,
                "convolutions": self.convolutions, "status": self.status, "obs": dict(self.obs),
                "watched": list(self.watched)}

    @classmethod
    def of(cls, rec) -> "GridRecord":
        """``rec`` as a record (a :class:`GridRecord`, or the dict a checkpoint file kept)."""
        if isinstance(rec, GridRecord):
            return rec
        return cls(rec["dx"], rec["nx"], rec["ny"], rec["seconds"], rec["convolutions"], rec["status"],
                   dict(rec["obs"]), tuple(rec.get("watched", ())))


def _kind(name: str) -> str:
    if name.endswith("_D") or name.startswith("D_"):
        return "D"
    if name.startswith("area_fraction") or name.startswith("A_"):
        return "fraction"
    if name.startswith("V_OC"):
        return "V"
    return "F"


def floor_of(name: str) -> float:
    return FLOORS[_kind(name)]


def contact_observables(res, full_length: float | None = None,
                        fraction: float = TRANSITION_LENGTH_FRACTION) -> dict:
    """{name: value} judged by the refinement: pull_off_F, jump_in_D, jump_out_D, and transition_D when the
    shape's full-contact length ``full_length`` is given (NaN where a run has none)."""
    out = {"pull_off_F": res.pull_off_force}
    jumps = res.jumps
    out["jump_in_D"] = next((j.D_after for j in jumps if j.kind == "jump-in"), math.nan)
    out["jump_out_D"] = next((j.D_after for j in jumps if j.kind == "jump-out"), math.nan)
    if full_length is not None and math.isfinite(full_length):
        out["transition_D"] = res.transition_D(full_length, fraction)
    return out


def _order(h, f) -> tuple[float, bool]:
    """(observed order clipped to [P_MIN, P_MAX], True) from three grids, or (1, False) where it cannot be had."""
    from scipy.optimize import brentq

    (h1, h2, h3), (f1, f2, f3) = h, f
    d12, d23 = f1 - f2, f2 - f3
    if d23 == 0 or d12 == 0 or (d12 > 0) != (d23 > 0):
        return 1.0, False

    def g(p):
        return (h1**p - h2**p) / (h2**p - h3**p) - d12 / d23

    lo, hi = g(P_MIN), g(P_MAX)
    if lo >= 0:
        return P_MIN, True
    if hi <= 0:
        return P_MAX, True
    return float(brentq(g, P_MIN, P_MAX, xtol=1e-10)), True


def richardson(h, f) -> dict:
    """Richardson extrapolation of the values ``f`` on grids of spacing ``h`` (coarse to fine): the last
    three (or two) grids give {'order', 'observed' (bool: the order was measured, else 1 was assumed),
    'extrapolated', 'error' (of the finest value, signed: extrapolated − finest)}; NaN with fewer than two
    finite values."""
    h = [float(x) for x in h]
    f = [float(x) for x in f]
    nan = {"order": math.nan, "observed": False, "extrapolated": math.nan, "error": math.nan}
    if len(h) < 2 or not all(math.isfinite(x) for x in f[-2:]):
        return nan
    if len(h) >= 3 and all(math.isfinite(x) for x in f[-3:]):
        p, observed = _order(h[-3:], f[-3:])
    else:
        p, observed = 1.0, False
    r = h[-2] / h[-1]
    err = (f[-1] - f[-2]) / (r**p - 1.0)
    return {"order": p, "observed": observed, "extrapolated": f[-1] + err, "error": err}


def relative(name: str, delta: float, value: float) -> float:
    """|delta| relative to max(|value|, floor of ``name``)."""
    return abs(delta) / max(abs(value), floor_of(name))


def _levels_table(levels: list, names: list) -> dict:
    cols = {k: [getattr(lv, k) for lv in levels] for k in ("dx", "nx", "ny", "seconds", "convolutions", "status")}
    for n in names:
        cols[n] = [lv.obs.get(n, math.nan) for lv in levels]
    return cols


def _judge(levels: list, names: list, tol: float) -> tuple[bool, dict, dict]:
    """(converged, {name: relative change of the last two grids}, {name: richardson dict with 'rel_error'})."""
    h = [lv.dx for lv in levels]
    changes, rich = {}, {}
    ok = len(levels) >= 2 and levels[-1].status != "under_resolved"  # other problems: refining cannot fix
    for n in names:
        f = [lv.obs.get(n, math.nan) for lv in levels]
        if len(f) >= 2:
            a, b = f[-2], f[-1]
            if math.isnan(a) and math.isnan(b):
                continue
            if math.isnan(a) != math.isnan(b):
                changes[n] = math.inf
                ok = False
                continue
            changes[n] = relative(n, b - a, b)
            ok = ok and changes[n] <= tol
        r = richardson(h, f)
        if math.isfinite(r["error"]):
            r["rel_error"] = relative(n, r["error"], r["extrapolated"])
            ok = ok and r["rel_error"] <= tol
        rich[n] = r
    return ok, changes, rich


#: an extrapolated dx finer than the last grid's / NEED_FLOOR (64× its pixels) is not given as a number: it comes
#: from an order clipped at 0.5 or a jump on one grid only, and says only "much finer"
NEED_FLOOR = 8.0


def _dx_needed(levels: list, rich: dict, changes: dict, tol: float) -> float:
    """dx at which every observable's error estimate and change between grids would be tol, both scaling as
    h^p (p the observed order, else 1): h·(tol/e)^(1/p) with e the larger of the two, the smallest dx of all."""
    h = levels[-1].dx
    need = h
    for n, r in rich.items():
        e = max((x for x in (r.get("rel_error", math.nan), changes.get(n, math.nan)) if math.isfinite(x)),
                default=math.nan)
        p = r["order"] if math.isfinite(r["order"]) else 1.0
        if math.isfinite(e) and e > tol:
            need = min(need, h * (tol / e) ** (1.0 / p))
    return need


def _why(changes: dict) -> str:
    """What keeps the refinement from converging, in words: the observable that moved most."""
    worst = max(changes, key=lambda n: changes[n], default=None)
    if worst is None:
        return "one grid only"
    if math.isinf(changes[worst]):  # NaN on one of the two grids: a jump or transition seen on one only
        return f"{worst} exists on one of the last two grids only (NaN on the other)"
    return f"{worst} changed {changes[worst]:.2%} between the last two grids"
