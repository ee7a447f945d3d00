"""Run descriptions: one [contact] table (CLI options or a TOML file) → the validated plan of a contact run.

The table's keys are :mod:`tengsim.run.keys`'s.  A physical run builds the shape's
:class:`tengsim.units.Scaling`; the core stays dimensionless.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from tengsim.kernels import film
from tengsim.errors import ConfigValueError, GeometryError, TengsimError, finite, positive, shown
from tengsim.laws import LJ93, make_law
from tengsim.continuation import PathSpec
from tengsim.plugins import KERNELS
from tengsim.run.tolerance import DEFAULT_TOL, check_tol
from tengsim.run.keys import (ADAPTIVE_KEYS, LOAD_KEYS, common_fields, common_names, contact_keys,
                              contact_table, law_fields, law_keys, physical_triggers, shape_class)
from tengsim.shapes.base import dimensionless_fields, physical_fields
from tengsim.shapes.roughened import roughen
from tengsim.units import Scaling, parse_quantity
from tengsim.solvers.types import SOLVER_TOL


_SUFFIX = {"length": "_m", "pressure": "_Pa", "energy/area": "_J_m2"}

_QUANTITY = {"E_star": "modulus"}
"""The plausibility range (tengsim.units.PLAUSIBLE) of a key, where it is not its dimension's."""


def _positive_as_given(cfg, names, vals) -> None:
    """Refuse a non-positive physical size or material constant naming the value as the user wrote it
    ('-2um', not its SI -2e-06); a key whose field takes 0 or less is left to its own checks."""
    for k in names:
        v = vals.get(k)
        raw = cfg.get(k)
        if isinstance(raw, str) and isinstance(v, (int, float)) and not isinstance(v, bool) and v <= 0:
            raise ConfigValueError(f"{k} must be > 0, got {shown(raw)}")


def _bare(v) -> bool:
    if isinstance(v, bool):
        return False
    if isinstance(v, (int, float)):
        return True
    if isinstance(v, str):
        from tengsim.units import read_number

        try:
            read_number(v)
        except TengsimError:
            return True  # a number, refused by its key's own reading
        except ValueError:
            return False
        return True
    return False


def _check_bare_numbers(cfg, phys) -> None:
    """Refuse a bare number (read as SI) outside the plausible range of its key's quantity (a physical run:
    'E_star = 0.59' is 0.59 Pa); a ConfigValueError naming the likely unit (tengsim.units.PLAUSIBLE)."""
    from tengsim.units import check_plausible

    fields = [f for f in common_fields() if f.dim] + [f for f in phys if f.dim]
    for f in fields:
        raw = cfg.get(f.name)
        items = raw if isinstance(raw, (list, tuple)) else [raw]
        for v in items:
            if _bare(v):
                check_plausible(f.name, v, _QUANTITY.get(f.name, f.dim))


def _maps_at(vals, scaling, control):
    """maps_at as numbers: D values (approach) or loads F of Eq. (10), a pressure converted (load)."""
    out = []
    for m in vals["maps_at"]:
        if control == "load":
            out.append(_load_F("maps_at", m, scaling))
        elif isinstance(m, str):
            raise TengsimError(f"maps_at = {m!r} has a unit: with control = 'approach' maps_at are D values in ε "
                               "(pressures with a unit are loads: control = 'load')")
        else:
            out.append(finite("maps_at", m))
    return tuple(out)


def _load_F(name, v, scaling):
    """A load key's value as F of Eq. (10): numbers as they are, a pressure p as p·cell area / force unit."""
    from tengsim.units import parse_quantity

    if not isinstance(v, str):
        return finite(name, v)
    if scaling is None:
        raise TengsimError(f"{name} = {v!r} has a unit, but this run is dimensionless: give {name} as F of "
                           "Eq. (10) (or the shape's physical sizes with E_star and W)")
    return finite(name, parse_quantity(v, "pressure", name=name) / scaling.pressure(1.0))


