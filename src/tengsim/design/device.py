"""The device a design describes, in one step (``tengsim device design --area-from DIR/design.nc``).

From the design result (design.nc, :mod:`tengsim.design.write`) the device takes what the design knows: the
tribo-charge density σ, the dielectric's ε_r and thickness T, the rest gap d0 (the values of Eq. 12 and Eq. 17
in the design) and its charged area A/S(P) on the approach over the design's pressures.  What a design does not
know comes from :data:`DEFAULTS` (the paper's Fig. 8 device, whose σ, ε_r, T and d0 are also a design's
defaults) unless given: the plate's mass, the spring, the electrode area, the load, and the pressure waveform
(a square wave pressing to the design's highest pressure).  :class:`DesignedDevice` says which values came from
where.  A waveform that presses outside the area table's pressures is refused
(:func:`tengsim.device.config.check_pressures`): the table is never held at its ends in silence.

A design with viscoelastic cycles (``tengsim design … --relaxation``) drives the device with the contact's own
A/S(t) over its presses at the waveform's frequency, press by press with the memory carried
(:func:`tengsim.device.areas.area_cycle_for_waveform`; docs/viscoelastic.md, "The device"): the waveform must be
one of the recorded presses (a square wave from 0 to the cycles' p_max pressed for half the period, or the sine
press (p_max/2)(1 − cos 2πft)) at a frequency within the cycles'; ``area_model`` says which A the device used.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from tengsim.device.params import QUASI_STATIC
from tengsim.errors import TengsimError

DEFAULTS = {
    # name: (value, what it is): the paper's Fig. 8 device (Section 5), the design's own device by default
    "mass_kg": (13.45e-3, "plate mass M = 13.45 g"),
    "stiffness_N_per_m": (5.12e3, "spring k_e = 5.12 kN/m"),
    "area_m2": (4.00e-4, "electrode area S = 4 cm²"),
    "load_ohm": (1.0e6, "load R = 1 MΩ"),
    "frequency_Hz": (2.0, "square wave at 2 Hz"),
}
"""What a design does not know, the paper's Fig. 8 device; ``amplitude_Pa`` defaults to the design's p_max."""
FROM_DESIGN = {"sigma_C_per_m2": "sigma_C_m2", "eps_r": "eps_r", "thickness_m": "thickness_m", "gap_m": "gap_m"}
"""DeviceParams field: the design.nc attribute it is read from."""


@dataclass(frozen=True)
class DesignedDevice:
    """The designed device: its ``params`` (DeviceParams), ``waveform``, ``source`` (the design.nc), the values
    taken from the design (``from_design``) and those taken from :data:`DEFAULTS` (``defaults``), each
    {name: text with its unit}, and the design's pressure range (Pa)."""

    params: object
    waveform: object
    source: str
    from_design: dict = field(default_factory=dict)
    defaults: dict = field(default_factory=dict)
    pressure_range: tuple = (math.nan, math.nan)
    unused: tuple = ()

    @property
    def area_model(self) -> str:
        """'quasi-static A(P)', or the viscoelastic cycle's label ('viscoelastic cycle at 2 Hz')."""
        area = self.params.area
        return str(area.label) if area.carries_history else QUASI_STATIC

    def provenance(self) -> dict:
        out = {"design": self.source, "from_design": dict(self.from_design), "defaults": dict(self.defaults),
               "design_pressure_range_Pa": list(self.pressure_range), "area_model": self.area_model}
        if self.params.area.carries_history:
            d = self.params.area.details
            out["area_cycle"] = {k: d[k] for k in ("cycle", "press", "cycle_frequencies_Hz", "cycle_weights",
                                                   "design_cycle_frequencies_Hz", "grid_correction", "cycle_grid",
                                                   "presses_recorded", "steady_state")
                                 if k in d}
            out["area_cycle"]["decay"] = self.params.area.decay
        return out

    def warnings(self) -> list:
        """One line per value given that this device does not use (area_memory with a viscoelastic cycle)."""
        return [f"{u} is not used: the viscoelastic contact carries its own history (A/S in flight is the cycle's "
                "at the release)" for u in self.unused]

    def lines(self) -> list:
        """Two lines for the user: what came from the design, and which values are defaults."""
        out = [f"device from the design {self.source}: " + ", ".join(self.from_design.values())]
        if self.defaults:
            out.append("defaults (the paper's Fig. 8 device; --mass, --stiffness, --electrode-area, --load-ohm, "
                       "--pressure, --frequency or [device]/[waveform] keys change them): "
                       + ", ".join(self.defaults.values()))
        return out


