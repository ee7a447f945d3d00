"""The result of a run in time: one row per time step, on the coordinate ``time`` (s)."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

COLUMNS = {  # name: (unit, meaning)
    "D": ("ε", "rigid approach"),
    "F": ("W ℓ²/ε", "force on the cell (Eq. 10), > 0 repulsive"),
    "mean_pressure": ("W/ε", "the mean of P over the cell (the load-controlled quantity)"),
    "area_fraction": ("1", "charged contact area over the cell, A/S (tengsim.analysis.charged_area)"),
    "area_repulsive": ("ℓ²", "area where P > 0"),
    "contact_length": ("ℓ", "Greenwood contact length through the apex"),
    "min_gap": ("ε", "smallest H"),
    "E_eff": ("Pa", "the step's instantaneous modulus E∞ + Σ E_i γ_i"),
    "residual": ("ε", "the solve's max|r|"),
    "n_conv": ("1", "convolutions spent on the step"),
}
FLAGS = ("jump", "converged")


@dataclass(frozen=True)
class TimeResult:
    """Arrays over the steps (``columns`` keyed as :data:`COLUMNS`, the flags ``jump``, ``converged``), the
    times ``t`` (s), the run's ``params`` and the (P, H) maps at the requested times."""

    t: np.ndarray
    columns: dict
    jump: np.ndarray
    converged: np.ndarray
    params: dict = field(default_factory=dict)
    maps: dict = field(default_factory=dict)

    def __getitem__(self, name: str) -> np.ndarray:
        if name == "t":
            return self.t
        if name in FLAGS:
            return getattr(self, name)
        return self.columns[name]

    @property
    def ok(self) -> bool:
        return bool(np.all(self.converged))

    def jumps(self) -> list:
        """(t, D, F) of each step marked as a jump: where a snap-in or pull-off happened (to the step's length)."""
        return [(float(self.t[i]), float(self.columns["D"][i]), float(self.columns["F"][i]))
                for i in np.flatnonzero(self.jump)]

    def pull_off(self) -> float:
        """The largest tensile force of the run (−min F, W ℓ²/ε; 0 if never tensile)."""
        return float(max(0.0, -np.min(self.columns["F"])))

    def to_xarray(self):
        import xarray as xr

        data = {k: ("time", np.asarray(v), {"units": COLUMNS[k][0], "long_name": COLUMNS[k][1]})
                for k, v in self.columns.items()}
        data.update({k: ("time", np.asarray(getattr(self, k), dtype=np.int8)) for k in FLAGS})
        attrs = {k: (v if isinstance(v, (int, float, str)) else str(v)) for k, v in self.params.items()}
        return xr.Dataset(data, coords={"time": ("time", np.asarray(self.t), {"units": "s"})}, attrs=attrs)