def _path_spec(vals, given, scaling):
    """The PathSpec (control = approach, fixed or adaptive) or LoadPathSpec (control = load) of a table."""
    control = vals["control"]
    if control == "load":
        bad = [k for k in ADAPTIVE_KEYS if k in given and (k != "adaptive" or vals[k])]
        if bad:
            raise TengsimError(f"{', '.join(bad)} {'does' if len(bad) == 1 else 'do'} not apply to control = "
                               "'load' (adaptive steps are a D-path option)")
        missing = [k for k in ("f_max", "f_step") if k not in given]
        if missing:
            raise TengsimError(f"control = 'load' needs {', '.join(missing)}")
        from tengsim.continuation import LoadPathSpec

        f = {k: _load_F(k, vals[k], scaling) for k in LOAD_KEYS if vals[k] is not None}
        kw = {"d_min": vals["d_min"], "d_step": vals["d_step"], "to_max": True}  # the path ends at f_max
        if "d_max" in given:  # else LoadPathSpec's wider search range
            kw["d_max"] = vals["d_max"]
        if scaling is not None:  # a physical run: the approach extends itself to the loads asked for (no d_max
            # to guess), and its errors name loads in Pa and D in metres
            kw.update(extend="d_max" not in given, pa_per_F=scaling.pressure(1.0), eps_m=scaling.eps)
        return LoadPathSpec(f.get("f_min", 0.0), f["f_max"], f["f_step"], refine_levels=vals["refine_levels"],
                            maps_at=_maps_at(vals, scaling, control), **kw)
    bad = [k for k in LOAD_KEYS if k in given]
    if bad:
        raise TengsimError(f"{', '.join(bad)} {'does' if len(bad) == 1 else 'do'} not apply to control = "
                           "'approach' (give control = 'load')")
    if "adapt_tol" in given and not vals["adaptive"]:
        raise TengsimError("adapt_tol applies only with adaptive = true")
    kw = {"adaptive": True} if vals["adaptive"] else {}
    if vals["adapt_tol"] is not None:
        kw["adapt_tol"] = vals["adapt_tol"]
    return PathSpec(vals["d_min"], vals["d_max"], vals["d_step"], maps_at=_maps_at(vals, scaling, control),
                    refine_levels=vals["refine_levels"], **kw)


def _check_maps_out(maps_at, out) -> None:
    """Refuse maps asked for with an output that cannot hold them (a .csv holds the curves only)."""
    if maps_at and isinstance(out, str) and out.lower().endswith(".csv"):
        raise TengsimError(f"maps_at = {', '.join(f'{m:g}' for m in maps_at)} needs a .nc output: out = {out!r} "
                           "holds the curves only")


def coupling(tabor) -> float:
    """The elastic coupling μ^{3/2} of Eq. (9) for the Tabor parameter μ = ``tabor`` (> 0, else a TengsimError)."""
    return positive("tabor", tabor) ** 1.5


def check_max_pixels(v) -> int:
    """max_pixels: a whole number of pixels nx·ny >= 9 (a ConfigValueError naming it otherwise)."""
    if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or int(v) < 9:
        raise ConfigValueError(f"max_pixels must be >= 9 (a whole number of pixels nx·ny), got {v!r}")
    return int(v)


DEFAULT_RESOLVE_TOL = DEFAULT_TOL
"""resolve_tol when a table does not give one (:data:`tengsim.run.tolerance.DEFAULT_TOL`)."""


@dataclass(frozen=True)
class ResolveSettings:
    """The automatic refinement of a run (``resolve = 'auto'``, :mod:`tengsim.run.resolve`), checked when built.

    ``rel_tol`` the relative tolerance of the observables; ``max_pixels`` the largest grid nx·ny (None: what the
    free memory holds); ``dx`` the first grid's spacing in X units (None: a coarse default); ``pressures`` the
    nominal pressures (Pa) at which A/S must converge too (physical runs; () if none)."""

    rel_tol: float = DEFAULT_RESOLVE_TOL
    max_pixels: int | None = None
    dx: float | None = None
    pressures: tuple = ()

    def __post_init__(self):
        object.__setattr__(self, "rel_tol", check_tol(self.rel_tol))
        if self.max_pixels is not None:
            object.__setattr__(self, "max_pixels", check_max_pixels(self.max_pixels))
        if self.dx is not None:
            object.__setattr__(self, "dx", positive("dx", self.dx))
        object.__setattr__(self, "pressures", tuple(float(p) for p in self.pressures))


