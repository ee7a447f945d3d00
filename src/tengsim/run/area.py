"""The charged-area fraction A/S of a contact result (Eq. 12: V_OC = σT/(ε_r ε0) × A/S), by one of two
definitions (:data:`DEFINITIONS`):

* ``contact`` (the default): the 2-D area where the gap is below the law's peak-tension separation, measured
  on each state's gap map (:func:`tengsim.analysis.charged_area`, the result's ``charged_fraction`` column);
  the same code for every shape, array, rough or measured surface;
* ``paper``: the paper's construction for its pyramids, from Greenwood's contact length Λc along X through
  the apex and the shape's patch family (Λc²/S, (π/4)Λc²/S or Λc/L), kept to reproduce the paper's figures.

Also: the result's scale to pressure, the approach states a pressed device passes, and the observer of A/S
at named pressures that automatic refinement (``resolve_pressures``) converges.  Read by the refinement
(:mod:`tengsim.run.resolve`), the study (:mod:`tengsim.study.observe`) and the designer (:mod:`tengsim.design`).
"""
from __future__ import annotations

import math

import numpy as np

# ---- units: the one place that knows how a result maps to pressure -------------------------------

def physical_scale(res) -> tuple[float, float] | None:
    """(Pa per unit F, metres per unit D) of a result, or None for a dimensionless run.

    Every physical run (any shape, :class:`tengsim.units.Scaling`) carries ``pressure_Pa`` (or ``F_N``
    with ``cell_area_m2``) and ``eps_m``: the ratio to F is one constant.  Older pyramid files without
    those columns: the paper's scaling (Eq. 7, ℓ = ε m/n) from their parameters.
    """
    p = res.params
    t = res.table
    eps = p.get("eps_m")
    F = np.asarray(t["F"], float)
    ok = np.abs(F) > 1e-12 * max(1.0, float(np.max(np.abs(F)))) if len(F) else np.zeros(0, bool)
    if eps and np.any(ok):
        if "pressure_Pa" in t:
            P = np.asarray(t["pressure_Pa"], float)
            return float(np.median(P[ok] / F[ok])), float(eps)
        if "F_N" in t and p.get("cell_area_m2"):
            fn = np.asarray(t["F_N"], float)
            return float(np.median(fn[ok] / F[ok])) / float(p["cell_area_m2"]), float(eps)
    need = ("E_star_Pa", "W_J_m2", "base_m", "height_m", "pitch_m", "eps_m")
    if shape_name(p) == "pyramid" and all(p.get(k) for k in need):
        m, n, L, eps = p["base_m"], p["height_m"], p["pitch_m"], p["eps_m"]
        # the pyramid's force unit 3π W ℓ²/ε with ℓ = ε m/n (Eqs. 7, 10), over the cell's area L²
        return 3 * math.pi * m**2 * p["W_J_m2"] * eps / n**2 / L**2, float(eps)
    return None


def shape_name(params: dict) -> str:
    """The registered name of a result's shape (from its [contact] table, else its class name)."""
    cfg = params.get("config")
    if isinstance(cfg, dict) and cfg.get("shape"):
        return str(cfg["shape"]).lower()
    return str(params.get("shape", "")).lower()


def is_array(params: dict) -> bool:
    """A result of an array of patterns (:mod:`tengsim.shapes.arrays`: ``pattern``, ``K``, ``pattern_*``)."""
    return shape_name(params) == "array" or (params.get("shape") == "Array" and "pattern_cell" in params)


def pattern_params(params: dict) -> dict:
    """The parameters of the one pattern a result's Λc is measured on: an array's pattern (its
    ``pattern_*`` parameters, named as the pattern names them; Λc is measured along X through the highest
    apex, one pattern's), the result's own otherwise."""
    if not is_array(params):
        return params
    name = str(params.get("pattern") or "pyramid")
    own = {k[len("pattern_"):]: v for k, v in params.items() if k.startswith("pattern_")}
    return {**own, "shape": name, "config": {"shape": name}}


