"""A design: one micro-structure and its materials in physical units, and the pressures asked for.

:func:`plan_design` turns a [design] table (CLI options or a TOML file) into a frozen :class:`DesignPlan`.
The table holds

* the shape and its physical keys, ``E_star``, ``W``, ``eps`` (the interaction range: the material input;
  the Tabor number is derived per shape) and the contact options a design leaves to the user (law and its
  keys, boundary, film, solver, symmetry, roughness): the [contact] schema's own keys, checked by
  :func:`tengsim.run.plan.plan_contact` (nothing is retyped here);
* the design's own keys (:func:`design_fields`): the pressures (``p_min``, ``p_max``, ``p_step``), the device
  inputs of Eq. (12) and Eq. (17) (σ, ε_r, T, rest gap d0: the paper's values by default), the grid (``dx``
  a length, ``max_pixels``), the convergence tolerance ``tol``, the time budget and the charged-area
  definition ``area``.

The boundary is ``periodic`` unless given: a pattern's design is the array it describes (``free``, one isolated
cell on a half-space, is named as such; :data:`BOUNDARY_WHY`).

The path (D range, steps) is not the user's: :mod:`tengsim.design.run` extends it until ``p_max`` is
reached.
"""
from __future__ import annotations

import dataclasses
import json
import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from tengsim.errors import ConfigValueError, TengsimError, listed, shown

if TYPE_CHECKING:
    from tengsim.run.plan import ContactPlan

PAPER_DEVICE = {"sigma": 5.84e-6, "eps_r": 2.40, "T": 400e-6, "gap": 0.1e-3}
"""The paper's device (Section 5, Fig. 8): σ = 5.84 µC/m², ε_r = 2.40, T = 400 µm, rest gap d0 = 0.1 mm."""

DEVICE_BOUNDS = {"sigma": (1e-9, 1e-2, "1 nC/m2 ... 10 mC/m2 (air breaks down far below the top)"),
                 "eps_r": (1.0, 1e5, "1 ... 1e5 (vacuum ... the largest ferroelectric permittivities)"),
                 "T": (1e-9, 1.0, "1 nm ... 1 m"),
                 "gap": (1e-9, 1.0, "1 nm ... 1 m")}
"""Physical bounds of the device inputs of Eq. (12) and Eq. (17): a value outside is a typo, not a device."""
SOLVER_TOL_PER_TOL = 0.01
"""Each equilibrium of a design is solved to max|r| <= this × the design's tol (ε; 1e-4 at the default 1 %): the
solver's share of a reported number is then far below tol (docs/validation.md, "A design's solver tolerance")."""


def constrained_solver(law):
    """The constrained solver a design runs ``law`` on unless it names its solver, asked of the law: one that
    declares an adhesive hard-wall limit (``Law.hard_wall()`` with a tension: ``md``, ``exp``, a plugin's) runs
    on the solver its limit prefers (``CohesiveLimit.solver``: 'pk' for ``md`` and ``exp``, 'ram' unless a
    plugin's limit says otherwise); None for any other law (LJ93; the wall without adhesion): the design's
    default solver."""
    lim = law.hard_wall() if hasattr(law, "hard_wall") else None
    if lim is None or not float(lim.tension) > 0:
        return None
    return lim.solver


TOL_FLOOR = 1e-4
"""The smallest design tolerance (0.01 %): each equilibrium is solved to 0.01 × tol, and a grid refinement to
1e-4 is already far beyond what a design's budget pays for."""
MAX_NAME = 200
"""The longest design name (characters): it labels tables, figures and a folder."""

CONTROLLED = ("tabor", "dx", "d_min", "d_max", "d_step", "refine_levels", "maps_at", "control", "f_min", "f_max",
              "f_step", "adaptive", "adapt_tol", "resolve", "resolve_tol", "max_pixels", "resolve_pressures",
              "out", "plot", "tol", "observers")
"""[contact] keys a design sets itself (the path, the grid, the refinement) or names otherwise (tol, dx)."""


