"""`tengsim device design --area-from DIR/design.nc` with a design that carries viscoelastic cycles
(`tengsim design … --relaxation`): the device is driven by the contact's own A/S(t) over its square cycle at the
waveform's frequency (docs/viscoelastic.md, "The device"), not by the quasi-static A(P) with an area_memory.

The designs are real (a small pyramid design, ~2 s, and its cycles on a 16-pixel grid, ~1.5 s per material), not
synthetic: the quasi-static limit below is the contact's, not the fixture's."""
import json
import math
import shutil

import numpy as np
import pytest

from tengsim.cli.main import main
from tengsim.relaxation import Prony, sls

SMALL = {"shape": "pyramid", "pitch": "1um", "base": "0.5um", "height": "0.2um", "E_star": "10MPa", "W": "20mJ/m2",
         "eps": "50nm", "p_max": "10kPa", "p_step": "10kPa", "tol": 0.05, "maps": False,
         "sigma": "8uC/m2", "eps_r": 3.0, "T": "200um", "gap": "0.2mm"}
E = 10e6
MATERIALS = {"slow": sls(E, E, 0.1),                     # relaxes at 0.1 s: inside the 0.5-10 Hz periods
             "weak": Prony(E, (1e-4 * E,), (0.1,)),      # E_i -> 0: the relaxed solid at every rate
             "fast": Prony(E, (E,), (1e-5,)),            # tau far below every period: relaxed at every step
             "long": sls(E, E, 5.0)}                     # tau = 10 periods at 2 Hz: no recovery between presses
FREQUENCIES = {"long": (2.0,), "weak": (2.0,), "fast": (2.0,)}  # (slow: 0.5, 2 and 10 Hz)
PRESSES = {"slow": ("square",)}                          # (the others: the square and the sine press, --visco-sine)


@pytest.fixture(scope="module")
def designs(tmp_path_factory):
    """{'static': a design folder without cycles, and one folder per material with its cycles recorded}."""
    from tengsim.design import plan_design, run_design, write_design
    from tengsim.design.visco import visco_cycles
    from tengsim.design.visco_write import record_in_design

    root = tmp_path_factory.mktemp("visco_device")
    res = run_design(plan_design(dict(SMALL)))
    write_design(res, root / "static", figures=False)
    out = {"static": root / "static"}
    for name, mat in MATERIALS.items():
        shutil.copytree(root / "static", root / name)
        vd = visco_cycles(res.plan, mat, frequencies=FREQUENCIES.get(name, (0.5, 2.0, 10.0)), pixels=16, steps=4,
                          presses=PRESSES.get(name, ("square", "sine")))
        assert record_in_design(vd, root / name) == root / name / "design.nc"
        out[name] = root / name
    return out


def test_the_design_result_records_its_material_and_cycles(designs):
    """design.nc says the design had a relaxation material and holds its square cycles (visco.csv's rows)."""
    from tengsim.device.areas import visco_record

    assert visco_record(designs["static"]) is None
    rec = visco_record(designs["slow"] / "design.nc")
    assert rec["frequencies_Hz"].tolist() == [0.5, 2.0, 10.0] and rec["p_max_Pa"] == pytest.approx(10e3)
    assert rec["relaxation"]["E_inf_Pa"] == pytest.approx(E) and rec["relaxation"]["tau_s"] == [0.1]
    assert rec["rise"] == 0.05 and set(rec["square"]) == {0.0, 0.5, 2.0, 10.0}
    t, P, a = rec["square"][2.0]
    assert t[0] == 0 and t[-1] == pytest.approx(0.5) and P.max() == pytest.approx(10e3, rel=1e-6)
    assert np.all((a >= 0) & (a <= 1)) and a.max() > 0


def _device(folder, frequency=None, **device):
    from tengsim.design.device import designed_device
    from tengsim.device import simulate

    dd = designed_device(folder / "design.nc", {"field": "parallel", **device}, frequency_Hz=frequency)
    res = simulate(dd.params, dd.waveform, 5 * dd.waveform.period, dt_out=1e-4)
    return dd, res


