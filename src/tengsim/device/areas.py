"""The charged-area model from a contact result on file: a ``tengsim design`` result (``design.nc``), or a
physical ``tengsim contact`` result (.nc or .csv; best a load-controlled one).

The design-result file holds, per nominal pressure (coordinate ``pressure``, Pa) and branch
(``approach``, ``retraction``), the charged-area fraction A/S (``charged_area_fraction``; NaN where a
pressure was not reached on that branch), and the states a pressed device passes (``state_pressure``,
``state_charged_area_fraction``).  A pressed device follows the stable approach branch, so the device takes
that branch's states (:func:`passed_curve`, the curve calibrate's nodes are read off too) between the lowest
and the highest asked pressure the approach reached: across a snap between two asked pressures A/S is the
branch the device is on, not a straight line from one asked pressure to the next.  A file without states:
its asked pressures, NaN rows dropped, and at a snap (the same pressure met twice) the first state reached at
that pressure kept, so the pressures increase strictly.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from tengsim.device.params import AreaTable
from tengsim.errors import TengsimError

DESIGN_FILE = "design.nc"
AREA_VARIABLE = "charged_area_fraction"


def stable_branch(pressure_Pa, area_fraction, where: str = "area table", rows=None, hint: str = ""):
    """(pressures, fractions) of an approach with the repeats of a snap removed: at a pressure met again
    (a jump at constant load) the first state reached is kept.  A pressure that falls is an error naming
    its row (0-based; ``rows``: the row numbers of the source, if the values were picked from it) and
    value, and the row before it, then ``hint``."""
    p = np.asarray(pressure_Pa, dtype=float).ravel()
    a = np.asarray(area_fraction, dtype=float).ravel()
    rows = np.arange(p.size) if rows is None else np.asarray(rows)
    if p.size != a.size:
        raise TengsimError(f"{where}: {p.size} pressures but {a.size} area fractions")
    keep = [0] if p.size else []
    for i in range(1, p.size):
        last = p[keep[-1]]
        if p[i] == last or abs(p[i] - last) <= 1e-9 * max(abs(last), abs(p[i])):
            continue  # the landing state of a snap, at the pressure already kept
        if p[i] < last:
            raise TengsimError(f"{where}: pressures must increase, but row {rows[i]} holds {p[i]:.6g} Pa after "
                               f"{last:.6g} Pa (row {rows[keep[-1]]}){hint}")
        keep.append(i)
    return p[keep], a[keep]


def passed_curve(pressure_Pa, area_fraction, p_lo: float, p_hi: float):
    """(P, A/S) of the states a pressed device passes, from ``p_lo`` to ``p_hi`` (Pa): the finite states, A/S
    clipped to [0, 1] and made monotone (the device passes the states whose load is above every earlier one), the
    states strictly inside (p_lo, p_hi) and both ends read off the states (held flat beyond the first and the
    last).  The one reading of a design's states: the device's area table (:func:`area_table_from_design`) and
    calibrate's nodes (:meth:`tengsim.calibrate.surrogate.Node.curve`)."""
    P = np.asarray(pressure_Pa, float).ravel()
    A = np.asarray(area_fraction, float).ravel()
    ok = np.isfinite(P) & np.isfinite(A)
    P, A = P[ok], np.maximum.accumulate(np.clip(A[ok], 0.0, 1.0))
    inside = (P > p_lo) & (P < p_hi)
    ends = np.interp([p_lo, p_hi], P, A)
    return np.concatenate([[p_lo], P[inside], [p_hi]]), np.concatenate([[ends[0]], A[inside], [ends[1]]])


def design_path(path) -> Path:
    """The design.nc of ``path`` (the file, or the folder a ``tengsim design --out DIR`` wrote)."""
    p = Path(path)
    if p.is_dir():
        p = p / DESIGN_FILE
    if not p.is_file():
        raise TengsimError(f"area: no design result {str(p)!r} (give the design.nc that `tengsim design --out "
                           "DIR` wrote, or its folder DIR)")
    return p