def cell_side(params: dict) -> float:
    """The side L̄ (in ℓ) of the square cell over which one contact patch is charged: an array's pattern
    cell (its super-cell holds K × K of them), the shape's ``cell``, else √(cell area)/ℓ of a physical
    run (``cell_area_m2``, ``lateral_m``); NaN if none of these is known."""
    p = pattern_params(params)
    cell = p.get("cell")
    if cell is not None:
        return float(cell)
    if params.get("cell_area_m2") and params.get("lateral_m"):
        return math.sqrt(float(params["cell_area_m2"])) / float(params["lateral_m"])
    return math.nan


def family(params: dict) -> str:
    """'square', 'disc' or 'line': how Λc (Greenwood's tensile-peak length along X through the apex)
    maps to the charged area (an array: its pattern's family).  The shape answers: its class's
    ``contact_family``, the class found in the registry by name or by class name (a result's ``shape``
    parameter); a shape not registered (a plugin's, not loaded) is 'square'."""
    from tengsim.plugins import SHAPES  # the built-in shapes registered

    name = shape_name(pattern_params(params))
    for key in SHAPES.names():
        cls = SHAPES.get(key)
        if name in (key, getattr(cls, "__name__", "").lower()):
            return getattr(cls, "contact_family", "square")
    try:
        return getattr(SHAPES.get(name), "contact_family", "square")  # an alias
    except Exception:  # noqa: BLE001 - not registered
        return "square"


def patch(shape, params: dict) -> tuple[float, str]:
    """(L̄, family) of the one pattern a result's Λc is measured on, asked of its ``shape`` object
    (``charged_patch``: an array answers its pattern's); a result read back from a file carries no shape object
    (None), nor does a shape that does not answer: then from the result's parameters ``params``
    (:func:`cell_side`, :func:`family`)."""
    ask = getattr(shape, "charged_patch", None)
    if ask is not None:
        return ask()
    return cell_side(params), family(params)


def area_fraction(res, contact_length, params: dict | None = None, shape=None) -> np.ndarray:
    """Charged-area fraction A/S of the cell (Eq. 12) from the contact length Λc:
    square patches (pyramid, cube) (Λc/L̄)², discs (cone, hemisphere, sphere, flat punch) π(Λc/2)²/L̄²,
    line gratings (line, sinusoid) Λc/L̄; clipped to [0, 1].  Λc/L̄ is the same ratio in ℓ or in metres.
    L̄ is :func:`cell_side` (an array: the pattern's cell, so A/S is that of K × K cells alike, each as
    the highest one; a run with the ``array_area`` observer has the sum over its cells, used instead by
    :func:`observe`).  L̄ and the family are the ``shape`` object's where it is given (:func:`patch`), else from
    ``params``: the result's parameters to read (default ``res.params``)."""
    p = res.params if params is None else params
    cell, fam = patch(shape, p)
    x = np.asarray(contact_length, float) / cell
    if fam == "line":
        return np.clip(x, 0.0, 1.0)
    if fam == "disc":
        return np.clip(math.pi / 4 * x**2, 0.0, 1.0)
    return np.clip(x**2, 0.0, 1.0)


def full_length(params: dict, shape=None) -> float:
    """Λc of full contact of a result's shape: its own :meth:`~tengsim.shapes.Shape.full_contact_length`
    (asked of the ``shape`` object where it is given; else the shape rebuilt from the result's parameters, a
    result read back from a file; an array: its pattern's); NaN if it has none or cannot be rebuilt (a shape
    not registered here, a height map)."""
    import dataclasses

    if shape is not None and hasattr(shape, "full_contact_length"):
        return float(shape.full_contact_length())

    from tengsim.registry import SHAPES

    params = pattern_params(params)
    try:
        cls = SHAPES.get(shape_name(params))
        kw = {f.name: params[f.name] for f in dataclasses.fields(cls) if f.init and f.name in params}
        return float(cls(**kw).full_contact_length())
    except Exception:  # noqa: BLE001 - a shape that cannot answer has no known full-contact length
        return math.nan