def _numbers(res):
    s = res.summary(1)
    return np.array([s["energy_per_cycle_J"], s["peak_voltage_V"], s["voc_V"], s["qsc_C"]])


SINE = {"kind": "sine", "amplitude_Pa": 5e3, "offset_Pa": 5e3, "phase_rad": -math.pi / 2, "frequency_Hz": 2.0}  # 0 -> p_max = 10 kPa


@pytest.mark.parametrize("name", ["weak", "fast"])
def test_a_relaxed_material_gives_the_quasi_static_device_under_the_sine_press(designs, name):
    """The sine press (p_max/2)(1 − cos 2πft), recorded by the design with its memory: for E_i -> 0 or τ ≪ period
    the device is the quasi-static one with the same sine within 0.5 % (energy, peak |V|, V_OC, Q_SC)."""
    from tengsim.design.device import designed_device
    from tengsim.device import simulate

    got = {}
    for which in ("static", name):
        dd = designed_device(designs[which] / "design.nc", {"field": "parallel"}, waveform=dict(SINE))
        got[which] = (dd, _numbers(simulate(dd.params, dd.waveform, 5 * dd.waveform.period, dt_out=1e-4)))
    assert got["static"][0].area_model == "quasi-static A(P)"
    assert got[name][0].area_model == "viscoelastic sine cycle at 2 Hz"
    assert got[name][0].params.area.details["press"] == "sine"
    assert np.all(got["static"][1] > 0)
    np.testing.assert_allclose(got[name][1], got["static"][1], rtol=5e-3)


def test_a_solid_that_recovers_repeats_its_first_press(designs):
    """τ ≪ period: every press is the first, to 0.5 % of the largest A/S at every phase after the first instant
    (measured 0.05 % square, 0.005 % sine); at the press's first instant a later press starts from the zero-load
    state the release left (the adhesive contact's retraction branch, A/S 0.028 against the approach's 0.022: the
    elastic hysteresis, not memory)."""
    for wave in (None, dict(SINE)):
        area = _designed(designs["fast"], 2.0, wave).params.area
        first, steady = area.area_fraction, area.steady
        after = area.phase > 0
        assert np.max(np.abs(steady[after] - first[after])) <= 5e-3 * first.max()
        assert float(area.at_phase(0.5, 5)) == pytest.approx(float(area.at_phase(0.5)), rel=5e-3)


def test_a_solid_that_does_not_recover_carries_its_memory_press_to_press(designs):
    """τ = 10 periods: press n starts from the relaxation state press n − 1 left.  The area at the release rises
    press by press (0.0248, 0.0251, 0.0254 … on the coarse grid) towards the periodic steady state's, higher by more
    than 10 % (0.0305, +23 %); the device reads press n's cycle in its period n, and its charged area in flight
    after the fifth press is that press's at its release; the energy per cycle is above that of a device that
    repeats the first press."""
    import dataclasses

    from tengsim.device import simulate

    dd = _designed(designs["long"], 2.0)
    area = dd.params.area
    rel = [float(area.at_phase(0.5, n)) for n in (1, 2, 3, 4, 5)]
    assert all(a < b for a, b in zip(rel, rel[1:]))
    assert float(area.at_phase(0.5, 10_000)) > 1.1 * rel[0]
    assert float(area.at_phase(0.5, 10_000)) == pytest.approx(float(np.interp(0.5, area.phase, area.steady)))
    assert 0.5 < area.decay < 1
    res = simulate(dd.params, dd.waveform, 5 * dd.waveform.period, dt_out=1e-4)
    t, a = np.asarray(res.t), np.asarray(res.area) / dd.params.area_m2
    contact = np.asarray(res.contact, bool)
    flight = a[(t > 4.7 * dd.waveform.period) & ~contact]
    assert flight.size and np.allclose(flight, rel[4], rtol=1e-9)
    first_only = dataclasses.replace(area, later=(), steady=None)
    res1 = simulate(dd.params.replace(area=first_only), dd.waveform, 5 * dd.waveform.period, dt_out=1e-4)
    assert res.summary(1)["energy_per_cycle_J"] > 1.01 * res1.summary(1)["energy_per_cycle_J"]