def area_table_from_design(path) -> AreaTable:
    """The :class:`AreaTable` A/S(P) of a design result (``DIR/design.nc`` or ``DIR``): its approach
    branch's states between the lowest and the highest asked pressure reached (:func:`passed_curve`); a file
    without states: its asked pressures, NaN rows dropped, one value per pressure (the first state reached at a
    snap's pressure)."""
    import xarray as xr

    p = design_path(path)
    try:
        ds = xr.load_dataset(p)
    except (OSError, ValueError) as exc:
        raise TengsimError(f"area: cannot read {str(p)!r} as a design result (not a NetCDF file: "
                           f"{str(exc).splitlines()[0][:80]})") from None
    if AREA_VARIABLE not in ds or "pressure" not in ds.coords:
        raise TengsimError(f"area: {str(p)!r} is no design result (it has no {AREA_VARIABLE!r} over 'pressure')")
    if ds["pressure"].dtype.kind not in "fiu" or ds["pressure"].ndim != 1 or ds[AREA_VARIABLE].dtype.kind != "f":
        raise TengsimError(f"area: {str(p)!r}: pressure and {AREA_VARIABLE} must be numbers, pressure 1-D")
    units = str(ds["pressure"].attrs.get("units", "Pa"))
    if units != "Pa":
        raise TengsimError(f"area: {str(p)!r}: pressure in {units!r}, expected 'Pa'")
    frac = ds[AREA_VARIABLE]
    if "branch" in frac.dims:
        branches = [b.decode() if isinstance(b, bytes) else str(b) for b in ds["branch"].values]
        if "approach" not in branches:
            raise TengsimError(f"area: {str(p)!r} has no approach branch (branches: {', '.join(branches)})")
        frac = frac.isel(branch=branches.index("approach"))
    pres = np.asarray(ds["pressure"].values, dtype=float)
    a = np.asarray(frac.values, dtype=float)
    ok = np.isfinite(pres) & np.isfinite(a)
    if ok.sum() < 2:
        raise TengsimError(f"area: {str(p)!r}: the approach branch reached {int(ok.sum())} of {pres.size} "
                           "pressures; the device needs at least 2")
    pres, a = stable_branch(pres[ok], a[ok], where=f"area: {p}")
    states = _approach_states(ds)
    if states is not None and np.count_nonzero(np.isfinite(states[0]) & np.isfinite(states[1])) >= 2:
        sp, sa = passed_curve(*states, float(pres[0]), float(pres[-1]))
        pres, a = stable_branch(_landing_after(sp), sa, where=f"area: {p} (its states)")
    return AreaTable(pres, a)


SNAP_STEP = 1e-8
"""A snap's landing state, met at the pressure of the state it jumps from, is placed this fraction of that pressure
above it in the device's table (which needs pressures that increase strictly): below the snap's pressure the
device is on the branch before the jump, above it on the branch it landed on.  Far below any pressure a waveform
resolves; above the 1e-9 within which :func:`stable_branch` takes two pressures as one."""


def _landing_after(P):
    """``P`` with each repeat of a pressure (a snap at constant load: its landing state) moved
    :data:`SNAP_STEP` above the one before it, where that stays below the next state's (else left for
    :func:`stable_branch` to take as one)."""
    P = np.array(P, float)
    for i in range(1, len(P)):
        last = P[i - 1]
        if abs(P[i] - last) <= 1e-9 * max(abs(last), abs(P[i])):
            up = last + SNAP_STEP * max(abs(last), 1.0)
            if i + 1 == len(P) or up < P[i + 1]:
                P[i] = up
    return P


PRESS_KINDS = ("square", "sine")
"""The presses a design records with their memory (:data:`tengsim.design.visco.PRESSES`; the device layer's copy of
the names its records hold)."""


