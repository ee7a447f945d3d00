"""Result of a dynamic run: SI time series (Eqs. 14, 17-19, 22), energies, cycle summaries."""
from __future__ import annotations

import json
import math
from dataclasses import dataclass

import numpy as np

from tengsim.device import formulas as fm
from tengsim.device.params import DeviceParams, SolverOptions

COLUMNS = {  # name: (unit, description)
    "t": ("s", "time"),
    "y": ("m", "plate travel toward the polymer"),
    "ydot": ("m/s", "plate velocity"),
    "gap": ("m", "air gap d = d0 - y"),
    "Q": ("C", "transferred charge"),
    "I": ("A", "current through the load, dQ/dt"),
    "V": ("V", "voltage across the load (Eq. 14 / 22)"),
    "V_oc": ("V", "open-circuit voltage along the trajectory (Eq. 17)"),
    "Q_sc": ("C", "short-circuit charge along the trajectory (Eq. 18)"),
    "I_sc": ("A", "short-circuit current along the trajectory (Eq. 19)"),
    "power": ("W", "power into the load, I V"),
    "P_a": ("Pa", "applied pressure"),
    "F_e": ("N", "electrostatic force toward the polymer"),
    "area": ("m2", "tribo-charged area A"),
    "contact": ("1", "1 while the plates touch"),
    "W_applied": ("J", "cumulative work of the applied force"),
    "W_electric": ("J", "cumulative work of the electrostatic force"),
    "E_load": ("J", "cumulative heat in the load"),
    "E_damping": ("J", "cumulative heat in the damper"),
    "E_impact": ("J", "cumulative kinetic energy lost at impacts"),
    "E_mech": ("J", "kinetic + spring energy"),
    "U": ("J", "field energy (sigma A - Q)^2 d/(2 eps0 S) + Q^2 T/(2 eps_r eps0 S)"),
}
CSV_COLUMNS = ("t", "y", "ydot", "Q", "I", "V", "V_oc", "I_sc", "Q_sc", "power", "P_a", "F_e", "area", "contact")


