"""Run descriptions: one dict (from CLI options or a TOML file) → the API objects of a contact run.

Physical inputs carry units ('0.59MPa', '54mJ/m2', '2um'); the core stays dimensionless.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

from tengsim.errors import TengsimError, positive
from tengsim.geometry import Cone, Cube, Hemisphere, Line, Paraboloid, Pyramid
from tengsim.interaction import make_law
from tengsim.path import PathSpec
from tengsim.units import PaperScaling, parse_quantity

SHAPES = ("pyramid", "sphere", "cone", "hemisphere", "cube", "line")
CONTACT_KEYS = {
    "shape", "N", "cell", "tabor", "pitch", "base", "height", "E_star", "W", "eps", "dx",
    "d_min", "d_max", "d_step", "boundary", "solver", "tol", "maps_at", "law", "slope",
    "radius", "half_width", "out", "plot", "refine_levels",
}


def load_toml(path) -> dict:
    """Read a TOML file; any failure becomes one clear TengsimError."""
    try:
        import tomllib
    except ModuleNotFoundError:  # Python 3.10
        import tomli as tomllib
    try:
        with open(path, "rb") as fh:
            return tomllib.load(fh)
    except FileNotFoundError:
        raise TengsimError(f"config file {path} not found") from None
    except OSError as exc:
        raise TengsimError(f"cannot read config file {path}: {exc.strerror}") from None
    except tomllib.TOMLDecodeError as exc:
        raise TengsimError(f"config file {path} is not valid TOML: {exc}") from None


def _num(cfg, key, default=None, kind=None):
    v = cfg.get(key, default)
    if v is None:
        return None
    x = parse_quantity(v, kind, name=key)
    if math.isnan(x):
        raise TengsimError(f"{key} must be a number, got {v!r}")
    return x


@dataclass
class ContactPlan:
    """Everything a contact run needs, built and validated from a config dict."""

    shape: object
    tabor: float
    dx: float
    path: PathSpec
    boundary: str
    solver: str
    tol: float
    law: object
    extra: dict = field(default_factory=dict)
    scaling: PaperScaling | None = None


def plan_contact(cfg: dict) -> ContactPlan:
    """Validate a contact description and build its pieces (no solving)."""
    unknown = set(cfg) - CONTACT_KEYS
    if unknown:
        raise TengsimError(f"unknown contact option(s): {', '.join(sorted(unknown))}")
    shape_name = str(cfg.get("shape", "pyramid")).lower()
    if shape_name not in SHAPES:
        raise TengsimError(f"unknown shape {shape_name!r} (choose from {', '.join(SHAPES)})")
    extra, scaling = {}, None
    physical = any(cfg.get(k) is not None for k in ("pitch", "base", "height", "E_star", "W", "eps"))
    tabor = _num(cfg, "tabor")
    if shape_name == "pyramid" and physical:
        need = ["pitch", "base", "height", "E_star", "W"]
        miss = [k for k in need if cfg.get(k) is None]
        if miss:
            raise TengsimError(f"physical pyramid input needs {', '.join(miss)}")
        L = positive("pitch", _num(cfg, "pitch", kind="length"))
        m = positive("base", _num(cfg, "base", kind="length"))
        n = positive("height", _num(cfg, "height", kind="length"))
        E = positive("E_star", _num(cfg, "E_star", kind="pressure"))
        W = positive("W", _num(cfg, "W", kind="energy/area"))
        if cfg.get("eps") is not None and tabor is not None:
            raise TengsimError("give either eps or tabor, not both")
        if cfg.get("eps") is not None:
            scaling = PaperScaling(E, W, m, n, L, positive("eps", _num(cfg, "eps", kind="length")))
        elif tabor is not None:
            scaling = PaperScaling.from_tabor(E, W, m, n, L, tabor)
        else:
            raise TengsimError("physical pyramid input needs eps or tabor")
        tabor = scaling.mu
        shape = Pyramid(scaling.N, scaling.cell)
        extra.update(scaling.params())
    else:
        tabor = positive("tabor", 0.5 if tabor is None else tabor)
        if shape_name == "pyramid":
            N, cell = cfg.get("N"), cfg.get("cell")
            if N is None or cell is None:
                raise TengsimError("pyramid needs --N and --cell (dimensionless) or pitch/base/height/E_star/W")
            shape = Pyramid(_num(cfg, "N"), _num(cfg, "cell"))
        elif shape_name == "sphere":
            shape = Paraboloid(1.0, _num(cfg, "cell", 10.0))
        elif shape_name == "cone":
            shape = Cone(_num(cfg, "slope", 1.0), _num(cfg, "cell", 10.0))
        elif shape_name == "hemisphere":
            shape = Hemisphere(_num(cfg, "radius", 3.0), _num(cfg, "cell", 10.0))
        elif shape_name == "cube":
            shape = Cube(_num(cfg, "half_width", 1.0), _num(cfg, "height", 5.0), _num(cfg, "cell", 6.0))
        else:
            shape = Line(_num(cfg, "half_width", 1.0), _num(cfg, "height", 5.0), _num(cfg, "cell", 6.0))
    dx = positive("dx", _num(cfg, "dx", 0.1))
    maps = cfg.get("maps_at") or ()
    if isinstance(maps, str):
        try:
            maps = tuple(float(v) for v in maps.split(",") if v.strip())
        except ValueError:
            raise TengsimError(f"maps_at must be comma-separated numbers, got {maps!r}") from None
    path = PathSpec(_num(cfg, "d_min", -1.0), _num(cfg, "d_max", 4.0), _num(cfg, "d_step", 0.05),
                    maps_at=tuple(maps), refine_levels=int(cfg.get("refine_levels", 4)))
    boundary = str(cfg.get("boundary", "free"))
    if boundary not in ("free", "periodic"):
        raise TengsimError(f"unknown boundary {boundary!r} (choose 'free' or 'periodic')")
    solver = str(cfg.get("solver", "fast"))
    if solver not in ("fast", "vsr"):
        raise TengsimError(f"unknown solver {solver!r} (choose 'fast' or 'vsr')")
    tol = positive("tol", _num(cfg, "tol", 1e-6))
    law = make_law(str(cfg.get("law", "lj93")))
    grid = shape.grid(dx)  # validates dx against the cell
    if grid.nx * grid.ny > 4096 * 4096:
        raise TengsimError(f"dx={dx} gives a {grid.nx}×{grid.ny} grid; too large")
    return ContactPlan(shape, tabor, dx, path, boundary, solver, tol, law, extra, scaling)


def run_contact(cfg: dict, progress=None):
    """Plan and run a contact description; returns a ContactResult with the config in params."""
    from tengsim.contact import simulate

    plan = plan_contact(cfg)
    res = simulate(plan.shape, plan.tabor, plan.dx, plan.path, boundary=plan.boundary,
                   solver=plan.solver, tol=plan.tol, law=plan.law, progress=progress,
                   extra_params=plan.extra)
    res.params["config"] = {k: v for k, v in cfg.items() if k not in ("out", "plot")}
    return res