@dataclass(frozen=True)
class ContactPlan:
    """Everything a contact run needs, validated: built once from a [contact] table (:func:`plan_contact`) or
    directly from API objects (``ContactPlan(shape, tabor, dx, path, ...)``); nothing downstream reads a config dict.

    ``tabor`` μ (> 0; :attr:`coupling` is μ^{3/2}); ``law`` an object or registered name (None: the paper's
    LJ93); ``boundary`` a registered kernel; ``solver`` a registered name or a solver object; ``grid`` the
    shape's grid of spacing about ``dx`` unless given (then the run's is the grid's); ``resolve`` the refinement
    settings (None: one grid); ``config`` the table the plan was read from (without out and plot), kept in
    the result's parameters.  The plan is pure: ``solver`` 'auto' stays 'auto' here, chosen for each grid that is
    solved (:func:`chosen_solver`), never probed for on a grid a refinement may not solve."""

    shape: object
    tabor: float
    dx: float
    path: object  # PathSpec or tengsim.continuation.load.LoadPathSpec
    boundary: str = "free"
    solver: object = "fast"
    solver_tol: float = SOLVER_TOL
    law: object = None
    extra: dict = field(default_factory=dict)
    scaling: Scaling | None = None
    observers: tuple = ()
    kernel_params: dict = field(default_factory=dict)
    resolve: ResolveSettings | None = None
    symmetry: str = "auto"
    grid: object = None
    config: dict = field(default_factory=dict)

    def __post_init__(self):
        mu = positive("tabor", self.tabor)
        grid = self.grid if self.grid is not None else self.shape.grid(self.dx)  # validates dx against the cell
        if self.scaling is not None and abs(self.scaling.mu - mu) > 1e-9 * mu:
            raise TengsimError(f"tabor = {mu:g} does not match the scaling's μ = {self.scaling.mu:g}")
        law = make_law(self.law) if isinstance(self.law, str) else (self.law or LJ93())
        for k, v in (("tabor", mu), ("law", law), ("boundary", KERNELS.canonical(self.boundary)), ("grid", grid),
                     ("extra", dict(self.extra or {})), ("observers", tuple(self.observers or ())),
                     ("kernel_params", dict(self.kernel_params or {})), ("config", dict(self.config or {}))):
            object.__setattr__(self, k, v)

    @property
    def coupling(self) -> float:
        """μ^{3/2}, the elastic coupling of Eq. (9)."""
        return coupling(self.tabor)


def chosen_solver(plan: ContactPlan, grid=None) -> tuple:
    """(the solver a run of ``plan`` on ``grid`` uses, the sentence that says why, '' unless 'auto' chose it):
    'auto' chosen on that grid's points (:func:`tengsim.run.choice.choose`: the GPU above its break-even
    where JAX sees one); ``grid`` None: the plan's own.  Every run of one grid asks here, and says the sentence
    where it solves (one grid, or each grid of a refinement whose choice changes)."""
    from tengsim.run.choice import choose

    g = plan.grid if grid is None else grid
    return choose(plan.solver, points=g.nx * g.ny)


def as_plan(plan) -> ContactPlan:
    """``plan`` itself if it is a :class:`ContactPlan`, else the plan of the [contact] table ``plan``."""
    return plan if isinstance(plan, ContactPlan) else plan_contact(plan)


def _dx(raw, lateral, name="dx"):
    """A length in X units (dx, thickness): a number, or (physical runs only) a length with a unit."""
    if isinstance(raw, str):
        from tengsim.units import read_number

        try:
            number = read_number(raw, name)
        except TengsimError:
            raise
        except ValueError:
            number = None
        if number is not None:
            return positive(name, number)
        if lateral is None:
            raise ConfigValueError(f"{name} = {shown(raw)} has a unit, but this run is dimensionless: give {name} in X "
                                   "units (or the shape's physical sizes with E_star and W)")
        return positive(name, parse_quantity(raw, "length", name=name) / lateral)
    if isinstance(raw, bool) or not isinstance(raw, (int, float)):
        raise ConfigValueError(f"{name} must be a number, got {shown(raw)}")
    from tengsim.units import read_number

    return positive(name, read_number(raw, name))


def _film(cfg, vals, lateral, extra) -> dict:
    """Kernel parameters of a film (empty for the half-space); its thickness in X units."""
    raw = cfg.get("thickness")
    if raw in (None, ""):
        given = [k for k in ("substrate", "poisson") if cfg.get(k) not in (None, "")]
        if given:
            raise TengsimError(f"{' and '.join(given)} {'describe' if len(given) > 1 else 'describes'} a film: "
                               "give its thickness too "
                               "(without one the elastic body is a half-space)")
        return {}
    t = _dx(raw, lateral, "thickness")
    t, substrate, nu = film.check_film(t, vals["substrate"], vals["poisson"])
    if lateral is not None:
        extra["thickness_m"] = t * lateral
    return {"thickness": t, "substrate": substrate, "poisson": nu}


def _build(cls, name, kw):
    try:
        return cls(**kw)
    except TypeError as exc:
        raise TengsimError(f"shape {name}: {exc}") from None


def _build_law(name, kw):
    """The law ``name`` with the given keys (the rest: its own defaults); its own check of the values."""
    try:
        return make_law(name, **kw)
    except (TypeError, ValueError) as exc:
        raise TengsimError(f"law {name}: {exc}") from None


