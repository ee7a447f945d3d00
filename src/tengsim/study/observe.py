"""Per-point observables of a design study (definitions in docs/design.md).

From one contact result (approach–retraction, dimensionless, Eq. 7/10) and the Eq. (12) device inputs
σ, ε_r, T.  Observables in the contact's own units (pull-off F, jump D, transition D, hysteresis,
charged-area fraction at zero load) exist for every run; those in pressure (V_OC at named pressures,
sensitivity, linear range, saturation, V_OC(P) curves) need a physical scaling and are NaN otherwise.
"""
from __future__ import annotations

import math

import numpy as np

from tengsim.errors import TengsimError

OBSERVABLE_DEFAULTS = {
    "pressures": ("1kPa", "10kPa", "100kPa"),
    "fit_range": ("0kPa", "10kPa"),
    "linear_tolerance": 0.1,
    "saturation_fraction": 0.9,
    "grid_max": "150kPa",
    "grid_num": 61,
    "transition_fraction": 0.95,
    "full_contact_fraction": 0.9,
}

SCALARS = {
    # name: (units, long name)
    "pull_off_F": ("3π W ε m²/n² (Eq. 10)", "most tensile force on retraction (negative: tensile)"),
    "pull_off_Pa": ("Pa", "pull-off force per cell area (negative: tensile)"),
    "jump_in_D": ("ε", "D at which the approach first lands on the jumped-in state"),
    "jump_out_D": ("ε", "D at which the retraction first lands on the jumped-out state"),
    "transition_D": ("ε", "approach D where Λc reaches transition_fraction of full contact"),
    "area_fraction_0": ("1", "charged-area fraction A/S at zero load (approach)"),
    "adhesive_full_contact": ("1", "1 if Λc at zero load >= full_contact_fraction × full contact (2N)"),
    "S_V_per_kPa": ("V/kPa", "dV_OC/dP, least-squares line over fit_range"),
    "linear_range_Pa": ("Pa", "highest P up to which V_OC stays within linear_tolerance of the fit "
                        "(fit_range[0] if the first state is off)"),
    "V_sat": ("V", "largest V_OC of the run"),
    "P_sat_Pa": ("Pa", "lowest P where V_OC reaches saturation_fraction × V_sat"),
    "hysteresis": ("3π W ε² m²/n² per cell (∮F dD)", "approach minus retraction ∮ F dD"),
    "hysteresis_J_m2": ("J/m²", "energy lost per cycle per unit nominal area"),
}


def parse_observables(table: dict, where: str = "study") -> dict:
    """Typed [observables] settings with defaults (pressures in Pa)."""
    from tengsim.schema import Field, Table

    t = Table("observables", [
        Field("pressures", "floats", OBSERVABLE_DEFAULTS["pressures"], dim="pressure",
              help="pressures at which V_OC is reported"),
        Field("fit_range", "floats", OBSERVABLE_DEFAULTS["fit_range"], dim="pressure",
              help="low-pressure range [lo, hi] of the sensitivity fit"),
        Field("linear_tolerance", "float", 0.1, help="relative deviation that ends the linear range"),
        Field("saturation_fraction", "float", 0.9, help="fraction of V_sat that defines P_sat"),
        Field("grid_max", "float", OBSERVABLE_DEFAULTS["grid_max"], dim="pressure",
              help="top of the common pressure grid (from 0)"),
        Field("grid_num", "int", 61, help="points of the common pressure grid"),
        Field("transition_fraction", "float", 0.95, help="Λc fraction of full contact for transition_D"),
        Field("full_contact_fraction", "float", 0.9, help="Λc fraction of full contact at zero load flagged"),
    ])
    raw = dict(table)
    labels = raw.get("pressures", OBSERVABLE_DEFAULTS["pressures"])
    if isinstance(labels, str):
        labels = [s.strip() for s in labels.split(",") if s.strip()]
    elif not isinstance(labels, (list, tuple)):
        labels = [labels]
    out = t.parse(raw, where=f"{where}: [observables] ")
    defaults = {k: out[k] for k in out}
    for k in ("pressures", "fit_range", "grid_max"):
        if defaults[k] == OBSERVABLE_DEFAULTS[k]:
            defaults[k] = t.fields[k].parse(OBSERVABLE_DEFAULTS[k])
    fr = defaults["fit_range"]
    if len(fr) != 2 or not fr[1] > fr[0] >= 0:
        raise TengsimError(f"{where}: [observables] fit_range must be [lo, hi] with 0 <= lo < hi, got {fr!r}")
    if not defaults["grid_max"] > 0 or defaults["grid_num"] < 2:
        raise TengsimError(f"{where}: [observables] grid_max must be > 0 and grid_num >= 2")
    defaults["pressure_labels"] = [str(s).replace(" ", "") for s in labels]
    defaults["pressures"] = list(defaults["pressures"])
    defaults["fit_range"] = list(fr)
    return defaults


