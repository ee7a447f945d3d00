"""Run descriptions: one [contact] table (CLI options or a TOML file) → the API objects of a contact run.

The table's keys come from the registries and the schema, never from a list kept here: the shape's
dimensionless fields (its dataclass fields, plain numbers) *or* its physical fields (numbers in SI
or unit strings such as '2um') with ``E_star``, ``W`` and ``eps`` or ``tabor``; then the grid, the
path, and the boundary, solver, law and observers by registered name, with the chosen law's own
parameters (its fields, :func:`law_fields`: plain numbers in units of W and ε).  A physical run builds
the shape's :class:`tengsim.units.Scaling`; the core stays dimensionless.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

from tengsim.kernels import film
from tengsim.errors import ConfigValueError, TengsimError, finite, positive, shown
from tengsim.laws import make_law
from tengsim.continuation import PathSpec
from tengsim.plugins import KERNELS, LAWS, OBSERVERS, SHAPES, SOLVERS
from tengsim.schema import Field, Table, dataclass_fields, signature_fields
from tengsim.shapes.base import dimensionless_fields, physical_fields
from tengsim.shapes.roughened import LENGTH_KEYS as _ROUGHNESS_LENGTHS, roughen, roughness_fields
from tengsim.units import Scaling, number_or_text, parse_quantity

PHYSICAL_KEYS = ("E_star", "W", "eps")
"""Keys that make a [contact] table a physical run (with any physical-only key of the shape)."""

_SUFFIX = {"length": "_m", "pressure": "_Pa", "energy/area": "_J_m2"}

X_UNIT_KEYS = {"dx": "length", "thickness": "length", "f_min": "pressure", "f_max": "pressure", "f_step": "pressure"}
"""Keys whose bare number is *not* SI (dx, thickness in X units; loads as F of Eq. 10), with the dimension a
unit string gives them in a physical run."""
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


def _physical_triggers(given, dim_names, phys_names) -> list:
    """The given keys that make a [contact] table a physical run."""
    return sorted(set(given) & (set(PHYSICAL_KEYS) | (set(phys_names) - set(dim_names))))


def key_dims(cfg: dict) -> dict:
    """{key: (dimension, bare number is SI)} of the quantity keys of the run a [contact] table describes.

    Empty for a dimensionless run (every number plain, lengths in X units) or an unknown shape (which
    :func:`plan_contact` reports).  In a physical run: E_star, W, eps and the shape's physical fields
    with a dimension (a bare number is SI), and dx, thickness, f_min, f_max, f_step (a bare number is in
    X units or F: :data:`X_UNIT_KEYS`).  Study expressions read it to give their SI value its unit."""
    try:
        _, cls = _shape_cls(cfg.get("shape") or "pyramid")
    except (TengsimError, KeyError, ValueError):
        return {}
    dims, phys = dimensionless_fields(cls), physical_fields(cls)
    given = {k for k, v in cfg.items() if v is not None and v != ""}
    if not phys or not _physical_triggers(given, [f.name for f in dims], [f.name for f in phys]):
        return {}
    out = {f.name: (f.dim, True) for f in common_fields() if f.dim}
    out.update({k: (d, False) for k, d in X_UNIT_KEYS.items()})
    out.update({k: ("length", False) for k in _ROUGHNESS_LENGTHS})  # bare: ε or X units, as dx
    out.update({f.name: (f.dim, True) for f in phys if f.dim})
    return out


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


def _observer_names(v):
    if isinstance(v, str):
        v = [s for s in (x.strip() for x in v.split(",")) if s]
    if not isinstance(v, (list, tuple)) or not all(isinstance(x, str) for x in v):
        raise TengsimError(f"observers must be a list of names, got {v!r}")
    return tuple(OBSERVERS.canonical(x) for x in v)


RESOLVE_CHOICES = ("off", "auto")
"""resolve: one grid (off) or automatic refinement (auto, tengsim.resolve)."""

CONTROLS = ("approach", "load")
"""Path controls of a [contact] table: the rigid approach D (PathSpec) or the load F (LoadPathSpec)."""

_LOAD_KEYS = ("f_min", "f_max", "f_step")
_ADAPTIVE_KEYS = ("adaptive", "adapt_tol")


def _load_value(v, label="load"):
    """A load key: a number (F of Eq. 10) or a string, a number or a pressure with a unit (checked later)."""
    return number_or_text(v, label, "a pressure")


def _maps_values(v, label="maps_at"):
    """maps_at: a list (or comma-separated text) of numbers, or pressures with a unit (control = load)."""
    items = v
    if isinstance(v, str):
        items = [t for t in v.split(",") if t.strip()]
    elif isinstance(v, (int, float)) and not isinstance(v, bool):
        items = [v]
    if not isinstance(items, (list, tuple)):
        raise TengsimError(f"{label} must be a list of numbers (or of pressures with a unit), got {v!r}")
    return tuple(number_or_text(x, label, "a pressure") for x in items)


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
        bad = [k for k in _ADAPTIVE_KEYS if k in given and (k != "adaptive" or vals[k])]
        if bad:
            raise TengsimError(f"{', '.join(bad)} {'does' if len(bad) == 1 else 'do'} not apply to control = "
                               "'load' (adaptive steps are a D-path option)")
        missing = [k for k in ("f_max", "f_step") if k not in given]
        if missing:
            raise TengsimError(f"control = 'load' needs {', '.join(missing)}")
        from tengsim.continuation import LoadPathSpec

        f = {k: _load_F(k, vals[k], scaling) for k in _LOAD_KEYS if vals[k] is not None}
        kw = {"d_min": vals["d_min"], "d_step": vals["d_step"], "to_max": True}  # the path ends at f_max
        if "d_max" in given:  # else LoadPathSpec's wider search range
            kw["d_max"] = vals["d_max"]
        if scaling is not None:  # a physical run: the approach extends itself to the loads asked for (no d_max
            # to guess), and its errors name loads in Pa and D in metres
            kw.update(extend="d_max" not in given, pa_per_F=scaling.pressure(1.0), eps_m=scaling.eps)
        return LoadPathSpec(f.get("f_min", 0.0), f["f_max"], f["f_step"], refine_levels=vals["refine_levels"],
                            maps_at=_maps_at(vals, scaling, control), **kw)
    bad = [k for k in _LOAD_KEYS if k in given]
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


def common_fields() -> list:
    """The [contact] keys every shape has (choices and help read from the registries)."""
    from tengsim.continuation import LoadPathSpec

    return [
        Field("shape", "str", "pyramid", check=SHAPES.canonical,
              help="registered shape: " + SHAPES.help()),
        Field("tabor", help="Tabor parameter μ (coupling μ^{3/2}); dimensionless runs: default 0.5; "
              "physical runs: no default, give tabor or eps"),
        Field("E_star", dim="pressure", help="effective modulus E* (physical run; a bare number is Pa, 100 to 1e12)"),
        Field("W", dim="energy/area", help="work of adhesion W (physical run; a bare number is J/m2, 1e-6 to 10)"),
        Field("eps", dim="length",
              help="interaction range ε (physical run; or give tabor; a bare number is m, 1e-12 to 1)"),
        Field("dx", "any", 0.1, help="grid spacing in X units; in a physical run also a length, e.g. '20nm'"),
        Field("d_min", default=-1.0, help="first rigid approach D of the path, in ε"),
        Field("d_max", default=4.0, help="last rigid approach D, in ε (control = load: the search range of D, "
              f"default {LoadPathSpec.d_max:g}; a physical run without d_max extends it until the loads are met)"),
        Field("d_step", default=0.05, help="step in D, in ε"),
        Field("refine_levels", "int", 4, help="step bisections before a change is called a jump"),
        Field("maps_at", "any", (), check=_maps_values,
              help="D values (control = load: loads F, or in a physical run nominal pressures with a unit, e.g. "
              "'50kPa') whose pressure and gap maps "
              "are kept, on both branches, exactly there (a value between the path's rows gets a row of its "
              "own; one outside the path is refused); needs a .nc out"),
        Field("control", "str", "approach", choices=CONTROLS,
              help="path control: approach (rigid approach D, Eq. 9) or load (total force F of Eq. 10, "
              "D an unknown)"),
        Field("f_min", "any", None, check=_load_value,
              help="control = load: first load, F of Eq. (10) per cell (default 0); in a physical run "
              "also a nominal pressure with a unit, e.g. '-2kPa'"),
        Field("f_max", "any", None, check=_load_value, help="control = load: largest load (as f_min), the "
              "path's last (a shorter last step if f_max - f_min is no multiple of f_step)"),
        Field("f_step", "any", None, check=_load_value, help="control = load: load step (as f_min)"),
        Field("adaptive", "bool", False, help="control = approach: adaptive steps in D (d_step the largest)"),
        Field("adapt_tol", "float", None, help="adaptive: force error tolerance of a step (PathSpec default 0.15)"),
        Field("boundary", "str", "free", choices=KERNELS.names, help="elastic kernel: " + KERNELS.help()),
        Field("thickness", "any", None,
              help="film thickness on a rigid substrate (default: half-space), in X units; in a physical run "
              "also a length, e.g. '400um'"),
        Field("substrate", "str", "bonded", choices=film.SUBSTRATES,
              help="film on its substrate: bonded (no slip) or frictionless (needs thickness)"),
        Field("poisson", default=0.5, help="Poisson ratio ν of the film, -1 < ν <= 0.5; E* keeps its meaning, "
              "E = E*(1 - ν²) (needs thickness)"),
        Field("solver", "str", "fast", choices=SOLVERS.names, help="solver: " + SOLVERS.help()),
        Field("tol", default=1e-6, help="max residual of Eq. (9) in ε"),
        Field("symmetry", "str", "auto", choices=("auto", "off"),
              help="auto: solve on the irreducible quarter (half) of the cell when the shape and its grid are "
              "mirror symmetric (same answer, less time and memory); off: always the full grid"),
        Field("law", "str", "lj93", check=LAWS.canonical, help="interaction law: " + LAWS.help()),
        Field("observers", "any", (), check=_observer_names,
              help="extra observers adding columns: "
              + ("; ".join(f"{n}: {OBSERVERS.summary(n)}" for n in OBSERVERS.names() if n != "summary")
                 or "none registered (F, Λc, areas, gaps, pressures are always there)")),
        *roughness_fields(),  # a roughness superimposed on the shape (tengsim.shapes.roughened)
        Field("resolve", "str", "off", choices=RESOLVE_CHOICES,
              help="auto: refine the grid (dx/√2 per level, from dx or a coarse default) until every equilibrium "
              "is ok and the observables changed by at most resolve_tol (tengsim.resolve); off: the one grid dx"),
        Field("resolve_tol", "float", None, help="resolve = auto: relative tolerance of the observables, "
              "> 0 and < 1 (default 0.01)"),
        Field("max_pixels", "int", None, help="resolve = auto: largest grid nx·ny, >= 9 (default: what the "
              "free memory holds)"),
        Field("resolve_pressures", "floats", None, dim="pressure",
              help="resolve = auto, physical run: nominal pressures (with a unit, e.g. '10kPa'; a bare number is "
              "Pa) at which the charged-area fraction A/S (and so V_OC, Eq. 12) must converge too; a study "
              "sets its [observables] pressures here"),
        Field("out", "str", None, help="output file, .csv or .nc"),
        Field("plot", "str", None, help="figure of F(D), Λc(D), Λc(F), .png/.pdf/.svg"),
    ]


def _shape_cls(name):
    if not isinstance(name, str):
        raise TengsimError(f"shape must be a name, got {name!r}")
    return SHAPES.canonical(name), SHAPES.get(name)


def law_fields(law) -> tuple:
    """A law's [contact] keys: its dataclass fields (or constructor arguments) less the numerical guards it
    names in ``internal_fields`` (g_safe); plain numbers in units of W and ε (help from ``field_help``).

    ``law`` is a registered name or the registered class (factory); the defaults are the law's own.
    """
    cls = LAWS.get(law) if isinstance(law, str) else law
    skip = tuple(getattr(cls, "internal_fields", ()) or ())
    helps = getattr(cls, "field_help", None) or {}
    if not dataclasses.is_dataclass(cls):
        return signature_fields(cls, skip, helps)
    return dataclass_fields(cls, skip, helps)


def _default_text(f) -> str:
    if f.required:
        return "required"
    return f"default {f.default:.6g}" if isinstance(f.default, float) else f"default {f.default!r}"


def _field_help(name, f) -> str:
    return f.help or f"parameter of law {name}, in units of W and ε"


def law_keys() -> dict:
    """{key: [(law name, Field), ...]}: every registered law's [contact] keys, and the laws having each.

    A law key may not be a common [contact] key (a TengsimError names the clash); several laws may share
    one (md and exp: wall_stiffness)."""
    common = {f.name for f in common_fields()}
    out = {}
    for name in LAWS.names():
        for f in law_fields(name):
            if f.name in common:
                raise TengsimError(f"law {name} field {f.name!r} clashes with the [contact] key of that name")
            out.setdefault(f.name, []).append((name, f))
    return out


def law_key_help(entries) -> str:
    """One help text for a law key shared by ``entries`` [(law, Field)]: its text, the laws and defaults."""
    groups = {}
    for name, f in entries:
        groups.setdefault(_field_help(name, f), []).append(f"{name}: {_default_text(f)}")
    return "; ".join(f"{h} [law {', '.join(laws)}]" for h, laws in groups.items())


def contact_table(shape: str = "pyramid", mode: str | None = None, law: str | None = None) -> Table:
    """The schema of a [contact] table for ``shape`` (and ``law``).

    ``mode`` 'dimensionless' or 'physical' gives the table a run of that kind is parsed with; None
    (default) every key the shape accepts in either (for docs, the sweep and the CLI).  ``law`` (a
    registered name) adds that law's keys with its defaults; None the keys of every registered law
    (no defaults: each law has its own).  A shape or law key named like another key is an error.
    """
    name, cls = _shape_cls(shape)
    common = common_fields()
    taken = {f.name for f in common}
    dims, phys = dimensionless_fields(cls), physical_fields(cls)
    for f in (*dims, *phys):
        if f.name in taken:
            raise TengsimError(f"shape {name} field {f.name!r} clashes with the [contact] key of that name")
    keys = law_keys()  # every law's: a clash with a shape key is an error whichever law a run picks
    for f in (*dims, *phys):
        if f.name in keys:
            raise TengsimError(f"law {keys[f.name][0][0]} field {f.name!r} clashes with the key of that name "
                               f"of shape {name}")
    if law is None:
        laws = [Field(k, entries[0][1].kind, None, help=law_key_help(entries)) for k, entries in keys.items()]
    else:
        lname = LAWS.canonical(law)
        laws = [dataclasses.replace(f, help=_field_help(lname, f) + f" [law {lname}]") for f in law_fields(lname)]
    if mode == "dimensionless":
        fields = [*common, *dims, *laws]
    elif mode == "physical":
        fields = [*common, *phys, *laws]
    elif mode is None:
        merged = {f.name: dataclasses.replace(f, default=None) if f.required else f for f in dims}
        for f in phys:
            d = merged.get(f.name)
            if d == f:  # the same field in both: keep it as it is
                continue
            if d is None:
                merged[f.name] = dataclasses.replace(f, default=None)
            else:  # same name in both: a plain number, or a quantity in a physical run
                h = d.help if d.help == f.help or not f.dim else f"{d.help} (dimensionless) / {f.help} (physical)"
                merged[f.name] = Field(f.name, "float", None, dim=f.dim, help=h)
        fields = [*common, *merged.values(), *laws]
    else:
        raise TengsimError(f"mode must be 'dimensionless', 'physical' or None, got {mode!r}")
    return Table("contact", fields, doc=f"shape {name}")


def contact_keys() -> tuple:
    """Every key a [contact] table may hold for some registered shape and law (the CLI's option set)."""
    keys = [f.name for f in common_fields()]
    for s in SHAPES.names():
        for k in contact_table(s).keys():
            if k not in keys:
                keys.append(k)
    return tuple(keys)


@dataclass
class ContactPlan:
    """Everything a contact run needs, built and validated from a config dict."""

    shape: object
    tabor: float
    dx: float
    path: object  # PathSpec or tengsim.loadpath.LoadPathSpec
    boundary: str
    solver: str
    tol: float
    law: object
    extra: dict = field(default_factory=dict)
    scaling: Scaling | None = None
    observers: tuple = ()
    kernel_params: dict = field(default_factory=dict)
    resolve: dict = field(default_factory=dict)  # resolve = auto: {resolve, resolve_tol, max_pixels, dx (start)}
    symmetry: str = "auto"


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


def plan_contact(cfg: dict) -> ContactPlan:
    """Validate a [contact] table and build its pieces (no solving)."""
    if not isinstance(cfg, dict):
        raise TengsimError(f"[contact] must be a table, got {cfg!r}")
    name, cls = _shape_cls(cfg.get("shape") or "pyramid")
    full = contact_table(name)
    all_law_keys = law_keys()
    unknown = [k for k in cfg if k not in full]
    if unknown:
        from tengsim.errors import listed

        every = set(contact_keys())  # once: a file of 16 000 unknown keys is checked in linear time
        others = [k for k in unknown if k in every]
        if others:
            own = [k for k in full.keys() if k not in _common_names() and k not in all_law_keys]
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
    triggers = _physical_triggers(given, dim_names, phys_names)
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
            eps = cls.eps_from_tabor(p, E, W, positive("tabor", vals["tabor"]))
        else:
            raise TengsimError(f"physical {name} input needs eps or tabor (tabor has no default in a physical run)")
        lateral = positive("lateral scale", cls.lateral_scale(p, eps))
        shape = cls.from_si(p, eps)
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
        tabor = positive("tabor", 0.5 if vals["tabor"] is None else vals["tabor"])
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
    grid = shape.grid(dx)  # validates dx against the cell
    from tengsim.resources import check_memory

    check_memory(grid.nx, grid.ny, vals["boundary"], vals["solver"], maps=2 * len(path.maps_at))
    resolve = _resolve(vals, given, dx if raw_dx not in (None, "") else None, scaling)
    return ContactPlan(shape, tabor, dx, path, vals["boundary"], vals["solver"], tol, law, extra, scaling,
                       tuple(vals["observers"]), kernel_params, symmetry=vals["symmetry"], resolve=resolve)


def _resolve(vals, given, dx, scaling=None) -> dict:
    """The refinement settings of a table: {} for resolve = off (resolve_tol, max_pixels, resolve_pressures
    refused there), else resolve, resolve_tol (default 0.01), max_pixels (None: the free memory's), the start dx
    (None: a coarse default, tengsim.resolve.default_dx) and pressures (Pa; () if none: physical runs only)."""
    if vals["resolve"] != "auto":
        bad = [k for k in ("resolve_tol", "max_pixels", "resolve_pressures") if k in given]
        if bad:
            raise ConfigValueError(f"{' and '.join(bad)} {'apply' if len(bad) > 1 else 'applies'} only with "
                                   "resolve = 'auto'")
        return {}
    tol = vals["resolve_tol"]
    if tol is not None and not 0 < tol < 1:
        raise ConfigValueError(f"resolve_tol must be > 0 and < 1, got {tol!r}")
    mp = vals["max_pixels"]
    if mp is not None and mp < 9:
        raise ConfigValueError(f"max_pixels must be >= 9 (pixels nx·ny), got {mp!r}")
    pressures = tuple(vals["resolve_pressures"] or ())
    if "resolve_pressures" in given:
        if scaling is None:
            raise ConfigValueError("resolve_pressures applies only to a physical run (E_star, W and the shape's "
                                   "sizes with units): a dimensionless run has no pressure")
        bad = [p for p in pressures if not p > 0]
        if bad or not pressures:
            raise ConfigValueError(f"resolve_pressures must be pressures > 0, got {vals['resolve_pressures']!r}")
    return {"resolve": "auto", "resolve_tol": 0.01 if tol is None else float(tol), "max_pixels": mp, "dx": dx,
            "pressures": pressures}


def _common_names():
    return {f.name for f in common_fields()}