def _attrs(path):
    import xarray as xr

    from tengsim.device.areas import design_path

    p = design_path(path)
    try:
        with xr.open_dataset(p) as ds:
            attrs = dict(ds.attrs)
    except (OSError, ValueError) as exc:
        raise TengsimError(f"area: cannot read {str(p)!r} as a design result ({str(exc).splitlines()[0][:80]})") \
            from None
    missing = [a for a in FROM_DESIGN.values() if a not in attrs]
    if missing:
        raise TengsimError(f"device design: {str(p)!r} is no design result of `tengsim design` (no "
                           f"{', '.join(missing)}); a contact result has no device: use `tengsim device run "
                           "--area-from FILE --config dev.toml`")
    return p, attrs


def designed_device(path, device: dict | None = None, waveform: dict | None = None, amplitude_Pa: float | None = None,
                    frequency_Hz: float | None = None) -> DesignedDevice:
    """The device of the design result ``path`` (DIR or DIR/design.nc).  ``device``: typed DeviceParams values
    that win over the design's and the defaults (a config's [device], the CLI options); the waveform: a square
    wave pressing to the design's p_max at :data:`DEFAULTS`' frequency, changed by a [waveform] mapping
    ``waveform`` (its keys, or a waveform of its own ``kind``), then by ``amplitude_Pa`` and ``frequency_Hz``
    (the CLI's --pressure and --frequency)."""
    import dataclasses

    from tengsim.device import DeviceParams, SquareWave
    from tengsim.device.config import parse_waveform
    from tengsim.device.areas import area_table_from_design
    from tengsim.units import format_si

    device = dict(device or {})
    p, attrs = _attrs(path)
    table = area_table_from_design(p)
    values, from_design, defaults = {}, {}, {}
    label = {"sigma_C_per_m2": ("σ", "C/m²"), "eps_r": ("ε_r", ""), "thickness_m": ("T", "m"),
             "gap_m": ("rest gap d0", "m")}
    for name, attr in FROM_DESIGN.items():
        values[name] = float(attrs[attr])
        if name not in device:
            sym, unit = label[name]
            from_design[name] = f"{sym} = " + (format_si(values[name], unit) if unit else f"{values[name]:.4g}")
    from_design["area"] = (f"A/S(P) of the approach from {table.pressure_Pa[0] / 1e3:.4g} to "
                           f"{table.pressure_Pa[-1] / 1e3:.4g} kPa")
    for name in ("mass_kg", "stiffness_N_per_m", "area_m2", "load_ohm"):
        if name not in device:
            values[name], defaults[name] = DEFAULTS[name][0], DEFAULTS[name][1]
    values.update(device)
    if "field" not in device:  # the designed device's own field: finite electrodes, a square of area S
        values["field"] = "finite"
        values.setdefault("electrode_shape", "square")
        defaults["field"] = (f"field model finite: a {values['electrode_shape']} electrode of area S "
                             f"({'side' if values['electrode_shape'] == 'square' else 'diameter'} "
                             f"{format_si(_size(values), 'm')}; --field parallel for the paper's plates)")
    if "area" not in device:
        values["area"] = table
    params = DeviceParams(**values)
    lo, hi = float(table.pressure_Pa[0]), float(table.pressure_Pa[-1])
    wave = SquareWave(hi, DEFAULTS["frequency_Hz"][0])
    if waveform:
        wave = parse_waveform(waveform, wave)
    changes = {k: float(v) for k, v in (("amplitude_Pa", amplitude_Pa), ("frequency_Hz", frequency_Hz))
               if v is not None}
    for k, v, unit in (("pressure", amplitude_Pa, "Pa"), ("frequency", frequency_Hz, "Hz")):
        if v is not None and not float(v) > 0:
            raise TengsimError(f"the {k} must be > 0 {unit}, got {float(v):g} {unit}")
    named = set(waveform or {}) | set(changes)
    bad = [k for k in changes if not hasattr(wave, k)]
    if bad:
        raise TengsimError(f"--{'pressure' if bad[0] == 'amplitude_Pa' else 'frequency'} does not apply to a "
                           f"[waveform] of kind {wave.to_dict()['kind']!r}: change it in the config file")
    wave = dataclasses.replace(wave, **changes) if changes else wave
    if isinstance(wave, SquareWave) and "kind" not in (waveform or {}):
        if "amplitude_Pa" not in named:
            defaults["amplitude_Pa"] = f"pressed to {hi / 1e3:.4g} kPa (the design's p_max)"
        if "frequency_Hz" not in named:
            defaults["frequency_Hz"] = DEFAULTS["frequency_Hz"][1]
    waveform = wave
    unused = ()
    if "area" not in device:  # the design's viscoelastic cycles, if it has them, carry the device's A/S
        cycle = _viscoelastic_area(p, waveform, table)
        if cycle is not None:
            params = params.replace(area=cycle)
            from_design["area"] = f"A/S(t) of the {cycle.label} ({cycle.details['cycle']})"
            if "area_memory" in device:
                unused = (f"area_memory = {device['area_memory']!r}",)
    return DesignedDevice(params, waveform, str(p), from_design, defaults, (lo, hi), unused)