def visco_record(path) -> dict | None:
    """The viscoelastic cycles a design result holds (``tengsim design … --relaxation``,
    :func:`tengsim.design.visco_write.record_in_design`), None for a design without: {'frequencies_Hz' (the
    square cycles', increasing, without the relaxed 0), 'p_max_Pa', 'rise', 'grid', 'relaxation' (dict),
    'square': {frequency: (t s, P Pa, A/S)} (the first press; 0: the relaxed elastic solid, period 1 s),
    'presses': {kind: {frequency: {'periods': [(t, P, A/S) of press 1, 2, …], 'steady': (t, P, A/S) or None}}},
    'steady': the record's list of how each steady state converged}."""
    import json

    import xarray as xr

    p = design_path(path)
    try:
        with xr.open_dataset(p) as ds:
            if "relaxation" not in ds.attrs:
                return None
            need = ("visco_frequency", "visco_cycle", "visco_time", "visco_charged_area_fraction")
            missing = [v for v in need if v not in ds]
            if missing or "visco_p_max_Pa" not in ds.attrs:
                raise TengsimError(f"area: {str(p)!r} names a relaxation but holds no viscoelastic cycles (no "
                                   f"{', '.join(missing) or 'visco_p_max_Pa'}): write it again with `tengsim design "
                                   "… --relaxation FILE`")
            f = np.asarray(ds["visco_frequency"].values, float)
            kind = np.asarray(ds["visco_cycle"].values).astype(str)
            t = np.asarray(ds["visco_time"].values, float)
            P = np.asarray(ds["visco_pressure"].values, float) if "visco_pressure" in ds else np.full(t.size, np.nan)
            a = np.asarray(ds["visco_charged_area_fraction"].values, float)
            press = (np.asarray(ds["visco_press"].values, int) if "visco_press" in ds
                     else np.ones(t.size, int))  # a record written before the presses were repeated: press 1 only
            attrs = dict(ds.attrs)
    except (OSError, ValueError) as exc:
        raise TengsimError(f"area: cannot read {str(p)!r} as a design result ({str(exc).splitlines()[0][:80]})") \
            from None
    presses = {}
    for k in PRESS_KINDS:
        for fr in np.unique(f[kind == k]):
            rows = {}
            for n in np.unique(press[(kind == k) & (f == fr)]):
                m = (f == fr) & (kind == k) & (press == n) & np.isfinite(t) & np.isfinite(a)
                if np.count_nonzero(m) >= 2:
                    order = np.argsort(t[m], kind="stable")
                    rows[int(n)] = (t[m][order], P[m][order], np.clip(a[m][order], 0.0, 1.0))
            periods = []
            while len(periods) + 1 in rows:
                periods.append(rows[len(periods) + 1])
            if periods:
                presses.setdefault(k, {})[float(fr)] = {"periods": periods, "steady": rows.get(0)}
    square = {fr: v["periods"][0] for fr, v in presses.get("square", {}).items()}
    freqs = np.array(sorted(k for k in square if k > 0))
    if freqs.size == 0 or 0.0 not in square:
        raise TengsimError(f"area: {str(p)!r}: its viscoelastic record holds no square cycle "
                           f"{'of the relaxed solid (0 Hz)' if freqs.size else 'at a frequency > 0'}")
    try:
        relax = json.loads(str(attrs["relaxation"]))
    except ValueError:
        relax = {"text": str(attrs["relaxation"])}
    try:
        steady = json.loads(str(attrs.get("visco_steady", "[]")))
    except ValueError:
        steady = []
    return {"frequencies_Hz": freqs, "p_max_Pa": float(attrs["visco_p_max_Pa"]),
            "rise": float(attrs.get("visco_rise", math.nan)), "grid": str(attrs.get("visco_grid", "")),
            "relaxation": relax, "square": square, "presses": presses, "steady": steady, "source": str(p)}


