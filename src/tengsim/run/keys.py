"""The [contact] table's schema: its keys and their help text, read from the registries and the shape's and law's
own fields, never from a list kept here.

The shape's dimensionless fields (its dataclass fields, plain numbers) *or* its physical fields (numbers in SI or
unit strings such as '2um') with ``E_star``, ``W`` and ``eps`` or ``tabor``; then the grid, the path, and the
boundary, solver, law and observers by registered name, with the chosen law's own parameters (its fields,
:func:`law_fields`: plain numbers in units of W and ε).  :mod:`tengsim.run.plan` reads a table with it.
"""
from __future__ import annotations

import dataclasses

from tengsim.kernels import film
from tengsim.errors import TengsimError
from tengsim.plugins import KERNELS, LAWS, OBSERVERS, SHAPES, SOLVERS
from tengsim.schema import Field, Table, dataclass_fields, signature_fields
from tengsim.shapes.base import dimensionless_fields, physical_fields
from tengsim.shapes.roughened import LENGTH_KEYS as _ROUGHNESS_LENGTHS, roughness_fields
from tengsim.units import number_or_text
from tengsim.solvers.types import SOLVER_TOL


PHYSICAL_KEYS = ("E_star", "W", "eps")
"""Keys that make a [contact] table a physical run (with any physical-only key of the shape)."""


X_UNIT_KEYS = {"dx": "length", "thickness": "length", "f_min": "pressure", "f_max": "pressure", "f_step": "pressure"}
"""Keys whose bare number is *not* SI (dx, thickness in X units; loads as F of Eq. 10), with the dimension a
unit string gives them in a physical run."""


def physical_triggers(given, dim_names, phys_names) -> list:
    """The given keys that make a [contact] table a physical run."""
    return sorted(set(given) & (set(PHYSICAL_KEYS) | (set(phys_names) - set(dim_names))))


def key_dims(cfg: dict) -> dict:
    """{key: (dimension, bare number is SI)} of the quantity keys of the run a [contact] table describes.

    Empty for a dimensionless run (every number plain, lengths in X units) or an unknown shape (which
    :func:`plan_contact` reports).  In a physical run: E_star, W, eps and the shape's physical fields
    with a dimension (a bare number is SI), and dx, thickness, f_min, f_max, f_step (a bare number is in
    X units or F: :data:`X_UNIT_KEYS`).  Study expressions read it to give their SI value its unit."""
    try:
        _, cls = shape_class(cfg.get("shape") or "pyramid")
    except (TengsimError, KeyError, ValueError):
        return {}
    dims, phys = dimensionless_fields(cls), physical_fields(cls)
    given = {k for k, v in cfg.items() if v is not None and v != ""}
    if not phys or not physical_triggers(given, [f.name for f in dims], [f.name for f in phys]):
        return {}
    out = {f.name: (f.dim, True) for f in common_fields() if f.dim}
    out.update({k: (d, False) for k, d in X_UNIT_KEYS.items()})
    out.update({k: ("length", False) for k in _ROUGHNESS_LENGTHS})  # bare: ε or X units, as dx
    out.update({f.name: (f.dim, True) for f in phys if f.dim})
    return out


def _observer_names(v):
    if isinstance(v, str):
        v = [s for s in (x.strip() for x in v.split(",")) if s]
    if not isinstance(v, (list, tuple)) or not all(isinstance(x, str) for x in v):
        raise TengsimError(f"observers must be a list of names, got {v!r}")
    return tuple(OBSERVERS.canonical(x) for x in v)


RESOLVE_CHOICES = ("off", "auto")
"""resolve: one grid (off) or automatic refinement (auto, tengsim.run.resolve)."""

CONTROLS = ("approach", "load")
"""Path controls of a [contact] table: the rigid approach D (PathSpec) or the load F (LoadPathSpec)."""

LOAD_KEYS = ("f_min", "f_max", "f_step")
ADAPTIVE_KEYS = ("adaptive", "adapt_tol")


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
        Field("solver", "str", "auto", choices=SOLVERS.names, help="solver: " + SOLVERS.help()),
        Field("tol", default=SOLVER_TOL, help="max residual of Eq. (9) in ε"),
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
              "is ok and the observables changed by at most resolve_tol (tengsim.run.resolve); off: the one grid dx"),
        Field("resolve_tol", "float", None, help="resolve = auto: relative tolerance of the observables, "
              "> 0 and < 0.5 (default 0.01)"),
        Field("max_pixels", "int", None, help="resolve = auto: largest grid nx·ny, >= 9 (default: what the "
              "free memory holds)"),
        Field("resolve_pressures", "floats", None, dim="pressure",
              help="resolve = auto, physical run: nominal pressures (with a unit, e.g. '10kPa'; a bare number is "
              "Pa) at which the charged-area fraction A/S (and so V_OC, Eq. 12) must converge too; a study "
              "sets its [observables] pressures here"),
        Field("out", "str", None, help="output file, .csv or .nc"),
        Field("plot", "str", None, help="figure of F(D), Λc(D), Λc(F), .png/.pdf/.svg"),
    ]


def shape_class(name):
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
    name, cls = shape_class(shape)
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


def common_names():
    return {f.name for f in common_fields()}