DEFINITIONS = {
    "contact": "A/S = the area where the gap is below the law's peak-tension separation (Greenwood's contact "
               "edge; for a law without tension, its wall's gap), measured on the 2-D contact map, over the cell "
               "area S",
    "paper": "the paper's A/S: Λc²/S (square patch), (π/4)Λc²/S (disc) or Λc/L (strip), Λc Greenwood's contact "
             "length (the tensile-peak length along X through the apex), S the cell area",
}
"""The charged-area definitions: ``contact`` (the default, the 2-D map) and ``paper`` (the paper's Λc)."""

CHARGED_COLUMN = "charged_fraction"

FULL_CONTACT_AREA_FRACTION = 0.95
"""Full contact as a design reports it (``full_contact_Pa``): the approach pressure at which the charged area A/S
reaches this fraction of its full-contact value (the footprint's): where the area saturates under the load.  (A
study's ``transition_D`` asks 0.95 of another measure, the contact length Λc:
tengsim.results.result.TRANSITION_LENGTH_FRACTION.)"""
ADHESIVE_FULL_CONTACT_LENGTH_FRACTION = 0.9
"""A study's ``adhesive_full_contact`` flag (its default ``full_contact_fraction``): the contact length Λc at zero
load at least this fraction of the full-contact length, a pattern that adhesion alone pulls (nearly) shut.  A
different question from :data:`FULL_CONTACT_AREA_FRACTION`'s (a yes/no of the zero-load state, not the pressure at
which the area saturates) on a different measure (a length: 0.9 of Λc is 0.81 of a square patch's area); both kept
at the values their results were published with."""


def check_definition(definition: str) -> str:
    """``definition`` if it names one of :data:`DEFINITIONS`; a TengsimError otherwise."""
    from tengsim.errors import ConfigValueError

    d = str(definition).strip().lower()
    if d not in DEFINITIONS:
        raise ConfigValueError(f"area must be one of {', '.join(DEFINITIONS)}, got {definition!r}")
    return d


# ---- the observables ----------------------------------------------------------------------------

def load_control(res, column: str = "contact_length"):
    """Approach states a pressed device passes under increasing load: F above every earlier F, F > 0; the
    zero-load state is put first, Λc (or ``column``) interpolated linearly in F between the last F <= 0 and the
    first F > 0; after a snap (the load fell back on the D path), the state the device lands on at the fold's load
    (:func:`_passed`).  Returns (F, Λc) arrays (possibly empty)."""
    a = res.branch("approach")
    F, L = np.asarray(a["F"], float), np.asarray(a[column], float)
    Fk, Lk = _passed(F, L, 0.0, _jumps(a, len(F)))
    if not len(Fk):
        return np.array([]), np.array([])
    i0 = int(np.flatnonzero(F == Fk[0])[0])
    if i0 > 0 and F[i0 - 1] <= 0:
        w = -F[i0 - 1] / (F[i0] - F[i0 - 1])
        Fk, Lk = np.insert(Fk, 0, 0.0), np.insert(Lk, 0, L[i0 - 1] + w * (L[i0] - L[i0 - 1]))
    return Fk, Lk


def retraction_control(res, columns):
    """Retraction states a device passes under decreasing load (each F below every earlier F), as arrays in
    increasing F: (F, [each of ``columns``]); after a snap, the state the load lands on first (:func:`_passed`)."""
    r = res.branch("retraction")
    F = np.asarray(r["F"], float)
    runs = [_passed(-F, np.asarray(r[c], float), -math.inf, _jumps(r, len(F))) for c in columns]
    negF = runs[0][0] if runs else _passed(-F, F, -math.inf)[0]
    return -negF[::-1], [y[::-1] for _, y in runs]