def pressure_grid(settings: dict) -> np.ndarray:
    return np.linspace(0.0, settings["grid_max"], int(settings["grid_num"]))


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


FAMILIES = {
    "square": ("pyramid", "cube"),
    "disc": ("cone", "hemisphere", "sphere", "paraboloid", "flat_punch", "flatpunch"),
    "line": ("line", "sinusoid", "sinusoid1d"),
}
"""Contact-patch family of each built-in shape for the charged-area fraction A/S (docs/design.md);
a shape not listed (a plugin) is taken as 'square' unless its class sets ``contact_family``."""


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
    maps to the charged area (an array: its pattern's family)."""
    name = shape_name(pattern_params(params))
    for fam, names in FAMILIES.items():
        if name in names:
            return fam
    try:
        from tengsim.registry import SHAPES

        return getattr(SHAPES.get(name), "contact_family", "square")
    except Exception:  # noqa: BLE001 - an unregistered plugin's file
        return "square"


def area_fraction(res, contact_length, params: dict | None = None) -> np.ndarray:
    """Charged-area fraction A/S of the cell (Eq. 12) from the contact length Λc:
    square patches (pyramid, cube) (Λc/L̄)², discs (cone, hemisphere, sphere, flat punch) π(Λc/2)²/L̄²,
    line gratings (line, sinusoid) Λc/L̄; clipped to [0, 1].  Λc/L̄ is the same ratio in ℓ or in metres.
    L̄ is :func:`cell_side` (an array: the pattern's cell, so A/S is that of K × K cells alike, each as
    the highest one; a run with the ``array_area`` observer has the sum over its cells, used instead by
    :func:`observe`).  ``params``: the result's parameters to read (default ``res.params``)."""
    p = res.params if params is None else params
    cell = cell_side(p)
    x = np.asarray(contact_length, float) / cell
    fam = family(p)
    if fam == "line":
        return np.clip(x, 0.0, 1.0)
    if fam == "disc":
        return np.clip(math.pi / 4 * x**2, 0.0, 1.0)
    return np.clip(x**2, 0.0, 1.0)


def full_length(params: dict) -> float:
    """Λc of full contact of a result's shape: its own :meth:`~tengsim.shapes.Shape.full_contact_length`
    (the shape rebuilt from the result's parameters; an array: its pattern's); NaN if it has none or
    cannot be rebuilt (a shape not registered here, a height map)."""
    import dataclasses

    from tengsim.registry import SHAPES

    params = pattern_params(params)
    try:
        cls = SHAPES.get(shape_name(params))
        kw = {f.name: params[f.name] for f in dataclasses.fields(cls) if f.init and f.name in params}
        return float(cls(**kw).full_contact_length())
    except Exception:  # noqa: BLE001 - a shape that cannot answer has no known full-contact length
        return math.nan


# ---- the observables ----------------------------------------------------------------------------

def load_control(res, column: str = "contact_length"):
    """Approach states a pressed device passes under increasing load: F above every earlier F, F > 0;
    the zero-load state is put first, Λc (or ``column``) interpolated linearly in F between the last
    F <= 0 and the first F > 0.  Returns (F, Λc) arrays (possibly empty)."""
    a = res.branch("approach")
    F, L = np.asarray(a["F"], float), np.asarray(a[column], float)
    keep, best = [], 0.0
    for i, f in enumerate(F):
        if f > best:
            keep.append(i)
            best = f
    if not keep:
        return np.array([]), np.array([])
    i0 = keep[0]
    Fk, Lk = list(F[keep]), list(L[keep])
    if i0 > 0 and F[i0 - 1] <= 0:
        w = -F[i0 - 1] / (F[i0] - F[i0 - 1])
        Fk.insert(0, 0.0)
        Lk.insert(0, L[i0 - 1] + w * (L[i0] - L[i0 - 1]))
    return np.array(Fk), np.array(Lk)


def _first_jump(res, kind):
    for j in res.jumps:
        if j.kind == kind:
            return j.D_after
    return math.nan


def device_values(device: dict) -> tuple[float, float, float]:
    """(σ in C/m², ε_r, T in m) of a point's [device] table; a TengsimError naming a bad value."""
    from tengsim.schema import Field

    sigma = Field("sigma", dim="charge/area").parse(device["sigma"], "device.")
    eps_r = Field("eps_r").parse(device["eps_r"], "device.")
    T = Field("thickness", dim="length").parse(device["thickness"], "device.")
    for k, v in (("sigma", sigma), ("eps_r", eps_r), ("thickness", T)):
        if not v > 0:
            raise TengsimError(f"device.{k} must be > 0, got {device[k]!r}")
    return sigma, eps_r, T


def loaded_area(res, params: dict | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray, list]:
    """(F, Λc, A/S, notes) of the approach states a pressed device passes (:func:`load_control`): A/S is
    :func:`area_fraction` of Λc, or, for a run with the ``array_area`` observer, its
    ``area_fraction_greenwood`` column (Σ over the array's cells).  ``params`` as in :func:`area_fraction`."""
    p = res.params if params is None else params
    Fk, Lk = load_control(res)
    notes = []
    if "area_fraction_greenwood" in res.table:  # the array_area observer: the sum over the cells
        A = np.clip(load_control(res, "area_fraction_greenwood")[1], 0.0, 1.0)
    else:
        A = area_fraction(res, Lk, p)
        if is_array(p) and len(Fk):
            notes.append("A/S of the array from its highest cell's contact length (K × K cells alike); "
                         "observers = ['array_area'] gives the sum over its cells")
    return Fk, Lk, A, notes


def area_name(pressure_Pa: float) -> str:
    """The refinement observable of A/S at a pressure: ``A_S_at_10000Pa``."""
    return f"A_S_at_{pressure_Pa:.6g}Pa".replace("+", "").replace(".", "p")


def area_at(pressures, cfg: dict | None = None):
    """The observer ``res -> {area_name(P): A/S at P}`` that automatic refinement (``resolve_pressures``,
    :func:`tengsim.run.resolve.run_contact`) also converges: the charged-area fraction of Eq. (12) at each
    nominal pressure P (Pa) on the approach (linear in F between loaded states; NaN outside the states the
    run reaches or for a run without a physical scale).  V_OC (Eq. 12) is σT/(ε_r ε0) × A/S, so its relative
    change is A/S's.  ``cfg``: the run's [contact] table (the shape's name for the patch family)."""
    pressures = [float(p) for p in pressures]

    def observe_area(res) -> dict:
        out = {area_name(p): math.nan for p in pressures}
        scale = physical_scale(res)
        if scale is None:
            return out
        params = res.params if cfg is None else {**res.params, "config": cfg}
        Fk, _, A, _ = loaded_area(res, params)
        known = np.isfinite(A)
        if np.count_nonzero(known) < 2:
            return out
        P, A = scale[0] * Fk[known], A[known]
        for p in pressures:
            if P[0] <= p <= P[-1]:
                out[area_name(p)] = float(np.interp(p, P, A))
        return out

    return observe_area


def contact_hooks(cfg: dict) -> dict:
    """What :func:`tengsim.run.resolve.run_contact` needs from this layer for the [contact] table ``cfg``: the
    A/S observer (``resolve_pressures``)."""
    return {"area_at": lambda pressures: area_at(pressures, cfg)}


def observe(res, device: dict, settings: dict) -> dict:
    """Scalars (dict name → float) and curves ('V_OC', 'area_fraction' on the common pressure grid,
    'V_OC_at' at the named pressures) of one contact result.

    A/S is :func:`area_fraction` of Λc, or, for a run with the ``array_area`` observer, its
    ``area_fraction_greenwood`` column (Σ over the array's cells).  A value that cannot be had is NaN:
    every pressure observable of a dimensionless run (no scaling); transition_D and
    adhesive_full_contact of a shape without a known full-contact length (:func:`full_length`); the
    V_OC observables of a run with fewer than two loaded states or no known cell (:func:`cell_side`).
    'notes' lists the reasons that apply to a physical run (V_OC missing; an array's A/S from one cell),
    for the study's message column."""
    from tengsim.device.formulas import voc_polymer

    sigma, eps_r, T = device_values(device)
    nan = math.nan
    out = {k: nan for k in SCALARS}
    out["pull_off_F"] = res.pull_off_force
    out["jump_in_D"] = _first_jump(res, "jump-in")
    retr = [j for j in res.jumps if j.kind == "jump-out"]
    out["jump_out_D"] = retr[0].D_after if retr else nan
    full = full_length(res.params)
    if math.isfinite(full):
        out["transition_D"] = res.transition_D(full, settings["transition_fraction"])
    out["hysteresis"] = res.hysteresis
    Fk, Lk, A, notes = loaded_area(res)
    grid = pressure_grid(settings)
    curves = {"V_OC": np.full(grid.shape, nan), "area_fraction": np.full(grid.shape, nan),
              "V_OC_at": np.full(len(settings["pressures"]), nan)}
    if len(Fk):
        out["area_fraction_0"] = float(A[0])
        if math.isfinite(full):
            out["adhesive_full_contact"] = float(Lk[0] >= settings["full_contact_fraction"] * full)
    scale = physical_scale(res)
    if scale is None:
        return {"scalars": out, "curves": curves, "notes": notes}
    k_p, k_D = scale
    out["pull_off_Pa"] = k_p * out["pull_off_F"]
    out["hysteresis_J_m2"] = k_p * k_D * out["hysteresis"]
    known = np.isfinite(A)
    if np.count_nonzero(known) < 2:
        why = ("no cell side known for A/S" if len(Fk) >= 2 and not math.isfinite(cell_side(res.params))
               else f"{len(Fk)} loaded state(s) (F > 0 rising) on the approach, 2 needed")
        return {"scalars": out, "curves": curves, "notes": [*notes, f"no V_OC: {why}"]}
    P = k_p * Fk[known]
    A = A[known]
    V = voc_polymer(A, sigma, eps_r, T)

    def at(x):
        x = np.asarray(x, float)
        y = np.interp(x, P, V)
        return np.where((x >= P[0]) & (x <= P[-1]), y, nan)

    curves["V_OC"] = at(grid)
    curves["area_fraction"] = np.where(np.isfinite(curves["V_OC"]), np.interp(grid, P, A), nan)
    curves["V_OC_at"] = at(settings["pressures"])
    lo, hi = settings["fit_range"]
    a, b = max(lo, P[0]), min(hi, P[-1])
    if b > a:  # least squares over the piecewise-linear V_OC(P) sampled evenly on [lo, hi] ∩ the run
        xs = np.linspace(a, b, 41)
        slope, icpt = np.polyfit(xs, np.interp(xs, P, V), 1)
        out["S_V_per_kPa"] = slope * 1e3
        fit = icpt + slope * P
        ok = np.abs(V - fit) <= settings["linear_tolerance"] * np.abs(fit)
        idx = np.flatnonzero(P >= lo)
        last = float(lo) if len(idx) else nan  # the first state already off the line: no linear range
        for i in idx:
            if not ok[i]:
                break
            last = P[i]
        out["linear_range_Pa"] = last
    vs = float(np.max(V))
    out["V_sat"] = vs
    target = settings["saturation_fraction"] * vs
    i = int(np.flatnonzero(V >= target)[0])
    if i == 0:
        out["P_sat_Pa"] = float(P[0])
    else:
        out["P_sat_Pa"] = float(P[i - 1] + (target - V[i - 1]) * (P[i] - P[i - 1]) / (V[i] - V[i - 1]))
    return {"scalars": out, "curves": curves, "notes": notes}
