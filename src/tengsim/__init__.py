"""tengsim: adhesive contact of micro-structured TENG interfaces and the device output.

The public API, gathered from the layers below (see the README's layout section): shapes
(:mod:`tengsim.shapes`), laws (:mod:`tengsim.laws`), kernels (:mod:`tengsim.kernels`), solvers,
observers, the continuation paths, results, units, and the registries through which each of those
is extended (:mod:`tengsim.registry`, filled by :mod:`tengsim.plugins`).  No tengsim module imports
this one: it is the user's entry point only.
"""
from tengsim._version import __version__
from tengsim.analysis import contact_length, force, repulsive_area
from tengsim.contact import simulate, simulate_pyramid
from tengsim.errors import TengsimError
from tengsim.grid import Grid
from tengsim.kernels import FreeKernel, PeriodicKernel
from tengsim.laws import LJ93, Exponential, MaugisDugdale, Repulsive
from tengsim.loadpath import LoadPathSpec, run_load_path
from tengsim.observers import Summary
from tengsim.path import PathSpec, run_path
from tengsim.plugins import KERNELS, LAWS, OBSERVERS, SHAPES, SOLVERS
from tengsim.resolve import resolve_contact
from tengsim.results import ContactResult, Jump
from tengsim.shapes import (Array, Cone, Cube, FlatPunch, HeightMap, Hemisphere, Line, Paraboloid, Pyramid,
                            Sinusoid1D, Topography, random_rough)
from tengsim.solvers import Equilibrium, FastSolver, Problem, State, VSRSolver
from tengsim.status import ResultStatusError
from tengsim.units import Scaling, parse_quantity


def run_contact(cfg: dict, progress=None, sink=None, observe=None):
    """One run of a [contact] table (the keys of ``tengsim contact``; ``resolve = "auto"``: refined until
    converged, :func:`tengsim.resolve.run_contact`), with the study layer's full-contact length and A/S
    observer (``resolve_pressures``) wired in, as ``tengsim contact`` runs it.  Returns a ContactResult."""
    from tengsim.resolve import run_contact as run
    from tengsim.study.observe import contact_hooks

    return run(cfg, progress=progress, sink=sink, observe=observe, **contact_hooks(cfg))

__all__ = [
    "KERNELS", "LAWS", "OBSERVERS", "SHAPES", "SOLVERS", "Scaling", "Summary",
    "Array", "Exponential", "LoadPathSpec", "MaugisDugdale", "ResultStatusError", "Topography", "run_load_path",
    "Cone", "ContactResult", "Cube", "Equilibrium", "FastSolver", "FlatPunch", "FreeKernel", "Grid",
    "HeightMap", "Hemisphere", "Jump", "LJ93", "Line", "Paraboloid", "PathSpec",
    "PeriodicKernel", "Problem", "Pyramid", "Repulsive", "Sinusoid1D", "State", "TengsimError",
    "VSRSolver", "contact_length", "force", "parse_quantity", "random_rough",
    "repulsive_area", "resolve_contact", "run_contact", "run_path", "simulate", "simulate_pyramid", "__version__",
]