def _cell_area_m2(cls, p, shape, lateral) -> float:
    """The cell's area in m²: the shape's own (``cell_area_si``, exact from its SI input) or its
    dimensionless cell area times ℓ²."""
    own = getattr(cls, "cell_area_si", None)
    if own is not None:
        return own(p)
    return getattr(shape, "cell_area", shape.cell**2) * lateral**2


def _metres(v: float) -> str:
    """A length in metres as the user reads it ('24 µm'): for :meth:`GeometryError.in_metres`."""
    from tengsim.units import format_si

    return format_si(v, "m")


def plan_contact(cfg: dict) -> ContactPlan:
    """Validate a [contact] table and build its pieces (no solving)."""
    if not isinstance(cfg, dict):
        raise TengsimError(f"[contact] must be a table, got {cfg!r}")
    name, cls = shape_class(cfg.get("shape") or "pyramid")
    full = contact_table(name)
    all_law_keys = law_keys()
    unknown = [k for k in cfg if k not in full]
    if unknown:
        from tengsim.errors import listed

        every = set(contact_keys())  # once: a file of 16 000 unknown keys is checked in linear time
        others = [k for k in unknown if k in every]
        if others:
            own = [k for k in full.keys() if k not in common_names() and k not in all_law_keys]
            raise TengsimError(f"shape {name} has no key {listed(others)} (its keys: {', '.join(own)})")
        raise TengsimError(f"[contact] unknown key(s) {listed(unknown)} "
                           f"(known: {', '.join(full.keys())})")
    dims, phys = dimensionless_fields(cls), physical_fields(cls)
    dim_names, phys_names = [f.name for f in dims], [f.name for f in phys]
    given = {k for k, v in cfg.items() if v is not None and v != ""}
    law_name = full.fields["law"].parse(cfg.get("law") or "lj93", "[contact] ")
    lfields = law_fields(law_name)
    wrong = [k for k in cfg if k in given and k in all_law_keys and k not in {f.name for f in lfields}]
    if wrong:
        raise TengsimError(f"law {law_name} has no key {', '.join(map(repr, wrong))} "
                           f"(its keys: {', '.join(f.name for f in lfields) or 'none'})")
    triggers = physical_triggers(given, dim_names, phys_names)
    extra, scaling, lateral = {}, None, None
    if triggers:
        if not phys:
            raise TengsimError(f"shape {name} has no physical input ({', '.join(triggers)} given): "
                               f"give its dimensionless keys {', '.join(dim_names)}")
        mixed = sorted(given & (set(dim_names) - set(phys_names)))
        if mixed:
            raise TengsimError(f"{name}: {', '.join(mixed)} {'is' if len(mixed) == 1 else 'are'} dimensionless but "
                               f"{', '.join(triggers)} make this a physical run; give {', '.join(phys_names)} "
                               "with units instead (do not mix the two)")
        missing = [k for k in ("E_star", "W") if k not in given]
        missing += [f.name for f in phys if f.required and f.name not in given]
        if missing:
            raise TengsimError(f"physical {name} input needs {', '.join(missing)}")
        vals = contact_table(name, "physical", law_name).parse(cfg)
        _check_bare_numbers(cfg, phys)
        _positive_as_given(cfg, ["E_star", "W", "eps", *(f.name for f in phys if f.dim and not (
            isinstance(f.default, (int, float)) and not isinstance(f.default, bool) and f.default <= 0))], vals)
        E, W = positive("E_star", vals["E_star"]), positive("W", vals["W"])
        p = {f.name: vals[f.name] for f in phys}
        if vals["eps"] is not None and vals["tabor"] is not None:
            raise TengsimError("give either eps or tabor, not both")
        if vals["eps"] is not None:
            eps = positive("eps", vals["eps"])
        elif vals["tabor"] is not None:
            eps = cls.eps_from_tabor(p, E, W, vals["tabor"])  # the shape checks μ > 0
        else:
            raise TengsimError(f"physical {name} input needs eps or tabor (tabor has no default in a physical run)")
        lateral = positive("lateral scale", cls.lateral_scale(p, eps))
        try:
            shape = cls.from_si(p, eps)
        except GeometryError as exc:  # said in metres, as the sizes were given
            raise exc.in_metres(lateral, _metres) from None
        scaling = Scaling(E, W, eps, lateral, _cell_area_m2(cls, p, shape, lateral))
        tabor = scaling.mu
        if vals["tabor"] is not None and abs(tabor - vals["tabor"]) > 1e-8 * vals["tabor"]:
            raise TengsimError(f"could not solve eps for tabor = {vals['tabor']:g} (got μ = {tabor:g})")
        extra.update({f"{f.name}{_SUFFIX.get(f.dim, '_input')}": p[f.name] for f in phys if p[f.name] is not None})
        extra.update(scaling.params())
        extra["lateral_m"] = lateral
    else:
        if not dims and phys:
            raise TengsimError(f"shape {name} has physical input only: give {', '.join(phys_names)} "
                               "with E_star, W and eps or tabor")
        missing = [f.name for f in dims if f.required and f.name not in given]
        if missing:
            raise TengsimError(f"{name} needs {', '.join(missing)} (dimensionless)"
                               + (f" or {', '.join(phys_names)} with E_star, W and eps or tabor (physical)"
                                  if phys_names else ""))
        vals = contact_table(name, "dimensionless", law_name).parse(cfg)
        tabor = 0.5 if vals["tabor"] is None else vals["tabor"]  # checked by ContactPlan
        shape = _build(cls, name, {f.name: vals[f.name] for f in dims if vals[f.name] is not None})
    shape, rough_extra = roughen(shape, vals, given, scaling)  # roughness = true: Roughened(shape, ...)
    extra.update(rough_extra)
    raw_dx = cfg.get("dx")  # not given: the shape's own pixel (a height map's) or 0.1
    dx = _dx(raw_dx, lateral) if raw_dx not in (None, "") else getattr(shape, "native_dx", 0.1)
    kernel_params = _film(cfg, vals, lateral, extra)
    refuse_unused = getattr(cls, "refuse_unused", None)
    if refuse_unused is not None:  # keys this variant of the shape does not use (an array without scatter: seed)
        refuse_unused(vals, given)
    path = _path_spec(vals, given, scaling)
    _check_maps_out(path.maps_at, cfg.get("out"))
    tol = positive("tol", vals["tol"])
    law = _build_law(law_name, {f.name: vals[f.name] for f in lfields if f.name in given})
    try:
        grid = shape.grid(dx)  # validates dx against the cell
    except GeometryError as exc:
        raise (exc.in_metres(lateral, _metres) if lateral is not None else exc) from None
    from tengsim.run.memory import check_memory

    if kernel_params.get("thickness") is not None:  # a film thinner than its pixel allows: refused now
        film.check_film_pixels(kernel_params["thickness"], max(grid.dx, grid.dy), lateral)
    resolve = _resolve(vals, given, dx if raw_dx not in (None, "") else None, scaling)
    if resolve is None:  # the plan's grid is the grid solved; a refinement checks each of its own grids
        check_memory(grid.nx, grid.ny, vals["boundary"], vals["solver"], maps=2 * len(path.maps_at))
    if isinstance(vals["solver"], str) and vals["solver"].strip().lower() == "gpu":
        from tengsim.run.choice import choose

        choose("gpu")  # asked for by name and absent here: refused before anything runs
    return ContactPlan(shape, tabor, dx, path, vals["boundary"], vals["solver"], tol, law, extra, scaling,
                       tuple(vals["observers"]), kernel_params, symmetry=vals["symmetry"], resolve=resolve,
                       grid=grid, config={k: v for k, v in cfg.items() if k not in ("out", "plot")})


def _resolve(vals, given, dx, scaling=None) -> ResolveSettings | None:
    """The refinement settings of a table: None for resolve = off (resolve_tol, max_pixels, resolve_pressures
    refused there), else its :class:`ResolveSettings` (pressures: physical runs only)."""
    if vals["resolve"] != "auto":
        bad = [k for k in ("resolve_tol", "max_pixels", "resolve_pressures") if k in given]
        if bad:
            raise ConfigValueError(f"{' and '.join(bad)} {'apply' if len(bad) > 1 else 'applies'} only with "
                                   "resolve = 'auto'")
        return None
    pressures = tuple(vals["resolve_pressures"] or ())
    if "resolve_pressures" in given:
        if scaling is None:
            raise ConfigValueError("resolve_pressures applies only to a physical run (E_star, W and the shape's "
                                   "sizes with units): a dimensionless run has no pressure")
        bad = [p for p in pressures if not p > 0]
        if bad or not pressures:
            raise ConfigValueError(f"resolve_pressures must be pressures > 0, got {vals['resolve_pressures']!r}")
    tol = DEFAULT_RESOLVE_TOL if vals["resolve_tol"] is None else vals["resolve_tol"]
    return ResolveSettings(tol, vals["max_pixels"], dx, pressures)
