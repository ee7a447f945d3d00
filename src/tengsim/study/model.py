"""The study as parsed: its :class:`Axis` dimensions, its :class:`Point` s and the :class:`Study`; the
tables a point holds.  Built by :mod:`tengsim.study.spec` (parsing) and :mod:`tengsim.study.sampling`."""
from __future__ import annotations

from dataclasses import dataclass, field

from tengsim.study.hashing import normalised, point_id

POINT_TABLES = ("contact", "device", "var")
"""Tables of a point; an axis is named 'table.key' with table one of these ('var': free variables that
only expressions read, e.g. an aspect ratio)."""
DEVICE_DEFAULTS = {"sigma": "5.84uC/m2", "eps_r": 2.40, "thickness": "400um"}
"""Eq. (12) inputs of the paper's Fig. 5: tribo-charge density σ, relative permittivity ε_r, thickness T."""
IGNORED_CONTACT_KEYS = ("out", "plot")
"""Keys of a `tengsim run` [contact] table that name output files; a sweep writes its own."""


@dataclass(frozen=True)
class Axis:
    """One dimension of the study: ``name`` and, per index, the values of its ``members``.

    A plain axis has one member (its own name); a zip group several, varied together.
    """

    name: str
    members: tuple
    values: tuple          # values[k] = tuple of member values at index k
    labels: tuple = ()     # zip group: one label per index (default 0, 1, ...)
    continuous: tuple = () # range axes: (start, stop, scale, unit) for sampling

    def __len__(self):
        return len(self.values)

    def coord(self):
        """Index values along this dimension (the axis value, or the zip label)."""
        if len(self.members) == 1:
            return [v[0] for v in self.values]
        return list(self.labels) if self.labels else list(range(len(self.values)))


@dataclass(frozen=True)
class Point:
    """One study point: its axis values (by axis member name) and resolved tables."""

    axes: dict
    tables: dict
    index: tuple = ()

    @property
    def contact(self) -> dict:
        return self.tables["contact"]

    @property
    def id(self) -> str:
        return point_id(self.contact)


@dataclass(frozen=True)
class Study:
    """A parsed study: base tables, axes, sampling, observables and objective settings, points (frozen:
    made whole by :func:`tengsim.study.spec.parse_study`)."""

    base: dict
    axes: list
    sampling: str = "grid"
    n: int = 0
    seed: int = 0
    observables: dict = field(default_factory=dict)
    objective: dict = field(default_factory=dict)
    points: list = field(default_factory=list)
    source: str = ""

    @property
    def is_grid(self) -> bool:
        return self.sampling == "grid"

    @property
    def columns(self) -> list:
        """Axis value columns, named as in [axes] (zip members by their own names)."""
        out = []
        for a in self.axes:
            if len(a.members) > 1:
                out.append(a.name)
            out.extend(a.members)
        return out

    def resolved(self) -> dict:
        """What DIR/study.json stores: enough to check a resumed study against the first one."""
        return {
            "format": "tengsim-study/1",
            "source": self.source,
            "sampling": self.sampling, "n": self.n, "seed": self.seed,
            "axes": [{"name": a.name, "members": list(a.members), "coord": normalised(a.coord()),
                      "values": [list(v) for v in a.values]}
                     for a in self.axes],
            "base": self.base,
            "observables": self.observables,
            "points": [{"id": p.id, "axes": p.axes, "index": list(p.index), "tables": p.tables}
                       for p in self.points],
        }


def with_unit(x, unit):
    """A generated axis value: a float (12 significant digits), or '<6 significant digits><unit>'."""
    if unit:
        return f"{float(x):.6g}{unit}"
    return float(f"{float(x):.12g}")