@pytest.mark.parametrize("name", ["weak", "fast"])
def test_a_relaxed_material_gives_the_quasi_static_device(designs, name):
    """E_i -> 0, or every tau far below the working period: the cycle is the relaxed solid's, so the device is the
    quasi-static one: energy per cycle, peak |V|, V_OC and Q_SC within 0.5 % (measured: 0.03 % for E_i = 1e-4 E∞,
    0.003 % for tau = 10 µs; the same 2 Hz device with tau = 0.1 s: -43 % energy, -24 % V_OC)."""
    dq, rq = _device(designs["static"])
    dv, rv = _device(designs[name])
    assert dq.area_model == "quasi-static A(P)" and dv.area_model == "viscoelastic cycle at 2 Hz"
    want, got = _numbers(rq), _numbers(rv)
    assert np.all(want > 0)
    np.testing.assert_allclose(got, want, rtol=5e-3)
    # the charged area in flight: the converged static design's A/S(p_max)
    a_q = dq.params.area(10e3)
    assert float(dv.params.area.at_phase(0.5)) == pytest.approx(float(a_q), rel=5e-3)


def test_the_area_lags_the_load_as_the_contact_does(designs):
    """A material relaxing at 0.1 s pressed at 2 Hz: the device's A/S creeps up while the pressure is held (it
    follows the load behind), is carried into flight at its value at the release, and on the cycle's release ramp
    it is at least the press ramp's at the same pressure (the contact's hysteresis, its direction)."""
    dd, res = _device(designs["slow"])
    area = dd.params.area
    a = np.asarray(res.area) / dd.params.area_m2
    contact, t = np.asarray(res.contact, bool), np.asarray(res.t)
    period = dd.waveform.period
    k = (t > period) & (t < 2 * period)  # the second cycle
    held = a[k & contact]
    assert held.size > 100
    assert np.all(np.diff(held) >= -1e-12)  # creep: never falls at constant load
    assert held[-1] > 1.02 * held[0]  # and grows by more than 2 % over the press
    flight = a[k & ~contact & (t > 1.5 * period)]
    assert flight.size and np.allclose(flight, float(area.at_phase(0.5, press=2)), rtol=1e-9)  # the second press's
    assert float(area.at_phase(0.5, press=2)) == pytest.approx(held[-1], rel=1e-3)
    # the cycle's ramps (rise 0.05 of the period): press 0 -> p_max, release p_max -> 0
    s = np.linspace(0.0, 1.0, 21)[1:-1]  # the same pressure s p_max on both ramps
    up, down = area.at_phase(0.05 * s), area.at_phase(0.5 + 0.05 * (1 - s))
    assert np.all(down >= up - 1e-12) and np.any(down > up + 1e-4)


def test_a_faster_press_charges_less_area(designs):
    """The stiffer solid at shorter times: A/S at the release at 10 Hz < 2 Hz < 0.5 Hz <= the relaxed (static)
    design's A/S(p_max); and 1 Hz lies between 0.5 and 2 Hz as their interpolation in ln f (weights 1/2)."""
    at = {}
    for f in (0.5, 1.0, 2.0, 10.0):
        at[f] = float(_designed(designs["slow"], f).params.area.at_phase(0.5))
    static = float(_designed(designs["static"], 2.0).params.area(10e3))
    assert at[10.0] < at[2.0] < at[0.5] <= static * (1 + 1e-9)
    assert at[2.0] < 0.9 * static  # a rate effect well above the coarse grid's
    dd = _designed(designs["slow"], 1.0)
    assert dd.area_model == "viscoelastic cycle at 1 Hz"
    cyc = dd.params.area.details
    assert "interpolated in log f" in cyc["cycle"] and cyc["cycle_frequencies_Hz"] == [0.5, 2.0]
    assert cyc["cycle_weights"] == pytest.approx([0.5, 0.5], rel=1e-12)
    assert at[1.0] == pytest.approx(0.5 * (at[0.5] + at[2.0]), rel=1e-9)


