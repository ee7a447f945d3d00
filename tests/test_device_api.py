"""The device API under `tengsim device`: plan_device(case, tables, overrides, source) -> a frozen DevicePlan ->
run_device(plan) -> a DeviceRun (one run) or a LoadSweepRun (a load sweep) -> write_device(run).  From Python a
single run, a load sweep and the designed device give what the command line writes (the same series, summary,
sidecar and lines), and a bad input raises the same TengsimError line the command line prints, nothing written."""
import dataclasses
import json

import numpy as np
import pytest

from tengsim.cli.main import main
from tengsim.errors import TengsimError

TINY = {"shape": "pyramid", "pitch": "1um", "base": "0.5um", "height": "0.2um", "E_star": "5MPa", "W": "20mJ/m2",
        "eps": "50nm", "p_max": "20kPa", "p_step": "10kPa", "tol": 0.05, "maps": False,
        "sigma": "8uC/m2", "eps_r": 3.0, "T": "200um", "gap": "0.2mm"}  # tests/test_device_designed.py's design


@pytest.fixture(scope="module")
def d1(tmp_path_factory):
    from tengsim.design import plan_design, run_design, write_design

    out = tmp_path_factory.mktemp("designed") / "d1"
    write_design(run_design(plan_design(TINY)), out, figures=False)
    return out


def _timeless(x):
    """``x`` as JSON reads it back, without the runs' wall times (the one value two equal runs differ in)."""
    if isinstance(x, dict):
        return {k: _timeless(v) for k, v in x.items() if k != "wall_s"}
    if isinstance(x, list):
        return [_timeless(v) for v in x]
    return x


def _as_written(obj):
    from tengsim.io import dumps

    return _timeless(json.loads(dumps(obj)))


def _rows(path):
    return [ln for ln in path.read_text().splitlines() if not ln.startswith("#")]


def test_a_single_run_from_python_is_what_the_cli_writes(tmp_path, capsys):
    from tengsim import plan_device, run_device, write_device

    cli_out, api_out = tmp_path / "cli.csv", tmp_path / "api.csv"
    assert main(["device", "fig7", "--cycles", "2", "--dt", "1e-3", "--load-ohm", "10MOhm", "--out",
                 str(cli_out)]) == 0
    cli = capsys.readouterr()
    plan = plan_device("fig7", {}, {"run": {"out": str(api_out), "cycles": "2", "dt_out": "1e-3"},
                                    "device": {"load_ohm": "10MOhm"}})
    with pytest.raises(dataclasses.FrozenInstanceError):
        plan.t_end = 1.0  # the plan is a value
    assert plan.params.load_ohm == 1e7 and plan.t_end == pytest.approx(2 * plan.waveform.period)
    run = run_device(plan)
    assert not api_out.exists()  # running writes nothing; write_device does
    side = json.loads(cli_out.with_suffix(".json").read_text())
    assert _as_written(run.summary) == _timeless(side["summary"])
    assert _as_written(run.provenance) == _timeless(side["run"])
    assert cli.out.startswith(json.dumps(run.summary, indent=1).split('"wall_s"')[0])  # its printed summary
    t = np.genfromtxt(_rows(cli_out), delimiter=",", names=True)
    np.testing.assert_allclose(t["V"], run.result.series["V"], rtol=1e-9, atol=0)
    assert write_device(run) == f"{api_out} (+ api.json)"
    assert _rows(api_out) == _rows(cli_out)
    assert _timeless(json.loads(api_out.with_suffix(".json").read_text())) == _timeless(side)