@dataclass(frozen=True, eq=False)
class DeviceResult:
    """Time series of one run (SI, one entry per output time) and what produced it."""

    params: DeviceParams
    waveform: object
    options: SolverOptions
    series: dict
    impacts_s: np.ndarray
    releases_s: np.ndarray
    nfev: int
    wall_s: float

    def __getattr__(self, name):  # result.t, result.V, ...
        series = self.__dict__.get("series", {})
        if name in series:
            return series[name]
        raise AttributeError(name)

    @classmethod
    def from_core(cls, *, params, waveform, options, tbar, state, contact, area_fraction, impact_energy,
                  impacts, releases, nfev, wall_s):
        p = params
        t = tbar * p.time_scale
        y = state[:, 0] * p.gap_m
        ydot = state[:, 1] * p.gap_m / p.time_scale
        q = state[:, 2] * p.charge_scale
        gap = np.where(contact, 0.0, p.gap_m - y)
        a = area_fraction * p.area_m2
        sig, S, T, er = p.sigma_C_per_m2, p.area_m2, p.thickness_m, p.eps_r
        v14 = fm.voltage(q, sig, a, gap, S, T, er)
        isc = fm.isc_apart(sig, a, gap, ydot, T, er)
        if p.load_mode == "finite":
            volt, cur = v14, v14 / p.load_ohm
        elif p.load_mode == "short":
            volt, cur = np.zeros_like(t), isc
        else:
            volt, cur = v14, np.zeros_like(t)
        if p.force_model == "field":
            fe = fm.field_force(q, sig, a, S)
        elif p.force_model == "eq20":
            fe = fm.eq20_force(q, sig, a, gap, S, T, er, p.eq20_reg * p.gap_m)
        else:
            fe = np.zeros_like(t)
        fe = np.where(contact, 0.0, fe)
        es = p.energy_scale
        finite_field = {}
        if p.field == "finite":  # the boundary-element field (device/field.py) replaces Eqs. 14, 17-19
            from tengsim.device.field import si_series

            finite_field = si_series(p, q, a, gap, ydot)
            volt = finite_field["V"] if p.load_mode != "short" else volt
            cur = (volt / p.load_ohm if p.load_mode == "finite"
                   else finite_field["I_sc"] if p.load_mode == "short" else cur)
            fe = np.where(contact, 0.0, finite_field["F_e"]) if p.force_model == "field" else fe
        series = {
            "t": t, "y": y, "ydot": ydot, "gap": gap, "Q": q, "I": cur, "V": volt,
            "V_oc": fm.voc_apart(sig, a, gap, S), "Q_sc": fm.qsc_apart(sig, a, gap, T, er), "I_sc": isc,
            "power": cur * volt, "P_a": waveform(t), "F_e": fe, "area": a, "contact": contact.astype(np.int8),
            "W_applied": state[:, 3] * es, "W_electric": state[:, 4] * es, "E_load": state[:, 5] * es,
            "E_damping": state[:, 6] * es, "E_impact": impact_energy * es,
            "E_mech": 0.5 * p.mass_kg * ydot ** 2 + 0.5 * p.stiffness_N_per_m * y ** 2,
            "U": fm.electrostatic_energy(q, sig, a, gap, S, T, er),
        }
        for k in ("V_oc", "Q_sc", "I_sc", "U"):
            if finite_field:
                series[k] = finite_field[k]
        if finite_field:
            series["power"] = cur * volt
        return cls(p, waveform, options, series, impacts, releases, int(nfev), float(wall_s))

    # --- cycles ---
    @property
    def period(self):
        return getattr(self.waveform, "period", None)

    def settled(self, skip_cycles: int = 1) -> np.ndarray:
        """Mask of rows after the first ``skip_cycles`` periods (the Q(0) start transient)."""
        per = self.period
        if per is None:
            return np.ones(self.t.size, bool)
        return self.t >= skip_cycles * per - 1e-12

    def cycle_values(self, name: str, skip_cycles: int = 1) -> np.ndarray:
        """Value of series ``name`` at each whole-period boundary after ``skip_cycles``."""
        per = self.period
        if per is None:
            return np.empty(0)
        n = int(math.floor(self.t[-1] / per + 1e-9))
        tb = np.arange(skip_cycles, n + 1) * per
        return np.interp(tb, self.t, self.series[name])

    def summary(self, skip_cycles: int = 1) -> dict:
        """Headline numbers over settled cycles: peaks, energy per cycle, mean power, net charge.

        Values that need a whole settled cycle are None when the run holds none (strict JSON, no NaN).
        """
        m = self.settled(skip_cycles)
        if not np.any(m):
            m = np.ones(self.t.size, bool)
        e = self.cycle_values("E_load", skip_cycles)
        qc = self.cycle_values("Q", skip_cycles)
        per = self.period
        n_cyc = max(e.size - 1, 0)
        energy = float((e[-1] - e[0]) / n_cyc) if n_cyc else None
        return {
            "peak_voltage_V": float(np.max(np.abs(self.V[m]))),
            "peak_current_A": float(np.max(np.abs(self.I[m]))),
            "peak_power_W": float(np.max(np.abs(self.power[m]))),
            "voc_V": float(np.max(self.V_oc[m])),
            "isc_A": float(np.max(np.abs(self.I_sc[m]))),
            "qsc_C": float(np.max(self.Q_sc[m])),
            "energy_per_cycle_J": energy,
            "average_power_W": energy / per if n_cyc else None,
            "net_charge_per_cycle_C": float(np.max(np.abs(np.diff(qc)))) if qc.size > 1 else None,
            "settled_cycles": n_cyc,
            "impacts": int(self.impacts_s.size),
            "wall_s": self.wall_s,
        }

    # --- output ---
    def header(self) -> dict:
        from tengsim._version import __version__

        return {"model": "tengsim.device (paper Eqs. 13-24)", "tengsim_version": __version__,
                "params": self.params.to_dict(),
                "waveform": self.waveform.to_dict(), "solver": self.options.to_dict(),
                "units": {k: COLUMNS[k][0] for k in CSV_COLUMNS}}

    def columns(self, names=CSV_COLUMNS) -> dict:
        return {k: self.series[k] for k in names}

    def write_csv(self, path, names=CSV_COLUMNS) -> None:
        """One row per output time; parameters as '# key: json' header lines (tengsim.io.write_csv)."""
        from tengsim.io import write_csv

        write_csv(path, self.columns(names), self.header())

    def to_dataset(self):
        """xarray Dataset over t with every series, by the CF-1.10 conventions (UDUNITS units, a long_name
        each); parameters as JSON strings in attrs (each once)."""
        import xarray as xr

        from tengsim.io import cf_conventions

        data = {k: ("t", v, {"units": COLUMNS[k][0], "long_name": COLUMNS[k][1]})
                for k, v in self.series.items() if k != "t"}
        attrs = {k: json.dumps(v) for k, v in self.header().items() if k != "units"}
        attrs["impacts_s"] = np.asarray(self.impacts_s, float)
        attrs["releases_s"] = np.asarray(self.releases_s, float)
        ds = xr.Dataset(data, coords={"t": ("t", self.t, {"units": "s", "long_name": COLUMNS["t"][1]})},
                        attrs=attrs)
        return cf_conventions(ds, "tengsim device run: time series of a contact-separation TENG")