def _designed(folder, f, waveform=None):
    from tengsim.design.device import designed_device

    return designed_device(folder / "design.nc", {"field": "parallel"}, waveform=waveform, frequency_Hz=f)


def test_the_cli_names_the_area_model(designs, tmp_path, capsys):
    out = tmp_path / "dev.csv"
    assert main(["device", "design", "--area-from", str(designs["slow"] / "design.nc"), "--out", str(out),
                 "--field", "parallel"]) == 0  # the parallel plates: the finite field's BEM is not what is tested
    err = capsys.readouterr().err
    assert "A/S(t) of the viscoelastic cycle at 2 Hz (the design's cycle at 2 Hz)" in err
    side = json.loads(out.with_suffix(".json").read_text())
    s = side["summary"]
    assert s["area_model"] == "viscoelastic cycle at 2 Hz"
    ac = s["designed_device"]["area_cycle"]
    assert ac["design_cycle_frequencies_Hz"] == [0.5, 2.0, 10.0] and ac["cycle_frequencies_Hz"] == [2.0]
    assert 0.5 < ac["grid_correction"] < 2.0
    assert side["params"]["area"]["kind"] == "cycle"
    # the designed device's Eq. 17 at its rest gap, with the cycle's A/S at the release
    assert s["voc_at_rest_gap_V"] < s["design_voc_eq17_V"]
    # the same design without cycles: unchanged, the quasi-static A(P)
    out2 = tmp_path / "dev2.csv"
    assert main(["device", "design", "--area-from", str(designs["static"]), "--out", str(out2), "--quiet",
                 "--field", "parallel"]) == 0
    s2 = json.loads(out2.with_suffix(".json").read_text())["summary"]
    assert s2["area_model"] == "quasi-static A(P)" and "area_cycle" not in s2["designed_device"]
    assert s2["design_voc_eq17_V"] > s["design_voc_eq17_V"]


def test_an_area_memory_given_is_warned_unused(designs, tmp_path, capsys):
    cfg = tmp_path / "dev.toml"
    cfg.write_text('[device]\narea_memory = "release"\n')
    out = tmp_path / "dev.csv"
    assert main(["device", "design", "--area-from", str(designs["slow"]), "--config", str(cfg), "--out", str(out),
                 "--quiet", "--field", "parallel"]) == 0
    warn = [ln for ln in capsys.readouterr().err.splitlines() if "warning" in ln]
    assert len(warn) == 1 and "area_memory = 'release' is not used" in warn[0]


@pytest.mark.parametrize("option, said", [(["--frequency", "20Hz"], "frequency 20 Hz is outside the design's "
                                                                      "viscoelastic cycles (0.5 to 10 Hz"),
                                          (["--frequency", "0.1Hz"], "frequency 0.1 Hz is outside"),
                                          (["--pressure", "5kPa"], "--pressure 5 kPa is not that cycle")])
def test_a_waveform_outside_the_cycles_is_one_line(designs, tmp_path, capsys, option, said):
    out = tmp_path / "dev.csv"
    assert main(["device", "design", "--area-from", str(designs["slow"] / "design.nc"), "--out", str(out),
                 *option]) == 2
    err = capsys.readouterr().err.strip()
    assert said in err and len(err.splitlines()) == 1
    assert not out.exists() and not out.with_suffix(".json").exists()


@pytest.mark.slow
def test_design_with_relaxation_then_device_end_to_end(tmp_path, capsys):
    """The command line both ways: `tengsim design … --relaxation FILE --out v/` records the cycles in
    v/design.nc and `device design --area-from v/design.nc` runs on them."""
    rel = tmp_path / "r.toml"
    rel.write_text('[relaxation]\nE_inf = "10MPa"\nbranches = [{E = "10MPa", tau = "0.1s"}]\n')
    v = tmp_path / "v"
    keys = [f"--{k.replace('_', '-')}={val}" for k, val in SMALL.items() if k not in ("shape", "maps")]
    assert main(["design", "pyramid", *keys, "--relaxation", str(rel), "--out", str(v), "--quiet"]) == 0
    assert (v / "visco.csv").exists()
    out = tmp_path / "dev.csv"
    assert main(["device", "design", "--area-from", str(v / "design.nc"), "--frequency", "5Hz", "--out",
                 str(out), "--quiet"]) == 0
    s = json.loads(out.with_suffix(".json").read_text())["summary"]
    assert s["area_model"] == "viscoelastic cycle at 5 Hz"
    assert s["designed_device"]["area_cycle"]["cycle_frequencies_Hz"] == [2.0, 10.0]
    w = math.log(5 / 2) / math.log(5)
    assert s["designed_device"]["area_cycle"]["cycle_weights"] == pytest.approx([1 - w, w])


