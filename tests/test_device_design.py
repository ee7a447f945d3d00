"""The device from a design result in one step (issue 29 item 4): `area_table_from_design`, `[device] area =
"DIR/design.nc"`, `--area-from`, peak and mean power, and one config serving `device run` and `device sweep`."""
import json

import numpy as np
import pytest
import xarray as xr

from tengsim.cli.main import main
from tengsim.device import AreaTable, area_table_from_design
from tengsim.device.areas import stable_branch
from tengsim.errors import TengsimError

P = np.array([0.0, 5e3, 1e4, 2e4, 4e4, 8e4])
APPROACH = np.array([np.nan, 0.05, 0.12, 0.2, 0.31, np.nan])  # 0 Pa and 80 kPa not reached on the approach
RETRACTION = np.array([0.4, 0.45, 0.5, 0.55, 0.6, np.nan])


def design_file(folder, approach=APPROACH, pressures=P, dim="pressure"):
    """A design.nc written to the contract of `tengsim design` (CF-1.10 names, SI units); ``dim``: the
    pressure dimension's name ('applied_pressure': the coordinate ``pressure`` on it, the branch names
    stored as a char array, as the design writer does)."""
    folder.mkdir(parents=True, exist_ok=True)
    bv = lambda a, r: (("branch", dim), np.vstack([a, r]))  # noqa: E731
    ds = xr.Dataset(
        {"charged_area_fraction": bv(approach, RETRACTION), "repulsive_area_fraction": bv(approach / 2, RETRACTION / 2),
         "voc_eq12": bv(approach * 100, RETRACTION * 100), "voc_eq17": bv(approach * 90, RETRACTION * 90),
         "dvoc_dp": bv(approach * 1e-3, RETRACTION * 1e-3)},
        coords={"pressure": (dim, pressures, {"units": "Pa", "long_name": "nominal pressure"}),
                "branch": ("branch", np.array(["approach", "retraction"], dtype=object))},
        attrs={"Conventions": "CF-1.10", "title": "synthetic design", "shape": "pyramid",
               "shape_params": json.dumps({"pitch_m": 1e-5, "base_m": 5e-6, "height_m": 3.5e-6}), "E_star_Pa": 1e6,
               "W_J_m2": 0.05, "eps_m": 2e-8, "tabor": 0.5, "sigma_C_m2": 5.84e-6, "eps_r": 2.4,
               "thickness_m": 4e-4, "status": "ok", "grids": "dx 57 nm", "tolerance": 0.01,
               "charged_area_definition": "gap below the LJ93 force peak"})
    for k in ("charged_area_fraction", "repulsive_area_fraction"):
        ds[k].attrs["units"] = "1"
    if dim != "pressure":
        ds["branch"].encoding["dtype"] = "S1"
    ds.to_netcdf(folder / "design.nc", engine="h5netcdf")
    return folder / "design.nc"


@pytest.mark.parametrize("dim", ["pressure", "applied_pressure"])
def test_area_table_from_design_takes_the_approach_branch(tmp_path, dim):
    path = design_file(tmp_path / "d1", dim=dim)
    for where in (path, tmp_path / "d1", str(path)):
        t = area_table_from_design(where)
        assert isinstance(t, AreaTable)
        np.testing.assert_array_equal(t.pressure_Pa, P[1:5])  # NaN rows dropped
        np.testing.assert_array_equal(t.area_fraction, APPROACH[1:5])  # approach, not retraction
    assert t(7.5e3) == pytest.approx(0.085)


def test_a_snap_keeps_one_pressure_and_a_fall_names_its_row():
    p, a = stable_branch([1e3, 2e3, 2e3, 3e3], [0.1, 0.2, 0.4, 0.5])
    np.testing.assert_array_equal(p, [1e3, 2e3, 3e3])
    np.testing.assert_array_equal(a, [0.1, 0.2, 0.5])  # the first state reached at the snap's pressure
    with pytest.raises(TengsimError, match=r"row 2 holds 1500 Pa after 2000 Pa \(row 1\)"):
        stable_branch([1e3, 2e3, 1.5e3], [0.1, 0.2, 0.3])
    with pytest.raises(TengsimError, match=r"row 1 holds 1000 Pa after 1000 Pa \(row 0\)"):
        AreaTable([1e3, 1e3], [0.1, 0.2])