def area_cycle_from_design(path, frequency_Hz: float, static_fraction: float | None = None, press: str = "square",
                           record: dict | None = None):
    """The :class:`AreaCycle` of a design result's viscoelastic presses ``press`` (square or sine;
    :func:`visco_record`; None for a design without) at the waveform's ``frequency_Hz``: the design's cycles at that
    frequency, or between two of its frequencies the two nearest interpolated linearly in log f at each phase;
    outside them refused (the contact's rate response is not extrapolated).  Each of the press's recorded periods
    (1, 2, … from rest) and its periodic steady state is carried (:class:`AreaCycle`: press n of the device reads
    its own).  ``static_fraction``: the converged static design's A/S at p_max; the cycles (on one coarse grid) are
    scaled by it over the relaxed (E∞) cycle's A/S at the end of its hold, the same state on the coarse grid (the
    factor is ``details['grid_correction']``)."""
    from tengsim.device.params import AreaCycle

    rec = visco_record(path) if record is None else record
    if rec is None:
        return None
    f = float(frequency_Hz)
    table = rec["presses"].get(press, {})
    fs = np.array(sorted(k for k in table if k > 0))
    if fs.size == 0:
        raise TengsimError(f"device: the design's viscoelastic record ({rec['source']}) holds no {press} press: "
                           "write it again with `tengsim design … --relaxation FILE` (which records the square and "
                           "the sine press)")
    span = f"{fs[0]:g} to {fs[-1]:g} Hz" if fs.size > 1 else f"{fs[0]:g} Hz only"
    if not (fs[0] * (1 - 1e-9) <= f <= fs[-1] * (1 + 1e-9)):
        raise TengsimError(f"device design: the waveform's frequency {f:g} Hz is outside the design's viscoelastic "
                           f"cycles ({span}; {rec['source']}): give --frequency within them (the contact's rate "
                           "response is not extrapolated)")

    def presses(fr):
        """[(phase, A/S) of press 1, 2, …], (phase, A/S) of the steady state (the last press if none)."""
        rows = table[fr]
        ph = [(np.clip(t * fr, 0.0, 1.0), a) for t, _, a in rows["periods"]]
        st = rows["steady"]
        return ph, ((np.clip(st[0] * fr, 0.0, 1.0), st[2]) if st is not None else ph[-1])

    near = np.flatnonzero(np.abs(np.log(fs / f)) <= 1e-9)
    if near.size:
        used, weights = [float(fs[near[0]])], [1.0]
        how = f"the design's cycle at {used[0]:g} Hz"
    else:
        j = int(np.searchsorted(fs, f))
        f1, f2 = float(fs[j - 1]), float(fs[j])
        w = math.log(f / f1) / math.log(f2 / f1)
        used, weights = [f1, f2], [1 - w, w]
        how = f"interpolated in log f between the design's cycles at {f1:g} and {f2:g} Hz (weights {1 - w:.3g}, {w:.3g})"
    per = [presses(fr) for fr in used]
    phase = np.unique(np.concatenate([c[0] for pp, st in per for c in pp + [st]]))
    n = min(len(pp) for pp, _ in per)

    def mix(pick):
        return sum(wt * np.interp(phase, *pick(pp, st)) for wt, (pp, st) in zip(weights, per))

    rel_t, _, rel_a = rec["square"][0.0]
    held = float(np.interp(0.5, rel_t, rel_a))  # the relaxed cycle at the end of its hold (period 1 s)
    corr = float(static_fraction) / held if static_fraction is not None and held > 0 else 1.0
    cycles = [np.clip(corr * mix(lambda pp, st, i=i: pp[i]), 0.0, 1.0) for i in range(n)]
    steady = np.clip(corr * mix(lambda pp, st: st), 0.0, 1.0)
    conv = [s for s in rec.get("steady", []) if s.get("cycle") == press and float(s.get("frequency_Hz", -1)) in used]
    details = {"cycle": how, "press": press, "cycle_frequencies_Hz": used, "cycle_weights": weights,
               "design_cycle_frequencies_Hz": fs.tolist(), "cycle_p_max_Pa": rec["p_max_Pa"],
               "grid_correction": corr, "cycle_grid": rec["grid"], "relaxation": rec["relaxation"],
               "presses_recorded": n, "steady_state": conv}
    return AreaCycle(f, phase, cycles[0], f"viscoelastic {press} cycle at {f:g} Hz" if press != "square"
                     else f"viscoelastic cycle at {f:g} Hz", details, tuple(cycles[1:]), steady)