def test_a_load_sweep_from_python_is_what_the_cli_writes(tmp_path, capsys):
    from tengsim.cases.device_plan import plan_device
    from tengsim.cases.device_run import LoadSweepRun, run_device, write_device

    cli_out, api_out = tmp_path / "cli.csv", tmp_path / "api.csv"
    argv = ["device", "sweep", "--r-min", "1e5", "--r-max", "1e9", "--points", "3", "--cycles", "2", "--dt", "1e-3"]
    assert main([*argv, "--out", str(cli_out), "--quiet"]) == 0
    capsys.readouterr()
    plan = plan_device("sweep", {}, {"run": {"out": str(api_out), "cycles": "2", "dt_out": "1e-3"},
                                     "sweep": {"r_min_ohm": "1e5", "r_max_ohm": "1e9", "points": "3"}}, quiet=True)
    assert plan.sweep.loads_ohm == pytest.approx((1e5, 1e7, 1e9)) and plan.sweep.cycles == 2
    run = run_device(plan)
    assert isinstance(run, LoadSweepRun)
    side = json.loads(cli_out.with_suffix(".json").read_text())
    assert _as_written(run.header) == _timeless(side)
    t = np.genfromtxt(_rows(cli_out), delimiter=",", names=True)
    np.testing.assert_allclose(t["average_power"], run.sweep.average_power_W, rtol=1e-9, atol=0)
    assert run.header["optimum_ohm"] == run.sweep.load_ohm[run.optimum_row]
    write_device(run)
    assert _rows(api_out) == _rows(cli_out)
    assert json.loads(api_out.with_suffix(".json").read_text()) == side


def test_the_designed_device_from_python_is_what_the_cli_writes_and_says(d1, tmp_path, capsys):
    from tengsim.cases.device_plan import plan_device
    from tengsim.cases.device_run import DeviceRun, run_device, write_device

    cli_out, api_out = tmp_path / "cli.csv", tmp_path / "api.csv"
    assert main(["device", "design", "--area-from", str(d1 / "design.nc"), "--pressure", "10kPa", "--cycles", "2",
                 "--out", str(cli_out)]) == 0
    cli = capsys.readouterr()
    plan = plan_device("design", {}, {"run": {"out": str(api_out), "cycles": "2"},
                                      "device": {"area": str(d1 / "design.nc")},
                                      "waveform": {"amplitude_Pa": "10kPa"}})
    assert plan.designed is not None and plan.params.sigma_C_per_m2 == pytest.approx(8e-6)
    said = cli.err.splitlines()
    assert said[:len(plan.messages)] == list(plan.messages)  # what it says before it runs, in order
    assert any("device from the design" in m for m in plan.messages)
    assert any(m.startswith("tengsim: defaults (") for m in plan.messages)
    run = run_device(plan)
    assert isinstance(run, DeviceRun)
    side = json.loads(cli_out.with_suffix(".json").read_text())
    assert _as_written(run.summary) == _timeless(side["summary"])
    assert run.summary["pressed_to_Pa"] == pytest.approx(10e3)
    assert said[-1] == f"wrote {cli_out} (+ cli.json)"
    write_device(run)
    assert _rows(api_out) == _rows(cli_out)
    # quiet keeps the notes out of the plan, not the run
    quiet = plan_device("design", {}, {"run": {"out": str(api_out), "cycles": "2"},
                                       "device": {"area": str(d1 / "design.nc")}}, quiet=True)
    assert quiet.messages == () and quiet.designed is not None


@pytest.mark.parametrize("case, argv, given", [
    ("design", ["--frequency", "-2Hz"], {"waveform": {"frequency_Hz": "-2Hz"}}),
    ("design", ["--pressure", "30kPa"], {"waveform": {"amplitude_Pa": "30kPa"}}),
    ("sweep", ["--points", "1"], {"sweep": {"points": "1"}}),
    ("fig7", ["--load-ohm", "-5"], {"device": {"load_ohm": "-5"}}),
])
def test_a_bad_input_raises_the_line_the_cli_prints(d1, tmp_path, capsys, case, argv, given):
    from tengsim.cases.device_plan import plan_device

    out = tmp_path / "x.csv"
    area = ["--area-from", str(d1)] if case == "design" else []
    assert main(["device", case, *area, *argv, "--out", str(out)]) == 2
    err = capsys.readouterr().err
    overrides = {**given, "run": {"out": str(out)}}
    if case == "design":
        overrides["device"] = {"area": str(d1)}
    with pytest.raises(TengsimError) as exc:
        plan_device(case, {}, overrides)
    assert err == f"tengsim: error: {exc.value}\n" and not out.exists()


def test_an_unknown_case_is_refused_by_name(tmp_path):
    from tengsim.cases.device_plan import plan_device

    with pytest.raises(TengsimError, match="device case 'fig9': one of fig7, fig8, run, sweep, design"):
        plan_device("fig9", {}, {"run": {"out": str(tmp_path / "x.csv")}})
