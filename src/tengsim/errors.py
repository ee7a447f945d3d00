"""Errors that the command line reports as one clear line (no traceback)."""


class TengsimError(ValueError):
    """Bad input or an unusable configuration; the message names the bad value."""


class ConfigValueError(TengsimError):
    """A value of the wrong kind for its key (a unit on a dimensionless key, text for a number, a
    choice not offered) or outside its key's own domain (:func:`positive`, :func:`finite`: NaN, a
    non-positive size): an error in the file, never a property of one point of a study (unlike a
    combination that cannot be built, e.g. a pyramid wider than its cell)."""


def require(condition: bool, message: str) -> None:
    """Raise :class:`TengsimError` with ``message`` unless ``condition`` holds."""
    if not condition:
        raise TengsimError(message)


def positive(name: str, value) -> float:
    """Return ``value`` as float if finite and > 0, else raise naming it."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ConfigValueError(f"{name} must be a number, got {value!r}") from None
    if not (v > 0 and v < float("inf")):
        raise ConfigValueError(f"{name} must be finite and > 0, got {value!r}")
    return v


def finite(name: str, value) -> float:
    """Return ``value`` as float if finite, else raise naming it."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ConfigValueError(f"{name} must be a number, got {value!r}") from None
    if v != v or v in (float("inf"), float("-inf")):
        raise ConfigValueError(f"{name} must be finite, got {value!r}")
    return v
