"""`tengsim device` command line and plots: columns, sidecar, bad input -> exit 2 and no file."""
import json

import numpy as np
import pytest

from tengsim.cli.main import main

REQUIRED = ["t", "y", "Q", "I", "V", "V_oc", "I_sc", "contact"]


def _read(path):
    lines = path.read_text().splitlines()
    body = [ln for ln in lines if not ln.startswith("#")]
    return body[0].split(","), np.array([[float(x) for x in ln.split(",")] for ln in body[1:]]), lines


def test_fig7_csv_columns_and_sidecar(tmp_path):
    out = tmp_path / "f7.csv"
    assert main(["device", "fig7", "--out", str(out), "--cycles", "1", "--dt", "1e-4", "--quiet"]) == 0
    names, data, lines = _read(out)
    assert all(c in names for c in REQUIRED)
    assert data.shape[0] >= 2001 and set(np.unique(data[:, names.index("contact")])) <= {0.0, 1.0}
    side = json.loads(out.with_suffix(".json").read_text())
    assert side["params"]["load_ohm"] == 1e6 and "voc_V" in side["summary"]
    assert any(ln.startswith("# params:") for ln in lines)


def test_fig7_load_override_and_netcdf(tmp_path):
    out = tmp_path / "f7.nc"
    assert main(["device", "fig7", "--out", str(out), "--cycles", "1", "--load-ohm", "inf", "--quiet"]) == 0
    import xarray as xr

    with xr.open_dataset(out, engine="h5netcdf") as ds:
        assert float(abs(ds["I"]).max()) == 0.0
        assert json.loads(ds.attrs["params"])["load_ohm"] == "inf"


@pytest.mark.parametrize("argv", [["--load-ohm", "-5"], ["--cycles", "0"], ["--dt", "-1"], ["--damping", "-0.1"]])
def test_bad_options_exit_2_no_file(tmp_path, argv, capsys):
    out = tmp_path / "bad.csv"
    assert main(["device", "fig7", "--out", str(out), "--quiet", *argv]) == 2
    assert not out.exists() and not out.with_suffix(".json").exists()
    assert "tengsim: error:" in capsys.readouterr().err


@pytest.mark.parametrize("text, suffix", [("[device\nmass_kg = ", ".toml"), ("[device]\nwidth = 3\n", ".toml"),
                                          ('{"device": {"mass_kg": "heavy"}}', ".json"), ("[nonsense]\n", ".toml")])
def test_malformed_config_exit_2_no_file(tmp_path, text, suffix):
    cfg = tmp_path / f"c{suffix}"
    cfg.write_text(text)
    out = tmp_path / "bad.csv"
    assert main(["device", "fig7", "--out", str(out), "--config", str(cfg), "--quiet"]) == 2
    assert not out.exists()


def test_fig8_with_area_table_in_config(tmp_path):
    cfg = tmp_path / "c.toml"
    cfg.write_text("[device.area]\npressure_Pa = [0.0, 5e4, 2e5]\narea_fraction = [0.0, 0.2, 0.25]\n")
    out = tmp_path / "f8.csv"
    assert main(["device", "fig8", "--out", str(out), "--config", str(cfg), "--cycles", "3", "--dt", "1e-3",
                 "--quiet"]) == 0
    names, data, _ = _read(out)
    assert all(c in names for c in REQUIRED)
    voc = json.loads(out.with_suffix(".json").read_text())["summary"]["voc_steps_V"]
    assert len(voc) == 3 and voc[0] < voc[1] < voc[2]


def test_run_any_device_from_config(tmp_path):
    cfg = tmp_path / "c.json"
    cfg.write_text(json.dumps({
        "device": {"mass_kg": 0.01, "stiffness_N_per_m": 3000, "area_m2": 1e-3, "thickness_m": 5e-5,
                   "gap_m": 5e-4, "eps_r": 3.0, "sigma_C_per_m2": 2e-6, "load_ohm": 1e7},
        "waveform": {"kind": "sine", "amplitude_Pa": 3000, "frequency_Hz": 4, "offset_Pa": 3000,
                     "phase_rad": -1.5707963267948966},
        "run": {"cycles": 2, "dt_out": 1e-4}}))
    out = tmp_path / "r.csv"
    assert main(["device", "run", "--out", str(out), "--config", str(cfg), "--quiet"]) == 0
    names, data, _ = _read(out)
    assert data[-1, names.index("t")] == pytest.approx(0.5)
    assert data[:, names.index("contact")].max() == 1


def test_run_without_config_is_error(tmp_path):
    assert main(["device", "run", "--out", str(tmp_path / "x.csv"), "--quiet"]) == 2


def test_plots(tmp_path):
    from tengsim.cases.paper import fig8_params, run_fig7
    from tengsim.device import resistance_sweep, simulate, Staircase, AreaTable
    from tengsim.device.plots import plot_fig7, plot_fig8, plot_resistance_sweep, plot_vq_cycle

    r = run_fig7(2, dt_out=1e-4)
    plot_fig7(r, tmp_path / "f7.png")
    plot_vq_cycle(r, tmp_path / "vq.pdf")
    wf = Staircase((2e4, 1e5), 2.0)
    r8 = simulate(fig8_params(AreaTable([0, 1e5, 2e5], [0, 0.2, 0.25])), wf, wf.duration, dt_out=1e-3)
    plot_fig8(r8, tmp_path / "f8.png")
    sw = resistance_sweep(r.params, r.waveform, [1e6, 1e7], cycles=2, dt_out=1e-3)
    plot_resistance_sweep(sw, tmp_path / "sw.png")
    for name in ("f7.png", "vq.pdf", "f8.png", "sw.png"):
        assert (tmp_path / name).stat().st_size > 1000


def test_a_bad_time_is_named_as_the_user_wrote_it(tmp_path, capsys):
    """`--dt -1ms`: one line naming '-1ms' (the check sees -0.001 s), exit 2, nothing written."""
    from tengsim.cli.main import main as cli

    out = tmp_path / "r.csv"
    assert cli(["device", "fig7", "--dt", "-1ms", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "'-1ms'" in err[0] and "--dt must be > 0" in err[0]
    assert not out.exists() and not list(tmp_path.iterdir())