def _config(tmp_path, waveform: str):
    from tengsim.cases.paper import fig8_params
    from tengsim.device import ConstantArea

    dev = {k: v for k, v in fig8_params(ConstantArea(1.0)).to_dict().items() if not isinstance(v, dict)}
    dev["field"] = "parallel"
    lines = ["[device]"] + [f"{k} = {json.dumps(v)}" for k, v in dev.items()] + ["[waveform]", waveform]
    cfg = tmp_path / "dev.toml"
    cfg.write_text("\n".join(lines) + "\n")
    return cfg


@pytest.mark.parametrize("waveform, model", [
    ('kind = "square"\namplitude_Pa = 1e4\nfrequency_Hz = 2.0', "viscoelastic cycle at 2 Hz"),
    ('kind = "sine"\namplitude_Pa = 5e3\noffset_Pa = 5e3\nphase_rad = -1.5707963267948966\nfrequency_Hz = 2.0',
     "viscoelastic sine cycle at 2 Hz")])
def test_device_run_area_from_a_viscoelastic_design_uses_its_cycles(designs, tmp_path, waveform, model):
    """`device run --area-from` a design with cycles: the viscoelastic A(t) of the press the waveform is, as `device
    design` takes it (the summary's area_model says so); the same design without cycles: the quasi-static A(P)."""
    cfg = _config(tmp_path, waveform)
    for which, want in (("fast", model), ("static", "quasi-static A(P)")):
        out = tmp_path / f"{which}.csv"
        assert main(["device", "run", "--config", str(cfg), "--area-from", str(designs[which] / "design.nc"),
                     "--out", str(out), "--quiet", "--cycles", "2"]) == 0
        side = json.loads(out.with_suffix(".json").read_text())
        assert side["summary"]["area_model"] == want
        assert side["params"]["area"]["kind"] == ("cycle" if which != "static" else "table")


@pytest.mark.parametrize("case, extra, said", [
    ("run", 'kind = "square"\namplitude_Pa = 5e3\nfrequency_Hz = 2.0',
     "the [waveform]'s square wave to 5 kPa (--config, or the command's default waveform) is not that cycle"),
    ("run", 'kind = "sine"\namplitude_Pa = 1e4\nfrequency_Hz = 2.0', "a sine of amplitude 10 kPa, offset 0 kPa"),
    ("run", 'kind = "table"\nt_s = [0, 0.25, 0.5]\npressure_Pa = [0, 1e4, 0]\nperiodic = true',
     "a [waveform] of kind 'table' is not one of them"),
    ("fig8", None, "the staircase to 15 pressures"),
    ("fig7", None, "is not that cycle")])
def test_device_cases_refuse_a_waveform_the_viscoelastic_design_has_no_cycle_for(designs, tmp_path, capsys, case,
                                                                               extra, said):
    """No silent quasi-static use of a viscoelastic design: a waveform that is none of its recorded presses is one
    line (exit 2, nothing written) naming the presses it has."""
    out = tmp_path / "x.csv"
    args = ["device", case, "--area-from", str(designs["fast"] / "design.nc"), "--out", str(out)]
    if extra is not None:
        args += ["--config", str(_config(tmp_path, extra))]
    assert main(args) == 2
    err = capsys.readouterr().err.strip()
    assert said in err and "viscoelastic cycles" in err and len(err.splitlines()) == 1, err
    assert not out.exists() and not out.with_suffix(".json").exists()