def design_fields() -> list:
    """The design's own keys (besides the [contact] keys of its shape)."""
    from tengsim.run.tolerance import DEFAULT_TOL
    from tengsim.schema import Field

    return [
        Field("name", "str", None, help="label of the design in tables and figures (default: the shape and "
              "its sizes)"),
        Field("p_min", default=0.0, dim="pressure", help="lowest nominal pressure asked for (default 0 Pa)"),
        Field("p_max", default=None, dim="pressure", help="highest nominal pressure asked for, e.g. '100kPa' "
              "(required)"),
        Field("p_step", default=None, dim="pressure", help="pressure step, e.g. '5kPa' (default (p_max - "
              "p_min)/20)"),
        Field("sigma", default=PAPER_DEVICE["sigma"], dim="charge/area",
              help="tribo-charge density σ (default the paper's 5.84 µC/m2)"),
        Field("eps_r", default=PAPER_DEVICE["eps_r"], help="relative permittivity ε_r of the polymer (default "
              "the paper's 2.40)"),
        Field("T", default=PAPER_DEVICE["T"], dim="length", help="polymer thickness T of Eq. (12) (default the "
              "paper's 400 µm)"),
        Field("gap", default=PAPER_DEVICE["gap"], dim="length",
              help="the device's rest gap d0 for Eq. (17) (default the paper's 0.1 mm)"),
        Field("tol", default=DEFAULT_TOL, help="relative tolerance the reported numbers are converged to (default "
              "0.01 = 1 %)"),
        Field("dx", default=None, dim="length", help="first grid spacing, a length such as '50nm' (default: "
              "from the shape's features and the law's process zone)"),
        Field("max_pixels", "int", None, help="largest grid nx·ny the refinement may use"),
        Field("budget", default=600.0, dim="time", help="largest estimated run time before it is refused, "
              "in seconds or with a unit, e.g. 600 or '600s' (default 600 s)"),
        Field("maps", "bool", True, help="keep contact pressure maps near 10 %, 50 % and 100 % of p_max (kept "
              "during the finest grid's walk, at the depths the grid before it predicts); false: none"),
        Field("retraction", "bool", True, help="solve the retraction too (the pull-off, the hysteresis, the "
              "unloading curve); false: the approach only, about half the solving (all a fit to loading data "
              "needs)"),
        Field("area", "str", "contact", help="charged-area definition: 'contact' (default: the 2-D area where "
              "the gap is below the law's peak-tension separation, any shape) or 'paper' (the paper's Λc², from "
              "the contact length through the apex; for its pyramids)"),
    ]


BOUNDARY_WHY = {
    "periodic": "the periodic array the shape's cell describes: every cell pressed beside its neighbours, whose "
                "deformation it feels",
    "free": "one isolated cell on an elastic half-space (the paper's Eq. 9): a single structure, or an array "
            "whose pitch is large against each contact",
}
"""Why each boundary: the report's line (docs/own_design.md, 'Array or isolated structure')."""


@dataclass(frozen=True)
class DesignPlan:
    """A validated design (SI throughout); ``contact_table`` is the [contact] table handed to
    :func:`tengsim.run.plan.plan_contact` (the shape's physical keys, E_star, W, eps and contact options) and
    ``contact_plan`` the :class:`tengsim.run.plan.ContactPlan` it gave (what :func:`tengsim.design.run.run_design`
    runs: a design is planned once)."""

    name: str
    shape: str
    contact_table: dict
    shape_params: dict
    pressures: tuple
    sigma: float
    eps_r: float
    T: float
    gap: float
    rel_tol: float
    dx_m: float | None
    max_pixels: int | None
    budget_s: float
    E_star: float
    W: float
    eps: float
    tabor: float
    maps: bool = True
    area: str = "contact"
    retraction: bool = True
    """Whether the retraction is solved (false: the approach only; no pull-off, hysteresis or unloading curve)."""
    boundary: str = "periodic"
    boundary_given: bool = False
    extra: dict = field(default_factory=dict)
    solver_given: bool = False
    """Whether the design's table names its solver (else a cohesive law runs on 'pk')."""
    contact_plan: ContactPlan | None = field(default=None, compare=False, repr=False)
    """The plan of ``contact_table`` the design runs (with its solver tolerance, :func:`solver_tol`, and its
    solver): always set by :func:`plan_design`, the one place a design is planned."""
    bands: tuple = field(default=(), compare=False, repr=False)
    """The designs of a fitted material's uncertainty points (:func:`plan_bands`; empty
    without a material or its points): what a prediction's band runs (:func:`tengsim.design.bands.predict_bands`)."""

    def shape_params_json(self) -> str:
        return json.dumps(self.shape_params, sort_keys=True)

    def shape_text(self) -> str:
        """'pitch 10 µm, base 5 µm, height 3.5 µm' (lengths in their unit, other numbers plain)."""
        from tengsim.units import length_text, pressure_text

        def each(v, text):  # a size may be a pair (a topography's physical_size): 'a × b'
            if isinstance(v, (tuple, list)):
                return " × ".join(each(x, text) for x in v)
            return text(v) if isinstance(v, (int, float)) and not isinstance(v, bool) else str(v)[:80]

        out = []
        for k, v in self.shape_params.items():
            if k.endswith("_m"):
                out.append(f"{k[:-2]} {each(v, length_text)}")
            elif k.endswith("_Pa"):
                out.append(f"{k[:-3]} {each(v, pressure_text)}")
            else:
                out.append(f"{k} {each(v, lambda x: f'{x:g}')}")
        return ", ".join(out)


