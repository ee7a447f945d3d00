"""The inputs of a device run from the command line: the config file and the options given.

:func:`read` reads a config file (:func:`tengsim.schema.read_config`); :func:`options` gathers the options given as
{table: {key: raw value}}, by :data:`tengsim.cases.device_inputs.OPTIONS`, for
:func:`tengsim.cases.device_plan.plan_device`, which types and checks them (an error names the option).
"""
from __future__ import annotations


def read(path) -> dict:
    if path is None:
        return {}
    from tengsim.schema import read_config

    return read_config(path)


def options(args) -> dict:
    """Options given on the command line, as {table: {key: raw value}}."""
    from tengsim.cases.device_inputs import OPTIONS

    out = {}
    for opt, (table, key) in OPTIONS.items():
        v = getattr(args, opt, None)
        if v is not None and v != "":
            out.setdefault(table, {})[key] = v
    from tengsim.cli import device_field  # --electrode-side/--electrode-diameter: S and the shape

    for key, v in device_field.device_values(args).items():
        out.setdefault("device", {})[key] = v
    if getattr(args, "air_pressure", None) is not None:
        out["air_pressure_Pa"] = device_field.air_pressure(args)
    return out