LANDING_STEEPNESS = 10.0
"""A path segment whose y changes this many times faster in F than on the segment after it is a jump of the D path
(the walk may step across one without flagging it): a snap lands on the state after it, not on a blend."""


def _steep(F, y, i: int) -> bool:
    """Whether the segment (i-1, i) is a jump by :data:`LANDING_STEEPNESS` (False where no rising segment follows)."""
    if i + 1 >= len(F) or not F[i + 1] > F[i]:
        return False
    here = abs(y[i] - y[i - 1]) / (F[i] - F[i - 1])
    after = abs(y[i + 1] - y[i]) / (F[i + 1] - F[i])
    return here > LANDING_STEEPNESS * after


def _jumps(branch, n: int):
    """The branch's ``jump`` column (row i follows a jump of the D path) as booleans, or None without one."""
    j = branch.get("jump") if hasattr(branch, "get") else None
    return None if j is None or len(j) != n else np.asarray(j, bool)


def _passed(F, y, start, jumps=None):
    """(F, y) of the states a device passes under increasing load F from ``start``: each F above every earlier one.
    Where the load fell back between two kept states (a fold: the device snaps at the load it reached), the state
    it lands on is put in at that load, so the value jumps at the fold's load instead of being blended from the
    fold to the next kept state: y linear in F on the path's segment that first exceeds it, or, where that segment
    is itself a jump of the D path (``jumps[i]``: row i follows one; or y rises along it :data:`LANDING_STEEPNESS`
    times faster in F than on the next segment), the state after that jump (the branch it lands on is not solved
    below that state's load)."""
    Fk, yk = [], []
    best, last = start, None
    for i, f in enumerate(F):
        if f > best:
            if last is not None and last != i - 1 and F[i - 1] <= best < f:  # landed after a snap
                w = (best - F[i - 1]) / (f - F[i - 1])
                if (jumps is not None and jumps[i]) or _steep(F, y, i):
                    w = 1.0
                Fk.append(best)
                yk.append(y[i - 1] + w * (y[i] - y[i - 1]))
            Fk.append(f)
            yk.append(y[i])
            best, last = f, i
    return np.array(Fk, float), np.array(yk, float)


def at_pressures(P, y, ps) -> np.ndarray:
    """``y`` of the states at pressures ``P`` (increasing) at the pressures ``ps``: linear between the two states
    around each; NaN outside the states' range (or with fewer than two)."""
    P, y = np.asarray(P, float), np.asarray(y, float)
    out = np.full(len(ps), np.nan)
    if len(P) < 2:
        return out
    ps = np.asarray(ps, float)
    inside = (ps >= P[0]) & (ps <= P[-1])
    out[inside] = np.interp(ps[inside], P, y)
    return out


def branch_states(res, definition: str, params: dict, shape=None) -> dict:
    """{'approach'|'retraction': {'P' (Pa, increasing), 'area' (A/S), 'repulsive' (fraction)}} of the states a
    pressed device passes on each branch (:func:`load_control`, :func:`retraction_control`); A/S by ``definition``
    (:data:`DEFINITIONS`; ``contact`` where the result has its column, else the paper's from Λc with ``params``
    and ``shape`` as in :func:`area_fraction`)."""
    sc = res.scaling
    k_p = sc.pressure(1.0)
    cell = sc.cell_area
    contact = definition == "contact" and CHARGED_COLUMN in res.table
    col = CHARGED_COLUMN if contact else "contact_length"

    def area(v):
        return np.clip(np.asarray(v, float), 0.0, 1.0) if contact else area_fraction(res, v, params, shape)

    F, L = load_control(res, col)
    _, R = load_control(res, "area_repulsive")
    out = {"approach": {"P": k_p * F, "area": area(L), "repulsive": R * sc.lateral**2 / cell}}
    Fr, (Lr, Rr) = retraction_control(res, (col, "area_repulsive"))
    out["retraction"] = {"P": k_p * Fr, "area": area(Lr), "repulsive": Rr * sc.lateral**2 / cell}
    return out