def _own(table: dict) -> dict:
    from tengsim.schema import Table

    t = Table("design", design_fields())
    raw = {k: v for k, v in table.items() if k in t.fields and v not in (None, "")}
    return t.parse(raw, where="")


_SUFFIX = {"length": "_m", "pressure": "_Pa", "energy/area": "_J_m2"}


def _shape_params(shape: str, extra: dict) -> dict:
    """The shape's physical parameters as the run records them, SI with the unit in the name (pitch_m, slope)."""
    from tengsim.plugins import SHAPES
    from tengsim.shapes.base import physical_fields

    out = {}
    for f in physical_fields(SHAPES.get(shape)):
        key = f.name + _SUFFIX.get(f.dim, "")
        raw = extra.get(f.name + _SUFFIX.get(f.dim, "_input"))
        if raw is not None:
            out[key] = raw
    return out


def plan_design(table: dict, where: str = "", material=None) -> DesignPlan:
    """Validate a [design] table and build its :class:`DesignPlan` (no solving).  A bad value raises one
    :class:`tengsim.errors.TengsimError` line naming it in the user's units.  ``material``: a fitted
    :class:`tengsim.design.material.Material` whose values replace the table's and whose uncertainty points are
    planned too (``bands``), each within the design's own bounds, before anything runs."""
    if material is not None:
        merged = {**table, **material.values} if isinstance(table, dict) else table
        try:
            plan = _plan_design(merged, where)
        except TengsimError as exc:  # the design with the material's values: say both
            raise exc.reworded(suffix=f" (with the material of {material.where})") from None
        return dataclasses.replace(plan, bands=plan_bands(merged, material, where))
    return _plan_design(table, where)


def plan_bands(table: dict, material, where: str = "") -> tuple:
    """The :class:`DesignPlan` of each of ``material``'s uncertainty points: ``table`` (the design's, the
    material's values in it) with the point's values and no maps, within the design's own bounds; a bad point is
    one line naming it (what :func:`tengsim.design.bands.predict_bands` runs)."""
    return tuple(_plan_design({**table, **pt, "maps": False}, f"{where}{material.where} [[uncertainty.point]] "
                                                               f"{i + 1}: ") for i, pt in enumerate(material.points))