def test_bad_design_results_are_one_line(tmp_path):
    with pytest.raises(TengsimError, match="no design result"):
        area_table_from_design(tmp_path / "nowhere")
    few = design_file(tmp_path / "few", approach=np.array([np.nan, 0.1, np.nan, np.nan, np.nan, np.nan]))
    with pytest.raises(TengsimError, match="reached 1 of 6 pressures"):
        area_table_from_design(few)


def _run(argv, capsys):
    code = main(argv)
    cap = capsys.readouterr()
    assert code == 0, cap.err
    return cap


def test_device_runs_from_a_design_result_as_from_its_table(tmp_path, capsys):
    design_file(tmp_path / "d1")
    table = "[device.area]\npressure_Pa = [5e3, 1e4, 2e4, 4e4]\narea_fraction = [0.05, 0.12, 0.2, 0.31]\n"
    common = "[run]\ncycles = 2\ndt_out = 1e-3\n[waveform]\namplitude_Pa = 3e4\n"
    (tmp_path / "inline.toml").write_text(table + common)
    (tmp_path / "file.toml").write_text(f'[device]\narea = "{(tmp_path / "d1" / "design.nc").as_posix()}"\n' + common)
    series = {}
    for name, extra in (("inline", []), ("file", []), ("flag", ["--area-from", str(tmp_path / "d1")])):
        cfg = tmp_path / ("inline.toml" if name == "inline" else "file.toml")
        out = tmp_path / f"{name}.nc"
        cap = _run(["device", "fig7", "--config", str(cfg), "--out", str(out), *extra], capsys)
        ds = xr.load_dataset(out)
        series[name] = ds["V"].values
        assert "power: peak " in cap.out and any(f" {p}W" in cap.out for p in "mµnp")
        summary = json.loads(ds.attrs["summary"])
        assert summary["peak_power_W"] >= summary["average_power_W"] > 0
        settled = ds["t"].values >= 0.2
        assert summary["peak_power_W"] == pytest.approx(float(np.max(np.abs(ds["power"].values[settled]))))
    np.testing.assert_array_equal(series["file"], series["inline"])
    np.testing.assert_array_equal(series["flag"], series["inline"])
    assert float(np.max(np.abs(series["inline"]))) > 0


def test_one_config_serves_a_run_and_a_sweep(tmp_path, capsys):
    from tengsim.cases.paper import fig7_params

    dev = {k: v for k, v in fig7_params().to_dict().items() if not isinstance(v, dict)}
    lines = ["[device]"] + [f"{k} = {json.dumps(v)}" for k, v in dev.items()]
    lines += ['[waveform]\nkind = "square"\namplitude_Pa = 2583.0\nfrequency_Hz = 5.0',
              '[run]\ncase = "run"\ncycles = 2\nt_end = 0.4\ndt_out = 1e-3',
              "[sweep]\nr_min_ohm = 1e5\nr_max_ohm = 1e7\npoints = 2\nsteady = false"]
    cfg = tmp_path / "both.toml"
    cfg.write_text("\n".join(lines) + "\n")
    cap = _run(["device", "run", "--config", str(cfg), "--out", str(tmp_path / "r.csv")], capsys)
    assert cap.err.count("note:") == 1 and "[sweep]" in cap.err and "error" not in cap.err
    cap = _run(["device", "sweep", "--config", str(cfg), "--out", str(tmp_path / "s.csv")], capsys)
    note = [ln for ln in cap.err.splitlines() if "note:" in ln]
    assert len(note) == 1 and "[device] load_ohm" in note[0] and "[run] t_end" in note[0] and "[run] case" in note[0]
    assert "optimum" in cap.out or "largest mean power" in cap.out
    assert "power: peak " in cap.out and "W" in cap.out
    head = json.loads((tmp_path / "s.json").read_text())
    assert head["optimum_peak_power_W"] >= head["optimum_power_W"] > 0
    assert "peak_power" in (tmp_path / "s.csv").read_text()
    # a key of neither command is still refused by name
    cfg.write_text(cfg.read_text().replace("[run]\n", "[run]\nquick = true\n"))
    assert main(["device", "sweep", "--config", str(cfg), "--out", str(tmp_path / "s2.csv")]) == 2
    assert "'quick'" in capsys.readouterr().err


