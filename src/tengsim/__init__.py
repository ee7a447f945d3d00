"""tengsim: adhesive contact of micro-structured TENG interfaces and the device output.

The public API, gathered from the layers below (see the README's layout section): shapes
(:mod:`tengsim.shapes`), laws (:mod:`tengsim.laws`), kernels (:mod:`tengsim.kernels`), solvers,
observers, the continuation paths, results, units, and the registries through which each of those
is extended (:mod:`tengsim.registry`, filled by :mod:`tengsim.plugins`).  No tengsim module imports
this one: it is the user's entry point only.

A contact is run one of three ways, each given a frozen plan (docs/extending.md, "The run layer"):
``simulate(plan)`` one grid (a :class:`ContactPlan` or a [contact] table), ``resolve(plan)`` refined until
converged (the plan's :class:`ResolveSettings`) and ``refine(plan)`` a refinement that must reach a pressure (a
:class:`RefinementPlan` from ``plan_refinement``).  Where new work goes: a shape, law, kernel, solver or observer
is a plugin registered in :mod:`tengsim.registry`.  A new application (a question asked of many contacts) is a
package beside :mod:`tengsim.design`, :mod:`tengsim.calibrate` and :mod:`tengsim.study`, above the run layer,
asking for contacts through those three entry points (or for whole designs through :mod:`tengsim.design`), never
the solvers directly.  A material with memory is a Prony series (:mod:`tengsim.relaxation`) driven in time by
:mod:`tengsim.visco`: each step one elastic equilibrium at the step's modulus with the history's gap offset.  A
field solve of the device is a model in :mod:`tengsim.device.field` (the gap coefficients; ``FIELD_MODELS``),
the finite electrodes solved in :mod:`tengsim.device.field_bem` and the charged pattern's near field in
:mod:`tengsim.device.nearfield`.
"""
from tengsim._version import __version__

_WHERE = {  # public name -> the module defining it, imported on first use (PEP 562): 'import tengsim'
    # and the command line's start stay light (no numpy until something numerical is asked for)
    "contact_length": "tengsim.analysis",
    "force": "tengsim.analysis",
    "repulsive_area": "tengsim.analysis",
    "simulate": "tengsim.run.simulate",
    "TengsimError": "tengsim.errors",
    "Grid": "tengsim.grid",
    "FreeKernel": "tengsim.kernels",
    "PeriodicKernel": "tengsim.kernels",
    "LJ93": "tengsim.laws",
    "Exponential": "tengsim.laws",
    "MaugisDugdale": "tengsim.laws",
    "Repulsive": "tengsim.laws",
    "LoadPathSpec": "tengsim.continuation",
    "run_load_path": "tengsim.continuation",
    "Summary": "tengsim.observers",
    "PathSpec": "tengsim.continuation",
    "run_path": "tengsim.continuation",
    "KERNELS": "tengsim.plugins",
    "LAWS": "tengsim.plugins",
    "OBSERVERS": "tengsim.plugins",
    "SHAPES": "tengsim.plugins",
    "SOLVERS": "tengsim.plugins",
    "resolve": "tengsim.run.resolve",
    "ResolveSettings": "tengsim.run.plan",
    "RefinementPlan": "tengsim.run.refine",
    "plan_refinement": "tengsim.run.refine",
    "refine": "tengsim.run.refine",
    "ContactPlan": "tengsim.run.plan",
    "plan_contact": "tengsim.run.plan",
    "ContactResult": "tengsim.results",
    "Jump": "tengsim.results",
    "Array": "tengsim.shapes",
    "Cone": "tengsim.shapes",
    "Cube": "tengsim.shapes",
    "FlatPunch": "tengsim.shapes",
    "HeightMap": "tengsim.shapes",
    "Hemisphere": "tengsim.shapes",
    "Line": "tengsim.shapes",
    "Paraboloid": "tengsim.shapes",
    "Pyramid": "tengsim.shapes",
    "Sinusoid1D": "tengsim.shapes",
    "Topography": "tengsim.shapes",
    "random_rough": "tengsim.shapes",
    "Equilibrium": "tengsim.solvers",
    "FastSolver": "tengsim.solvers",
    "Problem": "tengsim.solvers",
    "State": "tengsim.solvers",
    "VSRSolver": "tengsim.solvers",
    "ResultStatusError": "tengsim.status",
    "Scaling": "tengsim.units",
    "parse_quantity": "tengsim.units",
    "DevicePlan": "tengsim.cases.device_plan",
    "plan_device": "tengsim.cases.device_plan",
    "DeviceRun": "tengsim.cases.device_run",
    "LoadSweepRun": "tengsim.cases.device_run",
    "run_device": "tengsim.cases.device_run",
    "write_device": "tengsim.cases.device_run",
}


def __getattr__(name):
    mod = _WHERE.get(name)
    if mod is None:
        raise AttributeError(f"module 'tengsim' has no attribute {name!r}")
    import importlib

    value = getattr(importlib.import_module(mod), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(_WHERE))


__all__ = [
    "KERNELS", "LAWS", "OBSERVERS", "SHAPES", "SOLVERS", "Scaling", "Summary", "ContactPlan", "plan_contact",
    "ResolveSettings", "resolve", "RefinementPlan", "plan_refinement", "refine",
    "Array", "Exponential", "LoadPathSpec", "MaugisDugdale", "ResultStatusError", "Topography", "run_load_path",
    "Cone", "ContactResult", "Cube", "Equilibrium", "FastSolver", "FlatPunch", "FreeKernel", "Grid",
    "HeightMap", "Hemisphere", "Jump", "LJ93", "Line", "Paraboloid", "PathSpec",
    "PeriodicKernel", "Problem", "Pyramid", "Repulsive", "Sinusoid1D", "State", "TengsimError",
    "VSRSolver", "contact_length", "force", "parse_quantity", "random_rough",
    "repulsive_area", "run_path", "simulate", "__version__",
    "DevicePlan", "plan_device", "DeviceRun", "LoadSweepRun", "run_device", "write_device",
]