def areas_at(res, pressures, definition: str, params: dict, shape=None) -> dict:
    """{branch: A/S at each of ``pressures`` (Pa)} on the branches of :func:`branch_states`, clipped to [0, 1]
    (NaN outside the pressures a branch reaches)."""
    return {b: np.clip(at_pressures(s["P"], s["area"], pressures), 0.0, 1.0)
            for b, s in branch_states(res, definition, params, shape).items()}


def loaded_area(res, params: dict | None = None, definition: str = "contact", shape=None
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray, list]:
    """(F, Λc, A/S, notes) of the approach states a pressed device passes (:func:`load_control`).  A/S by
    ``definition`` (:data:`DEFINITIONS`): ``contact``, the result's ``charged_fraction`` column (a result
    written without it falls back to the paper's, with a note); ``paper``, :func:`area_fraction` of Λc, or,
    for a run with the ``array_area`` observer, its ``area_fraction_greenwood`` column (Σ over the array's
    cells).  ``params`` and ``shape`` as in :func:`area_fraction`."""
    definition = check_definition(definition)
    p = res.params if params is None else params
    Fk, Lk = load_control(res)
    notes = []
    if definition == "contact" and CHARGED_COLUMN in res.table:
        return Fk, Lk, np.clip(load_control(res, CHARGED_COLUMN)[1], 0.0, 1.0), notes
    if definition == "contact" and len(Fk):
        notes.append("A/S by the paper's definition (Λc): the result has no charged_fraction column (written "
                     "by an older tengsim); run it again for the 2-D charged area")
    if "area_fraction_greenwood" in res.table:  # the array_area observer: the sum over the cells
        A = np.clip(load_control(res, "area_fraction_greenwood")[1], 0.0, 1.0)
    else:
        A = area_fraction(res, Lk, p, shape)
        if is_array(p) and len(Fk):
            notes.append("A/S of the array from its highest cell's contact length (K × K cells alike); "
                         "observers = ['array_area'] gives the sum over its cells")
    return Fk, Lk, A, notes


def area_name(pressure_Pa: float) -> str:
    """The refinement observable of A/S at a pressure: ``A_S_at_10000Pa``."""
    return f"A_S_at_{pressure_Pa:.6g}Pa".replace("+", "").replace(".", "p")


def area_at(pressures, cfg: dict | None = None, definition: str = "contact", shape=None):
    """The observer ``res -> {area_name(P): A/S at P}`` that automatic refinement (``resolve_pressures``,
    :func:`tengsim.run.resolve.resolve`) also converges: the charged-area fraction of Eq. (12) at each
    nominal pressure P (Pa) on the approach (linear in F between loaded states; NaN outside the states the
    run reaches or for a run without a physical scale).  V_OC (Eq. 12) is σT/(ε_r ε0) × A/S, so its relative
    change is A/S's.  ``shape``: the run's shape object, which the paper's A/S asks (:func:`patch`); without it,
    ``cfg``, the run's [contact] table (the shape's name for the patch family); ``definition``: :data:`DEFINITIONS`."""
    pressures = [float(p) for p in pressures]

    def observe_area(res) -> dict:
        out = {area_name(p): math.nan for p in pressures}
        scale = physical_scale(res)
        if scale is None:
            return out
        params = res.params if cfg is None else {**res.params, "config": cfg}
        Fk, _, A, _ = loaded_area(res, params, definition, shape)
        known = np.isfinite(A)
        if np.count_nonzero(known) < 2:
            return out
        P, A = scale[0] * Fk[known], A[known]
        for p in pressures:
            if P[0] <= p <= P[-1]:
                out[area_name(p)] = float(np.interp(p, P, A))
        return out

    return observe_area