def area_cycle_for_waveform(path, wave, static_fraction: float | None = None, where: str = "device"):
    """The :class:`AreaCycle` of a design result's viscoelastic presses for the waveform ``wave`` (None: the design
    has none); a waveform that is none of the recorded presses is refused in one line saying which ones are: a
    square wave from 0 to the cycles' p_max pressed for half the period, or the sine press
    (p_max/2)(1 − cos 2π f t) (a Sine with amplitude = offset = p_max/2, phase −π/2)."""
    from tengsim.device.waveforms import Sine, SquareWave

    rec = visco_record(path)
    if rec is None:
        return None
    pm = rec["p_max_Pa"]
    kinds = set(rec["presses"]) & set(PRESS_KINDS)
    sine = "sine" in kinds
    what = (f"the design's viscoelastic cycles ({rec['source']}) are a square press from 0 to {pm / 1e3:.4g} kPa, "
            "pressed for half of each period" + (f", and the sine press {pm / 2e3:.4g} kPa × (1 − cos 2πft) "
                                                 "(amplitude = offset = p_max/2, phase −π/2)" if sine else ""))
    kind = wave.to_dict()["kind"]
    if isinstance(wave, Sine):
        if not sine:
            raise TengsimError(f"{where}: {what}; this record holds no sine press: write the design again with "
                               "`tengsim design … --relaxation FILE`, or give a square wave")
        ph = math.remainder(wave.phase_rad + math.pi / 2, 2 * math.pi)
        if (abs(wave.amplitude_Pa - pm / 2) > 1e-6 * pm or abs(wave.offset_Pa - pm / 2) > 1e-6 * pm
                or abs(ph) > 1e-9):
            raise TengsimError(f"{where}: {what}; a sine of amplitude {wave.amplitude_Pa / 1e3:.4g} kPa, offset "
                               f"{wave.offset_Pa / 1e3:.4g} kPa, phase {wave.phase_rad:.4g} rad is not that press: give "
                               f"amplitude_Pa = offset_Pa = {pm / 2:.6g} and phase_rad = {-math.pi / 2:.6g}")
        return area_cycle_from_design(path, wave.frequency_Hz, static_fraction, "sine", rec)
    if not isinstance(wave, SquareWave):
        raise TengsimError(f"{where}: {what}; a [waveform] of kind {kind!r} is not one of them (its own presses are "
                           "not recorded): give a square wave" + (" or that sine" if sine else ""))
    if abs(wave.amplitude_Pa - pm) > 1e-6 * pm:
        given, fix = ((f"--pressure {wave.amplitude_Pa / 1e3:.4g} kPa", f"press to {pm / 1e3:.4g} kPa (the default)")
                      if where == "device design" else
                      (f"the [waveform]'s square wave to {wave.amplitude_Pa / 1e3:.4g} kPa (--config, or the command's "
                       "default waveform)", f"give a [waveform] table with kind = 'square', amplitude_Pa = {pm:.6g}"))
        raise TengsimError(f"{where}: {what}; {given} is not that cycle: {fix}, or design with --p-max "
                           f"{wave.amplitude_Pa / 1e3:.4g}kPa")
    if abs(wave.duty - 0.5) > 1e-9 or wave.low_Pa != 0:
        raise TengsimError(f"{where}: {what}; a square wave of duty {wave.duty:g} from {wave.low_Pa:g} Pa is "
                           "not that cycle: give duty 0.5 and low_Pa 0 (the defaults)")
    return area_cycle_from_design(path, wave.frequency_Hz, static_fraction, "square", rec)


def _approach_states(ds):
    """(P, A/S) of the approach states a design result holds (None: a file written without them)."""
    if "state_pressure" not in ds or "state_charged_area_fraction" not in ds:
        return None
    sp, sa = ds["state_pressure"], ds["state_charged_area_fraction"]
    if "branch" in sp.dims:
        branches = [b.decode() if isinstance(b, bytes) else str(b) for b in ds["branch"].values]
        sp, sa = (x.isel(branch=branches.index("approach")) for x in (sp, sa))
    if sp.ndim != 1 or sp.shape != sa.shape or sp.dtype.kind != "f" or sa.dtype.kind != "f":
        return None
    return np.asarray(sp.values, float), np.asarray(sa.values, float)


