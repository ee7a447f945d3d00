"""Reading results back and `tengsim plot`: nothing invented, load sweeps, saved maps, study folders."""
import sys
import types

import numpy as np
import pytest

from tengsim import io, plots
from tengsim.cli.main import main
from tengsim.errors import TengsimError
from tengsim.results.read import REQUIRED_CONTACT, load_result
from tengsim.results import CURVE_COLUMNS, ContactResult

CONTACT = ["contact", "sphere", "--cell", "4", "--tabor", "1", "--dx", "0.4", "--d-min", "-0.5",
           "--d-max", "0.5", "--d-step", "0.5", "--quiet"]


@pytest.fixture(scope="module")
def result_files(tmp_path_factory):
    d = tmp_path_factory.mktemp("res")
    assert main(CONTACT + ["--out", str(d / "r.csv")]) == 0
    assert main(CONTACT + ["--out", str(d / "r.nc"), "--maps", "0.5"]) == 0
    return d


def _one_line_error(capsys, word):
    err = capsys.readouterr().err
    assert word in err and "Traceback" not in err and len(err.strip().splitlines()) == 1, err
    return err


def test_csv_lacking_columns_is_refused_with_their_names(result_files, tmp_path, capsys):
    src = (result_files / "r.csv").read_text().splitlines()
    head = [line for line in src if line.startswith("#")]
    body = [line.split(",") for line in src if not line.startswith("#")]
    keep = [j for j, name in enumerate(body[0]) if name not in ("F", "converged")]
    p = tmp_path / "cut.csv"
    p.write_text("\n".join(head + [",".join(r[j] for j in keep) for r in body]) + "\n")
    with pytest.raises(TengsimError, match="lacks column.s. F, converged"):
        load_result(p)
    png = tmp_path / "cut.png"
    assert main(["plot", str(p), "--out", str(png)]) == 2
    _one_line_error(capsys, "F, converged")
    assert not png.exists()


def test_csv_grid_comes_from_the_header_or_is_absent(result_files, tmp_path, monkeypatch):
    kind, res = load_result(result_files / "r.csv")
    assert kind == "contact"
    assert (res.grid.nx, res.grid.ny) == (res.params["nx"], res.params["ny"]) and res.grid.nx > 3
    assert res.grid.dx == res.params["dx"]
    # the same curves without the header lines: no grid is made up
    p = tmp_path / "bare.csv"
    p.write_text("\n".join(line for line in (result_files / "r.csv").read_text().splitlines()
                           if not line.startswith("#")) + "\n")
    kind, bare = load_result(p)
    assert bare.grid is None and bare.params == {}
    for k in REQUIRED_CONTACT:
        np.testing.assert_array_equal(bare.table[k], res.table[k])
    saved = []
    monkeypatch.setattr(plots, "save", lambda fig, path: saved.append(path))
    assert main(["plot", str(p), "--out", str(tmp_path / "bare.png")]) == 0  # curves need no grid
    assert saved == [tmp_path / "bare.png"]


def test_csv_round_trip_is_exact(result_files):
    _, a = load_result(result_files / "r.csv")
    _, b = load_result(result_files / "r.nc")
    for k in CURVE_COLUMNS:
        if k != "seconds":
            np.testing.assert_array_equal(a.table[k], b.table[k], err_msg=k)


def test_plot_draws_saved_maps(result_files, tmp_path, capsys):
    out = tmp_path / "fig.png"
    assert main(["plot", str(result_files / "r.nc"), "--out", str(out)]) == 0
    maps = tmp_path / "fig_maps.png"
    assert out.stat().st_size > 10_000 and maps.stat().st_size > 10_000
    assert str(maps) in capsys.readouterr().out



def test_plot_no_maps_option(result_files, tmp_path, monkeypatch):
    saved = []
    monkeypatch.setattr(plots, "save", lambda fig, path: saved.append(str(path)))
    assert main(["plot", str(result_files / "r.nc"), "--out", str(tmp_path / "n.png"), "--no-maps"]) == 0
    assert saved == [str(tmp_path / "n.png")]


