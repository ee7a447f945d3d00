"""The field-model options of ``tengsim device`` (--field, --electrode-side, --electrode-diameter, --air-pressure).

Additive to cli/device.py: :func:`add_options` adds the options to a case's parser, :func:`device_values` turns
them into DeviceParams values (merged by cli/device_inputs.options); the field's keys of a run's summary are
:func:`tengsim.cases.device_field.field_summary`'s.
"""
from __future__ import annotations

import math

from tengsim.errors import TengsimError

FIELD_HELP = ("field model: parallel (infinite plates, Eqs. 14-19, the paper's) or finite (electrodes of the given "
              "size and shape, boundary elements; docs/device.md); default parallel, device design: finite")


def add_options(sp) -> None:
    sp.add_argument("--field", choices=("parallel", "finite"), default=None, help=FIELD_HELP)
    sp.add_argument("--electrode-side", help="square electrode of this side, e.g. 2cm (sets S = side²)")
    sp.add_argument("--electrode-diameter", help="disk electrode of this diameter, e.g. 2cm (sets S = π D²/4)")
    sp.add_argument("--air-pressure", help="air pressure for Paschen's breakdown, e.g. 101.3kPa (default 1 atm)")


def device_values(args) -> dict:
    """{DeviceParams key: value} from --electrode-side / --electrode-diameter (S and the shape); one-line errors."""
    from tengsim.units import parse_quantity

    side, diam = getattr(args, "electrode_side", None), getattr(args, "electrode_diameter", None)
    if side is None and diam is None:
        return {}
    if side is not None and diam is not None:
        raise TengsimError("give --electrode-side (square) or --electrode-diameter (disk), not both")
    if getattr(args, "electrode_area", None) is not None:
        raise TengsimError("give --electrode-area or the electrode's size (--electrode-side/--electrode-diameter), "
                           "not both")
    opt, raw = ("--electrode-side", side) if side is not None else ("--electrode-diameter", diam)
    size = parse_quantity(raw, "length", opt)
    if not size > 0:
        raise TengsimError(f"{opt} must be > 0, got {raw!r}")
    if side is not None:
        return {"area_m2": size * size, "electrode_shape": "square"}
    return {"area_m2": math.pi * size * size / 4, "electrode_shape": "disk"}


def air_pressure(args) -> float:
    from tengsim.device.paschen import ATM_PA
    from tengsim.units import parse_quantity

    raw = getattr(args, "air_pressure", None)
    if raw is None:
        return ATM_PA
    p = parse_quantity(raw, "pressure", "--air-pressure")
    if not p > 0:
        raise TengsimError(f"--air-pressure must be > 0, got {raw!r}")
    return p
