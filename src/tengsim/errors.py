"""Errors that the command line reports as one clear line (no traceback)."""


class TengsimError(ValueError):
    """Bad input or an unusable configuration; the message names the bad value."""

    def reworded(self, prefix: str = "", suffix: str = "") -> "TengsimError":
        """The same error (its type and its parts: a :class:`NumberError`'s name, a budget) with its message
        framed by ``prefix`` and ``suffix`` (where in the file, which material): the caller adds its context
        without rebuilding the error from its text, which a subclass with its own parts cannot take."""
        err = self.__class__.__new__(self.__class__)
        err.__dict__.update(self.__dict__)
        err.args = (f"{prefix}{self}{suffix}",)
        return err

    def __reduce__(self):  # pickled whole (a worker's error reaches the parent with its parts and its words)
        return _rebuilt, (self.__class__, self.args, dict(self.__dict__))


class ConfigValueError(TengsimError):
    """A value of the wrong kind for its key (a unit on a dimensionless key, text for a number, a
    choice not offered) or outside its key's own domain (:func:`positive`, :func:`finite`: NaN, a
    non-positive size): an error in the file, never a property of one point of a study (unlike a
    combination that cannot be built, e.g. a pyramid wider than its cell)."""


class NumberError(ConfigValueError):
    """A number refused where text becomes a number (:func:`tengsim.units.read_number`): too long, an underscore,
    not finite, out of range.  It carries its parts (``name``, the ``text`` as given, the ``reason``), so that a
    caller that reads the number under another label (an option, a number inside a quantity) names it in its own
    words with :meth:`named`, never by rewriting this message's text."""

    def __init__(self, name: str, text, reason: str, finite: bool = False):
        self.name, self.text, self.reason, self.finite = name, text, reason, finite
        super().__init__(self.named(name))

    def named(self, label: str | None, value: bool = True) -> str:
        """The message under ``label``: "label = 'text'<reason>" (``value`` false: "label<reason>", for a label that
        already shows the text); ``label`` None: "'text'<reason>" (argparse names the option itself)."""
        if self.finite:
            return f"{label or 'value'} must be finite, got {shown(self.text)}"
        if label is None:
            return f"{shown(self.text)}{self.reason}"
        return f"{label} = {shown(self.text)}{self.reason}" if value else f"{label}{self.reason}"


class MachineError(TengsimError):
    """What this machine cannot give a run, not a property of its input: a solver or extra not installed
    (:class:`SolverUnavailable`), too little memory (:class:`MemoryRefused`), the time budget spent or expected
    to be (:class:`BudgetExceeded`).  Told by its type, never by its text: a run that keeps results (a
    calibration's designs) never keeps one of these as the input's answer; the next run tries again."""


class SolverUnavailable(MachineError):
    """The solver asked for cannot run here (JAX not installed, no GPU)."""


class MemoryRefused(MachineError):
    """A grid that would not fit in the memory available."""


class BudgetExceeded(MachineError):
    """A run expected to take longer than its time budget, or stopped at it (``budget_s``, s)."""

    def __init__(self, message: str, budget_s: float = float("nan")):
        self.budget_s = budget_s
        super().__init__(message)


class GeometryError(TengsimError):
    """A size that does not fit (a structure wider than its cell, a grid too fine for its cell), raised where
    the sizes are dimensionless: ``template`` with ``{name}`` fields and the ``lengths`` (in the shape's
    lateral unit) that fill them.  The physical layer says it in metres (:meth:`in_metres`), the unit the user
    gave; a dimensionless run reads the plain numbers."""

    def __init__(self, template: str, **lengths):
        self.template, self.lengths = template, lengths
        super().__init__(template.format(**{k: f"{v:g}" for k, v in lengths.items()}))

    def in_metres(self, lateral: float, fmt) -> "GeometryError":
        """The same error with every length times ``lateral`` (m), written by ``fmt(metres)`` (the physical
        layer passes :func:`tengsim.units.format_si` with 'm': '24 µm')."""
        err = GeometryError(self.template, **self.lengths)
        err.args = (self.template.format(**{k: fmt(v * lateral) for k, v in self.lengths.items()}),)
        return err


def _rebuilt(cls, args, state):
    """A pickled :class:`TengsimError` back: its type, its message, its parts (no ``__init__`` re-run)."""
    err = cls.__new__(cls)
    err.__dict__.update(state)
    err.args = args
    return err


SHOWN = 60
"""How many characters of a value an error message echoes (:func:`shown`)."""


def shown(value, limit: int = SHOWN) -> str:
    """``repr(value)`` cut to ``limit`` characters plus '…' and its length: a hostile 100 KB value is
    named, not echoed whole."""
    text = repr(value)
    if len(text) <= limit:
        return text
    return f"{text[:limit]}… ({len(text)} characters)"


def listed(names, limit: int = 5) -> str:
    """"'a', 'b', 'c'" of ``names``, at most ``limit`` of them (each cut as :func:`shown` cuts it), then
    'and N more': a message about 16 000 unknown keys stays one short line."""
    names = list(names)
    head = ", ".join(shown(n, 40) for n in names[:limit])
    return head + (f" and {len(names) - limit} more" if len(names) > limit else "")


def require(condition: bool, message: str) -> None:
    """Raise :class:`TengsimError` with ``message`` unless ``condition`` holds."""
    if not condition:
        raise TengsimError(message)


def positive(name: str, value) -> float:
    """Return ``value`` as float if finite and > 0, else raise naming it."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ConfigValueError(f"{name} must be a number, got {shown(value)}") from None
    if not (v > 0 and v < float("inf")):
        raise ConfigValueError(f"{name} must be finite and > 0, got {shown(value)}")
    return v


def finite(name: str, value) -> float:
    """Return ``value`` as float if finite, else raise naming it."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ConfigValueError(f"{name} must be a number, got {shown(value)}") from None
    if v != v or v in (float("inf"), float("-inf")):
        raise ConfigValueError(f"{name} must be finite, got {shown(value)}")
    return v
