"""Figures of a physical run in physical units (issue 29 item 5): the axis labels are read back."""
import numpy as np
import pytest

from tengsim import plots
from tengsim.cli.main import main
from tengsim.results.read import load_result

PYR = ["contact", "pyramid", "--pitch", "10um", "--base", "5um", "--height", "3.5um", "--E-star", "1MPa",
       "--W", "50mJ/m2", "--eps", "100nm", "--dx", "1um", "--quiet"]


@pytest.fixture(scope="module")
def physical_load_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("phys") / "p.nc"
    assert main([*PYR, "--control", "load", "--f-max", "20kPa", "--f-step", "5kPa", "--maps-at", "10kPa",
                 "--out", str(out)]) == 0
    return out


def _figs(monkeypatch):
    figs = []
    monkeypatch.setattr(plots, "save", lambda fig, path: figs.append(fig))
    return figs


def _labels(fig):
    return [(ax.get_xlabel(), ax.get_ylabel()) for ax in fig.axes]


def test_curves_of_a_physical_run_in_kpa_and_um_titled_with_the_shape(physical_load_run, monkeypatch):
    figs = _figs(monkeypatch)
    assert main(["plot", str(physical_load_run), "--out", "unused.png"]) == 0
    curves, maps = figs
    labels = _labels(curves)
    assert labels[0] == ("rigid approach α (µm)", "force per cell f (µN)")
    assert labels[1] == ("rigid approach α (µm)", "contact length λc (µm)")
    assert labels[2] == ("nominal pressure p (kPa)", "contact length λc (µm)")
    assert labels[3] == ("", "nominal pressure p (kPa)")  # the first panel's right-hand axis
    title = curves._suptitle.get_text()
    assert title.startswith("pyramid: pitch 10 µm, base 5 µm, height 3.5 µm; E* = 1 MPa, W = 50 mJ/m², ε = 100 nm")
    res = load_result(physical_load_run)[1]
    drawn = np.concatenate([ln.get_xdata() for ln in curves.axes[2].get_lines()])  # the run's pressures, in kPa
    assert np.nanmax(drawn) == pytest.approx(np.nanmax(res.table["pressure_Pa"]) / 1e3, rel=1e-9)
    lo, hi = curves.axes[0].get_ylim()  # the right-hand axis reads the same curve as a pressure
    plo, phi = curves.axes[3].get_ylim()
    k = float(np.nanmax(res.table["pressure_Pa"]) / 1e3 / (np.nanmax(res.table["F_N"]) * 1e6))
    assert (plo, phi) == pytest.approx((lo * k, hi * k), rel=1e-9)
    img_axes = [ax for ax in maps.axes if ax.get_xlabel()]
    assert {ax.get_xlabel() for ax in img_axes} == {"x (µm)"} and {ax.get_ylabel() for ax in img_axes} == {"y (µm)"}
    titles = {ax.get_title() for ax in img_axes}
    assert any(t.startswith("approach, p = 10 kPa (α = ") for t in titles), titles
    bars = sorted(ax.get_ylabel() for ax in maps.axes if not ax.get_xlabel())
    assert any(b.startswith("contact pressure (") and "Pa; compressive > 0)" in b for b in bars), bars
    assert any(b.startswith("gap (") and b.endswith("m)") for b in bars), bars
    for x, y in _labels(curves) + _labels(maps):
        assert "dimensionless" not in x + y and "Eq. 10" not in x + y


def test_device_time_series_in_prefixed_units_with_a_power_panel(tmp_path, monkeypatch):
    out = tmp_path / "d.csv"
    assert main(["device", "fig7", "--cycles", "2", "--dt", "1e-3", "--quiet", "--out", str(out)]) == 0
    figs = _figs(monkeypatch)
    assert main(["plot", str(out), "--out", str(tmp_path / "d.png")]) == 0
    fig = figs[0]
    ylabels = [ax.get_ylabel().replace("\n", " ") for ax in fig.axes]
    assert "current I (µA)" in ylabels and "voltage V (V)" in ylabels
    assert any(y.startswith("power into the load (") and y.endswith("W)") for y in ylabels), ylabels
    assert fig.axes[-1].get_xlabel() == "time t (ms)"
    for ax in fig.axes:  # no '1e-10'-style offset or exponent on any axis
        fig.canvas.draw()
        assert ax.yaxis.get_offset_text().get_text() == "", ax.get_ylabel()
    _, data = load_result(out)
    power = ax_power = [a for a in fig.axes if a.get_ylabel().startswith("power")][0]
    drawn = ax_power.get_lines()[0].get_ydata()
    unit = power.get_ylabel().split("(")[-1].rstrip(")")
    factor = {"W": 1, "mW": 1e-3, "µW": 1e-6, "nW": 1e-9}[unit]
    np.testing.assert_allclose(drawn * factor, np.asarray(data["power"]), rtol=1e-12)