def area_table_from_contact(path) -> AreaTable:
    """The :class:`AreaTable` of a physical ``tengsim contact`` result (.nc or .csv): its approach rows at
    nominal pressures >= 0, A/S its ``charged_fraction`` column (the 2-D charged area of each state, the
    design's default; a file without it: the paper's λc²/L²), one row per pressure (at a load-controlled snap the first state reached).  A displacement-
    controlled approach, whose force falls after the jump-in, is refused at the row where it falls (run
    it with control = load)."""
    from tengsim.results.read import load_result

    kind, res = load_result(path)
    where = f"area: {path}"
    if kind != "contact":
        raise TengsimError(f"{where} is a {kind} result, not a contact or design result")
    t, cell = res.table, (res.params or {}).get("cell_area_m2")
    if "pressure_Pa" not in t or "contact_length_m" not in t or not cell:
        raise TengsimError(f"{where} is a dimensionless contact result (no pressure_Pa): run it with physical "
                           "input (lengths with units, E_star, W)")
    br = np.asarray(t["branch"]).astype(str)
    p = np.asarray(t["pressure_Pa"], float)
    rows = np.flatnonzero((br == "approach") & (p >= 0) & np.isfinite(p))
    if rows.size < 2:
        raise TengsimError(f"{where}: the approach has {rows.size} state(s) at a pressure >= 0; the device "
                           "needs at least 2")
    if "charged_fraction" in t:  # the result's own 2-D charged area (tengsim.analysis.charged_area)
        frac = np.asarray(t["charged_fraction"], float)[rows]
    else:  # a result written before it: the paper's λc²/L²
        frac = np.asarray(t["contact_length_m"], float)[rows] ** 2 / float(cell)
    pres, a = stable_branch(p[rows], np.clip(frac, 0.0, 1.0), where=where, rows=rows,
                            hint=" on the approach (a displacement-controlled run's force falls after a jump: "
                                 "run it with --control load)")
    return AreaTable(pres, a)


def _one_line(read):
    """``read(path)`` whose every failure on a file that is not what it should be (text where numbers belong,
    a 3-D array, random bytes named .csv) is one :class:`TengsimError` naming the file, never a traceback."""
    import functools

    @functools.wraps(read)
    def wrapped(path):
        from tengsim.errors import shown

        try:
            table = read(path)
        except TengsimError:
            raise
        except (ValueError, TypeError, KeyError, IndexError, OSError, UnicodeError, AttributeError) as exc:
            why = shown(str(exc).splitlines()[0] if str(exc) else "", 100)[1:-1]
            raise TengsimError(f"area: cannot read {shown(str(path), 200)} as a design or contact result "
                               f"({type(exc).__name__}: {why})") from None
        p, a = np.asarray(table.pressure_Pa), np.asarray(table.area_fraction)
        if p.ndim != 1 or a.shape != p.shape or p.dtype.kind != "f" or a.dtype.kind != "f":
            raise TengsimError(f"area: {shown(str(path), 200)} holds no 1-D numeric table of pressure and area")
        return table

    return wrapped


def design_visco_record(path) -> dict | None:
    """The viscoelastic record (:func:`visco_record`) of ``path`` if it is a design result (DIR, DIR/design.nc)
    with cycles; None for a design without, a contact result or no file (whose own readers say what is wrong)."""
    p = Path(path)
    if p.is_dir():
        return visco_record(p) if (p / DESIGN_FILE).is_file() else None
    if not p.is_file() or p.suffix.lower() == ".csv":
        return None
    import xarray as xr

    try:
        with xr.open_dataset(p) as ds:
            design = AREA_VARIABLE in ds
    except (OSError, ValueError):
        return None
    return visco_record(p) if design else None


@_one_line
def area_table_from_file(path) -> AreaTable:
    """The area model of a result on file: a design result (DIR, DIR/design.nc) or a contact result."""
    p = Path(path)
    if p.is_dir() or p.suffix.lower() == ".csv":
        return area_table_from_design(p) if p.is_dir() else area_table_from_contact(p)
    if p.is_file():
        import xarray as xr

        try:
            with xr.open_dataset(p) as ds:
                design = AREA_VARIABLE in ds
        except (OSError, ValueError) as exc:
            raise TengsimError(f"area: cannot read {str(p)!r} as NetCDF ({str(exc).splitlines()[0][:80]})") from None
        if not design:
            return area_table_from_contact(p)
    return area_table_from_design(p)


__all__ = ["area_cycle_from_design", "area_cycle_for_waveform", "design_visco_record", "visco_record", "area_table_from_contact", "area_table_from_design",
           "area_table_from_file", "design_path", "passed_curve", "stable_branch", "DESIGN_FILE"]