def test_device_takes_a_load_controlled_contact_result_with_its_snap(tmp_path, capsys):
    """A physical load-controlled run repeats the pressure at its snap (fold and landing rows): the device
    keeps the first state reached there, refuses nothing, and A/S is the result's own charged_fraction column (the
    2-D charged area) of the approach rows."""
    from tengsim.device.areas import area_table_from_contact
    from tengsim.results.read import load_result

    run = tmp_path / "load.csv"
    assert main(["contact", "pyramid", "--pitch", "10um", "--base", "5um", "--height", "3.5um", "--E-star", "1MPa",
                 "--W", "50mJ/m2", "--eps", "100nm", "--dx", "1um", "--control", "load", "--f-max", "20kPa",
                 "--f-step", "5kPa", "--quiet", "--out", str(run)]) == 0
    capsys.readouterr()
    res = load_result(run)[1]
    a = np.asarray(res.table["branch"]).astype(str) == "approach"
    p = np.asarray(res.table["pressure_Pa"])[a]
    assert np.any(np.diff(p[p >= 0]) == 0) or np.any(np.isclose(np.diff(p[p >= 0]), 0, atol=1e-6 * p.max()))
    t = area_table_from_contact(run)
    assert np.all(np.diff(t.pressure_Pa) > 0) and t.pressure_Pa[-1] == pytest.approx(20e3, rel=1e-3)
    L = np.asarray(res.table["charged_fraction"])[a]
    first = {}
    for pi, li in zip(p, L):  # the first state reached at each pressure (>= 0)
        if pi >= 0 and not any(abs(pi - q) <= 1e-9 * max(abs(q), abs(pi)) for q in first):
            first[pi] = li
    np.testing.assert_allclose(t.area_fraction, list(first.values()), rtol=1e-12)
    out = tmp_path / "dev.csv"
    wave = tmp_path / "wave.toml"  # inside the table's pressures (Fig. 7's 2.58 kPa lies below its first state)
    wave.write_text(f'[waveform]\namplitude_Pa = {float(t.pressure_Pa[-1])}\n')
    cap = _run(["device", "fig7", "--area-from", str(run), "--config", str(wave), "--cycles", "2", "--dt", "1e-3",
                "--out", str(out)], capsys)
    side = json.loads(out.with_suffix(".json").read_text())
    np.testing.assert_allclose(side["params"]["area"]["pressure_Pa"], t.pressure_Pa)
    assert "power: peak" in cap.out


def test_a_relative_area_path_is_read_beside_the_config(tmp_path, capsys, monkeypatch):
    design_file(tmp_path / "proj" / "d1")
    cfg = tmp_path / "proj" / "dev.toml"
    cfg.write_text('[device]\narea = "d1/design.nc"\n[waveform]\namplitude_Pa = "10kPa"\n[run]\ncycles = 2\n'
                   'dt_out = 1e-3\n')
    monkeypatch.chdir(tmp_path)  # not the config's folder
    out = tmp_path / "r.csv"
    _run(["device", "fig7", "--config", str(cfg), "--out", str(out), "--quiet"], capsys)
    side = json.loads(out.with_suffix(".json").read_text())
    np.testing.assert_allclose(side["params"]["area"]["pressure_Pa"], P[1:5])


