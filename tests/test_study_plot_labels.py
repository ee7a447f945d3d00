"""Design maps of a study in words and units (issue 29 item 5): categorical colours for shapes, a line
style per pitch, status marks for points that are not ok, axis labels read back (no 'contact.pitch')."""
import numpy as np
import pytest
import xarray as xr

from tengsim import plots
from tengsim.study.plot import STATUS_MARKS, axis_label, axis_scale, plot_study

SHAPES, PITCHES = ["pyramid", "cone"], ["1.2um", "2um"]


@pytest.fixture
def study_dir(tmp_path):
    P = np.linspace(0.0, 1.5e5, 7)
    rng = np.random.default_rng(0)
    dims = ("contact.shape", "contact.pitch")
    scalar = lambda scale: (dims, scale * (1 + rng.random((2, 2))))  # noqa: E731
    ds = xr.Dataset(
        {"status": (dims, np.array([["ok", "under_resolved"], ["ok", "not_converged"]])),
         "pull_off_F": scalar(-1.0), "pull_off_Pa": scalar(-1e5), "S_V_per_kPa": scalar(0.1),
         "linear_range_Pa": scalar(5e4), "P_sat_Pa": scalar(1e5), "area_fraction_0": scalar(0.3),
         "V_sat": scalar(50.0), "adhesive_full_contact": (dims, np.array([[1, 0], [0, 0]])),
         "V_OC": (dims + ("applied_pressure",), 30 + rng.random((2, 2, 7)))},
        coords={"contact.shape": SHAPES, "contact.pitch": PITCHES, "applied_pressure": ("applied_pressure", P)})
    ds.to_netcdf(tmp_path / "study.nc")
    return tmp_path


def test_axis_values_in_one_prefixed_unit():
    assert axis_scale(["1.2um", "2um"])[:2] == ("µm", ["1.2", "2"])
    assert axis_scale(["0.1MPa", "3MPa"])[:2] == ("MPa", ["0.1", "3"])
    assert axis_scale(["pyramid", "cone"])[:2] == ("", ["pyramid", "cone"])
    assert axis_label(xr.Dataset(coords={"contact.E_star": ["1MPa", "2MPa"]}), "contact.E_star") == "E* (MPa)"


def test_design_maps_and_voc_in_words_with_units_and_status_marks(study_dir, monkeypatch):
    figs = []
    monkeypatch.setattr(plots, "save", lambda fig, path: figs.append(fig))
    plot_study(study_dir, study_dir / "design.png")
    maps, voc = figs
    for ax in [a for a in maps.axes if a.get_xlabel()]:
        if a_is_map(ax):
            assert ax.get_xlabel() == "shape" and ax.get_ylabel() == "pitch (µm)"
            assert [t.get_text() for t in ax.get_yticklabels()] == ["1.2", "2"]
    labels = " ".join(ax.get_ylabel() for ax in maps.axes)
    assert "contact." not in labels and "Eq. 10" not in labels and "pull-off pressure (kPa" in labels
    legend = [t.get_text() for t in maps.legends[0].get_texts()]
    assert legend == ["status not converged", "status under resolved", "full contact at zero load"]
    # V_OC(P): one colour per shape (categorical), one line style per pitch, status marks at the curves' ends
    ax = voc.axes[0]
    assert ax.get_xlabel() == "nominal pressure (kPa)" and ax.get_ylabel().startswith("open-circuit voltage V_OC (V)")
    curves = [ln for ln in ax.get_lines() if len(ln.get_xdata()) > 1]
    assert len(curves) == 4
    colours = {tuple(np.round(ln.get_color(), 3)) if not isinstance(ln.get_color(), str) else ln.get_color()
               for ln in curves}
    assert len(colours) == 2 and len({ln.get_linestyle() for ln in curves}) == 2
    ends = [ln for ln in ax.get_lines() if len(ln.get_xdata()) == 1]
    assert sorted(ln.get_marker() for ln in ends) == sorted([STATUS_MARKS["under_resolved"][0],
                                                             STATUS_MARKS["not_converged"][0]])
    texts = [t.get_text() for t in ax.get_legend().get_texts()]
    assert texts[:4] == ["shape pyramid", "shape cone", "pitch 1.2 µm", "pitch 2 µm"]
    assert "status under resolved" in texts and "status not converged" in texts


def a_is_map(ax):
    return bool(ax.get_images() or ax.collections)