def _viscoelastic_area(path, wave, table):
    """The :class:`tengsim.device.params.AreaCycle` of the design's viscoelastic presses for the waveform (None: the
    design has none); the waveform must be one of the recorded presses (one line if not;
    :func:`tengsim.device.areas.area_cycle_for_waveform`)."""
    from tengsim.device.areas import area_cycle_for_waveform, visco_record

    rec = visco_record(path)
    if rec is None:
        return None
    return area_cycle_for_waveform(path, wave, float(table(rec["p_max_Pa"])), where="device design")


def _size(values) -> float:
    from tengsim.device.field import electrode_size

    return electrode_size(values["electrode_shape"], float(values["area_m2"]))


def rest_gap_voltage(designed: DesignedDevice, result) -> dict:
    """The device's V_OC at rest (the last output row, the plate back at its rest gap after the last press) and
    the design's Eq. 17 V_OC, σ (A/S) d0/ε0 with A/S at the highest pressure the waveform applied; the two agree
    when the device reaches its rest gap (the electrostatic pull moves it by a fraction κ of d0 at most)."""
    from tengsim.device.config import waveform_peak
    from tengsim.device.formulas import voc_apart

    p = designed.params
    peak = waveform_peak(designed.waveform, float(result.t[-1]))
    rest = np.flatnonzero(np.asarray(result.series["P_a"]) <= 0)  # released: the last row before the next press
    i = int(rest[-1]) if rest.size else -1
    if p.area.carries_history:  # the largest A/S of the last press (the square press's at its release)
        f = p.area.frequency_Hz
        last = max(math.floor(float(result.t[i]) * f - 1e-9), 0)
        a = p.area.largest(last / f, (last + 1) / f)
    else:
        a = float(np.interp(peak, p.area.pressure_Pa, p.area.area_fraction)) if hasattr(p.area, "pressure_Pa") \
            else math.nan
    return {"voc_at_rest_gap_V": float(result.series["V_oc"][i]), "gap_at_rest_m": float(result.series["gap"][i]),
            "design_voc_eq17_V": float(voc_apart(p.sigma_C_per_m2, a, p.gap_m, 1.0)), "pressed_to_Pa": peak}


__all__ = ["DEFAULTS", "FROM_DESIGN", "QUASI_STATIC", "DesignedDevice", "designed_device", "rest_gap_voltage"]