@pytest.mark.parametrize("what, words", [("nosuch", "no design result 'nosuch'"),
                                         ("nosuch.nc", "no design result 'nosuch.nc'"),
                                         ("device.csv", "is a device result, not a contact or design result")])
def test_bad_area_from_is_one_line_and_writes_nothing(tmp_path, capsys, monkeypatch, what, words):
    monkeypatch.chdir(tmp_path)
    if what == "device.csv":
        _run(["device", "fig7", "--cycles", "1", "--dt", "1e-3", "--quiet", "--out", "device.csv"], capsys)
    out = tmp_path / "x.csv"
    assert main(["device", "fig7", "--area-from", what, "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and words in err and not out.exists()


def test_sweep_with_a_designs_area_is_the_long_runs_steady_state(tmp_path):
    """A design's area table starts at A/S = 0 and is remembered at its largest (area_memory 'max'): the steady
    start of a sweep is the fixed point of the cycle map with the area every later cycle starts with, not one
    cycle from zero charge (which gave a mean power 30 % to 5× too high at R >= 1 GΩ, rising again with R).
    Checked against plain runs of 150 cycles (the last 10 averaged) at loads whose RC in contact is 8–80 s."""
    from tengsim.cases.paper import fig7_params, fig7_waveform
    from tengsim.device import resistance_sweep, steady_start

    design_file(tmp_path / "d1", approach=np.array([0.0, 0.019, 0.03, 0.05, 0.09, 0.15]))
    params = fig7_params().replace(area=area_table_from_design(tmp_path / "d1" / "design.nc"))
    wf = fig7_waveform()
    assert params.area.initial_fraction == 0.0 and params.area_memory == "max"
    loads = [1e6, 1e9, 1e10]
    steady = resistance_sweep(params, wf, loads).average_power_W
    for r, p in zip(loads, steady):
        long = resistance_sweep(params.replace(load_ohm=r), wf, [r], cycles=150, skip_cycles=140, steady=False,
                                dt_out=1e-4).average_power_W[0]
        assert p == pytest.approx(long, rel=1e-4), r
    q0, area0 = steady_start(params.replace(load_ohm=1e10), wf)
    assert area0 > params.area.initial_fraction and q0 > 0
    assert np.all(np.diff(steady[1:]) < 0)  # past the optimum the mean power falls with R


def test_device_runs_with_an_output_step_that_ends_a_flight_before_its_first_row(tmp_path):
    """`--dt 10ms` (period 0.2 s): an impact before the first output time of a flight left scipy's solution
    empty (a list), and the run crashed with an internal error (exit 70)."""
    out = tmp_path / "r.csv"
    assert main(["device", "fig7", "--dt", "10ms", "--cycles", "4", "--out", str(out), "--quiet"]) == 0
    assert out.exists()


def test_the_paper_fig7_sweep_over_its_whole_range_finds_every_steady_cycle():
    """The Fig. 7 device's default sweep (1 kΩ–10 GΩ, 15 loads): every load's steady start is found (at 3.16 GΩ
    the secant meets the integrator's own error, 2.4e-17 C, above 1e-9 σS) and the numbers are docs/device.md's."""
    from tengsim.cases.paper import fig7_params, fig7_waveform
    from tengsim.device import resistance_sweep

    sw = resistance_sweep(fig7_params(), fig7_waveform(), np.logspace(3, 10, 15))
    assert np.all(np.isfinite(sw.average_power_W)) and not sw.optimum_at_edge
    assert 3e6 <= sw.optimum_ohm <= 1e7
    assert sw.energy_per_cycle_J.max() == pytest.approx(86e-9, rel=0.01)
    assert sw.energy_per_cycle_J[6] == pytest.approx(44.8e-9, rel=0.01) and sw.load_ohm[6] == pytest.approx(1e6)