def test_plot_maps_axes_labels_aspect_colourbars(result_files, monkeypatch):
    figs = []
    monkeypatch.setattr(plots, "save", lambda fig, path: figs.append(fig))
    _, res = load_result(result_files / "r.nc")
    plots.plot_maps(res, "unused.png")
    fig = figs[0]
    main_axes = [ax for ax in fig.axes if ax.get_xlabel()]
    cbars = [ax for ax in fig.axes if not ax.get_xlabel()]
    assert len(main_axes) == 2 * len(res.maps) == 4  # P and H at D = 0.5 on both branches
    for ax in main_axes:
        unit = res.params["lateral_unit"]  # the run's lateral unit in words (issue 29: no "(dimensionless)")
        assert ax.get_xlabel() == f"X ({unit})" and ax.get_ylabel() == f"Y ({unit})"
        assert "dimensionless" not in ax.get_xlabel()
        assert ax.get_aspect() == 1.0
    labels = sorted(ax.get_ylabel() for ax in cbars)
    assert labels == [r"gap $H$ ($\varepsilon$)"] * 2 + [r"pressure $P$ ($W_{ad}/\varepsilon$, Eq. 7)"] * 2


def test_plot_maps_without_maps_is_a_clear_error(result_files):
    _, res = load_result(result_files / "r.csv")
    with pytest.raises(TengsimError, match="no maps"):
        plots.plot_maps(res, "x.png")


def _sweep_csv(path):
    R = np.logspace(5, 9, 9)
    p = 1e-6 * (R / 1e7) / (1 + (R / 1e7) ** 2)
    io.write_csv(path, {"R": R, "energy_per_cycle": p * 0.5, "average_power": p, "peak_voltage": R * 1e-6,
                        "peak_current": 1 / R}, {"optimum_ohm": 1e7, "optimum_power_W": float(p.max())})
    return R, p


def test_plot_draws_a_load_sweep(tmp_path, monkeypatch):
    src = tmp_path / "sweep.csv"
    R, p = _sweep_csv(src)
    kind, data = load_result(src)
    assert kind == "sweep" and data["header"]["optimum_ohm"] == 1e7
    figs, save = [], plots.save
    monkeypatch.setattr(plots, "save", lambda fig, path: figs.append(fig) or save(fig, path))
    assert main(["plot", str(src)]) == 0
    assert (tmp_path / "sweep.png").stat().st_size > 10_000
    axs = figs[0].axes
    assert [ax.get_xscale() for ax in axs] == ["log", "log"]
    assert "power" in axs[0].get_ylabel() and "energy" in axs[1].get_ylabel()
    assert "best load 1e+07" in axs[0].get_legend().get_texts()[0].get_text()


def test_sweep_lacking_columns_is_refused(tmp_path):
    p = tmp_path / "s.csv"
    io.write_csv(p, {"R": [1.0, 2.0], "average_power": [1.0, 2.0]})
    with pytest.raises(TengsimError, match="load sweep lacks column.s. energy_per_cycle"):
        load_result(p)


def test_plot_of_a_folder_goes_to_the_study_plotter(tmp_path, monkeypatch, capsys):
    calls = []
    fake = types.ModuleType("tengsim.study.plot")
    fake.plot_study = lambda d, out: calls.append((d, out)) or [d / "study.png"]
    monkeypatch.setitem(sys.modules, "tengsim.study.plot", fake)
    assert main(["plot", str(tmp_path)]) == 0
    assert calls == [(tmp_path, tmp_path / "design.png")]
    assert "study.png" in capsys.readouterr().out


def test_plot_of_a_folder_that_is_no_study_is_one_error_line(tmp_path, capsys):
    assert main(["plot", str(tmp_path)]) == 2
    _one_line_error(capsys, str(tmp_path))
    assert list(tmp_path.iterdir()) == []


def test_loaded_result_without_grid_is_a_contact_result():
    t = {k: np.zeros(2) for k in CURVE_COLUMNS}
    t["branch"] = np.array(["approach", "retraction"])
    res = ContactResult(table=t, grid=None)
    assert res.branch("approach")["D"].shape == (1,)


def test_plot_draws_the_output_of_device_sweep(tmp_path, monkeypatch):
    src = tmp_path / "sw.csv"
    assert main(["device", "sweep", "--out", str(src), "--points", "3", "--cycles", "2", "--quiet"]) == 0
    kind, data = load_result(src)
    assert kind == "sweep" and len(data["R"]) == 3
    saved = []
    monkeypatch.setattr(plots, "save", lambda fig, path: saved.append((fig, path)))
    assert main(["plot", str(src)]) == 0
    fig, path = saved[0]
    assert path == tmp_path / "sw.png"
    best = fig.axes[0].get_legend().get_texts()[0].get_text()
    assert f"best load {data['header']['optimum_ohm']:.3g}" in best
