"""tengsim: adhesive contact of micro-structured TENG interfaces and the device output.

Public API (re-exported by hand; internals may move):
shapes (geometry), laws (interaction), kernels, solvers, observers, the continuation path, results,
units, and the registries through which each of those is extended (tengsim.registry).
"""
__version__ = "0.1.0"

from tengsim.analysis import contact_length, force, repulsive_area  # noqa: E402
from tengsim.contact import simulate, simulate_pyramid  # noqa: E402
from tengsim.errors import TengsimError  # noqa: E402
from tengsim.geometry import (Cone, Cube, FlatPunch, HeightMap, Hemisphere, Line, Paraboloid,  # noqa: E402
                              Pyramid, Sinusoid1D, random_rough)
from tengsim.grid import Grid  # noqa: E402
from tengsim.arrays import Array  # noqa: E402
from tengsim.interaction import LJ93, Exponential, MaugisDugdale, Repulsive  # noqa: E402
from tengsim.kernels import FreeKernel, PeriodicKernel  # noqa: E402
from tengsim.observers import Summary  # noqa: E402
from tengsim.loadpath import LoadPathSpec, run_load_path  # noqa: E402
from tengsim.path import PathSpec, run_path  # noqa: E402
from tengsim.registry import KERNELS, LAWS, OBSERVERS, SHAPES, SOLVERS  # noqa: E402
from tengsim.results import ContactResult, Jump  # noqa: E402
from tengsim.solvers import Equilibrium, FastSolver, Problem, State, VSRSolver  # noqa: E402
from tengsim.status import ResultStatusError  # noqa: E402
from tengsim.topography import Topography  # noqa: E402
from tengsim.units import PaperScaling, Scaling, paper_scaling, parse_quantity  # noqa: E402

__all__ = [
    "KERNELS", "LAWS", "OBSERVERS", "SHAPES", "SOLVERS", "Scaling", "Summary",
    "Array", "Exponential", "LoadPathSpec", "MaugisDugdale", "ResultStatusError", "Topography", "run_load_path",
    "Cone", "ContactResult", "Cube", "Equilibrium", "FastSolver", "FlatPunch", "FreeKernel", "Grid",
    "HeightMap", "Hemisphere", "Jump", "LJ93", "Line", "PaperScaling", "Paraboloid", "PathSpec",
    "PeriodicKernel", "Problem", "Pyramid", "Repulsive", "Sinusoid1D", "State", "TengsimError",
    "VSRSolver", "contact_length", "force", "paper_scaling", "parse_quantity", "random_rough",
    "repulsive_area", "run_path", "simulate", "simulate_pyramid", "__version__",
]