def _plan_design(table: dict, where: str) -> DesignPlan:
    from tengsim.run.keys import contact_table
    from tengsim.run.plan import plan_contact
    from tengsim.plugins import SHAPES

    if not isinstance(table, dict):
        raise TengsimError(f"{where}a design must be a table of keys, got {table!r}")
    shape = table.get("shape")
    if shape in (None, ""):
        raise ConfigValueError(f"{where}give the shape (one of {', '.join(SHAPES.names())})")
    if not isinstance(shape, str) or shape.strip().lower() not in [s.lower() for s in SHAPES.names()]:
        raise ConfigValueError(f"{where}unknown shape {shown(shape)} (shapes: {', '.join(SHAPES.names())})")
    shape = SHAPES.canonical(shape)
    own_names = {f.name for f in design_fields()}
    contact_keys = set(contact_table(shape, "physical").keys())
    refused = sorted(k for k in table if k in CONTROLLED and k not in own_names and table[k] not in (None, ""))
    if "tabor" in refused:
        raise ConfigValueError(f"{where}a design takes eps (the interaction range, a length such as '50nm'), "
                               "not tabor: the Tabor number is derived for each shape and printed")
    if refused:
        raise ConfigValueError(f"{where}{listed(refused)}: set by the design itself (the path extends until "
                               "p_max is reached; the grid is refined to tol)")
    unknown = sorted(k for k in table if k not in own_names and k not in contact_keys)
    if unknown:
        raise ConfigValueError(f"{where}shape {shape} has no key {listed(unknown)} (design keys: "
                               f"{', '.join(sorted(own_names))}; [contact] keys of {shape}: "
                               f"{', '.join(k for k in sorted(contact_keys) if k not in CONTROLLED)})")
    if table.get("eps") in (None, ""):
        raise ConfigValueError(f"{where}eps is missing: give the interaction range ε of the law, a length such as "
                               "'50nm' (docs/own_design.md, 'Choosing ε')")
    own = _own(table)
    cfg = {k: v for k, v in table.items() if k in contact_keys and k not in own_names and v not in (None, "")}
    cfg["shape"] = shape
    boundary_given = "boundary" in cfg
    solver_given = cfg.get("solver") not in (None, "", "auto")
    cfg.setdefault("boundary", "periodic")  # a pattern's design is the array it describes
    from tengsim.run.area import check_definition

    try:
        area = check_definition(own["area"])
    except TengsimError as exc:
        raise exc.reworded(prefix=where) from None
    checked = dict(cfg)  # after the boundary's default
    if table.get("dx") not in (None, ""):  # the grid checked at the design's own first dx, not the default's
        checked["dx"] = table["dx"]
    try:
        plan = plan_contact(checked)
    except TengsimError as exc:
        raise exc.reworded(prefix=where) from None
    if plan.scaling is None:
        raise ConfigValueError(f"{where}a design is physical: give the sizes of {shape} with units and E_star, W")
    pressures = _pressures(own, where)
    for k in ("sigma", "eps_r", "T", "gap"):
        if not own[k] > 0:
            raise ConfigValueError(f"{where}{k} must be > 0, got {shown(table.get(k))}")
        lo_k, hi_k, text = DEVICE_BOUNDS[k]
        if not lo_k <= own[k] <= hi_k:
            raise ConfigValueError(f"{where}{k} = {shown(table.get(k))} is outside {text}")
    from tengsim.run.tolerance import MAX_TOL

    tol = own["tol"]
    if isinstance(tol, bool) or not 0 < tol < MAX_TOL:
        raise ConfigValueError(f"{where}tol must be a fraction > 0 and < {MAX_TOL:g} (0.01 = 1 %), got "
                               f"{table.get('tol')!r}")
    if tol < TOL_FLOOR:
        raise ConfigValueError(f"{where}tol = {tol:g} is below {TOL_FLOOR:g}: the grids' discretisation error "
                               f"cannot be driven that low within any budget (give tol >= {TOL_FLOOR:g})")
    if own["name"] is not None and len(own["name"]) > MAX_NAME:
        raise ConfigValueError(f"{where}name is {len(own['name'])} characters long: at most {MAX_NAME}")
    if own["dx"] is not None and not own["dx"] > 0:
        raise ConfigValueError(f"{where}dx must be a length > 0, got {table.get('dx')!r}")
    if own["max_pixels"] is not None and own["max_pixels"] < 9:
        raise ConfigValueError(f"{where}max_pixels must be >= 9, got {table.get('max_pixels')!r}")
    if not own["budget"] > 0:
        raise ConfigValueError(f"{where}budget must be a time > 0, got {table.get('budget')!r}")
    sp = _shape_params(shape, plan.extra)
    sc = plan.scaling
    draft = DesignPlan("", shape, {}, sp, (), 0, 0, 0, 0, 0, None, None, 0, 0, 0, 0, 0)
    name = own["name"] or f"{shape} {draft.shape_text()}"
    own_solver = None if solver_given else constrained_solver(plan.law)
    pk = {"solver": own_solver} if own_solver else {}
    plan = dataclasses.replace(plan, solver_tol=SOLVER_TOL_PER_TOL * tol, **pk)  # the plan the design runs
    return DesignPlan(name=name, shape=shape, contact_table=cfg, shape_params=sp, pressures=pressures,
                      sigma=own["sigma"], eps_r=own["eps_r"], T=own["T"], gap=own["gap"], rel_tol=tol, dx_m=own["dx"],
                      max_pixels=own["max_pixels"], budget_s=own["budget"], E_star=sc.E_star,
                      W=sc.W, eps=sc.eps, tabor=sc.mu, maps=bool(own["maps"]), area=area,
                      retraction=bool(own["retraction"]), boundary=str(plan.boundary), boundary_given=boundary_given, solver_given=solver_given,
                      contact_plan=plan)


def _pressures(own: dict, where: str) -> tuple:
    """The pressures asked for (Pa), increasing: p_min, p_min + p_step, ..., p_max."""
    lo, hi, step = own["p_min"], own["p_max"], own["p_step"]
    if hi is None:
        raise ConfigValueError(f"{where}p_max is missing: give the highest nominal pressure, e.g. '100kPa'")
    if not hi > 0:
        raise ConfigValueError(f"{where}p_max must be a pressure > 0, got {hi / 1e3:g} kPa")
    if not 0 <= lo < hi:
        raise ConfigValueError(f"{where}p_min must be >= 0 and below p_max = {hi / 1e3:g} kPa, got {lo / 1e3:g} kPa")
    step = (hi - lo) / 20 if step is None else step
    if not step > 0:
        raise ConfigValueError(f"{where}p_step must be a pressure > 0, got {step / 1e3:g} kPa")
    n = int(math.floor((hi - lo) / step * (1 + 1e-9)))
    if n > 400:
        raise ConfigValueError(f"{where}p_step = {step / 1e3:g} kPa gives {n + 1} pressures: at most 401")
    ps = [lo + i * step for i in range(n + 1)]
    if hi - ps[-1] > 1e-9 * hi:
        ps.append(hi)
    return tuple(float(p) for p in ps)


def solver_tol(plan) -> float:
    """The solver's tolerance of a design (:data:`SOLVER_TOL_PER_TOL`)."""
    return SOLVER_TOL_PER_TOL * plan.rel_tol
