"""The charged pattern's near field of a design (design/nearfield.py, issue 51): a uniform map is the uniform sheet,
one Fourier mode against its closed form, the decay height scales with the pitch, far above the surface the field
is σ A/S/ε0, and a tiny design's report and design.nc carry the numbers."""
import dataclasses
import math

import numpy as np
import pytest
from scipy.optimize import brentq

from tengsim.constants import EPS0
from tengsim.design.nearfield import GAP_NAMES, GAPS_M, LEVEL, attributes, pattern_nearfield, report_line
from tengsim.device.nearfield import PatternField

SIG, T, ER, D0 = 5.84e-6, 400e-6, 2.4, 100e-6


def disk(n=64, r=0.3):
    """A charged disk of radius r × the pitch in the middle of a square cell (binary pixels)."""
    c = (np.arange(n) + 0.5) / n - 0.5
    return (np.hypot(c[:, None], c[None, :]) <= r).astype(float)


def test_uniform_map_is_the_uniform_sheet():
    nf = pattern_nearfield(np.ones((32, 32)), 1e-6, 1e-6, SIG, T, ER, D0)
    np.testing.assert_allclose(nf.peak_over_uniform, 1.0, rtol=0, atol=1e-12)
    np.testing.assert_allclose(nf.voltage_spread_over_uniform, 0.0, rtol=0, atol=1e-12)
    assert nf.decay_height_m == 0.0 and nf.area_fraction == 1.0
    assert nf.uniform_field_V_m == pytest.approx(SIG / EPS0, rel=1e-14)
    assert np.max(np.abs(PatternField(np.ones((32, 32)), 1e-6, SIG, T, ER).field_z(1e-6, 0.0))) < 1e-12 * SIG / EPS0


def test_one_fourier_mode_against_its_closed_form():
    """f = 1/2 + 1/2 cos(2π x/p) on N pixels: one mode of amplitude σ sinc(1/N)/4 each side (the pixels' cell
    factor), so E_p(0) = (σ/2) sinc(1/N) coth(qx)/(ε0 (coth qx + ε_r coth qT)) cos(2π x/p) and the surface
    potential's spread 2 (σ/2) sinc(1/N)/(ε0 q (coth qx + ε_r coth qT)); the decay height solves
    (σ/2) sinc(1/N) cosh(q(x − z))/(sinh(qx) ε0 (coth qx + ε_r coth qT)) = 1 % of σ/(2ε0)."""
    n, p = 64, 5e-6
    f = np.repeat((0.5 + 0.5 * np.cos(2 * np.pi * np.arange(n) / n))[:, None], 8, axis=1)
    nf = pattern_nearfield(f, p, p / 8, SIG, T, ER, D0)  # a rectangular cell: 64 x 8 pixels of one size
    q, amp = 2 * np.pi / p, np.sinc(1 / n)
    assert nf.area_fraction == pytest.approx(0.5, abs=1e-15)
    for x, peak, spread in zip(nf.gaps_m, nf.peak_over_uniform, nf.voltage_spread_over_uniform):
        den = 1 / math.tanh(q * x) + ER / math.tanh(q * T)
        assert peak == pytest.approx(1 + amp / math.tanh(q * x) / den, rel=1e-12)
        assert spread == pytest.approx(2 * amp / (q * x * den), rel=1e-12)
    x = nf.decay_gap_m
    assert x == pytest.approx(max(D0, 10 * p))
    den = 1 / math.tanh(q * x) + ER / math.tanh(q * T)
    z = brentq(lambda z: amp * math.cosh(q * (x - z)) / math.sinh(q * x) / den - LEVEL, 0, x, xtol=1e-15)
    assert nf.decay_height_m == pytest.approx(z, rel=2e-3)  # bisected to 1e-3 of the height


def test_decay_height_scales_with_the_pitch():
    """The same disk map at pitch p and 2p (T and the open gap >> both): twice the height within 1 %."""
    a = pattern_nearfield(disk(), 1e-6, 1e-6, SIG, T, ER, D0)
    b = pattern_nearfield(disk(), 2e-6, 2e-6, SIG, T, ER, D0)
    assert 0.1e-6 < a.decay_height_m < 1e-6
    assert b.decay_height_m / a.decay_height_m == pytest.approx(2.0, rel=0.01)


def test_far_above_the_surface_the_field_is_the_uniform_sheet():
    """z = 3 pitches up in a gap of 50: |E_u + E_p| = σ (A/S)/ε0 within 1e-3 everywhere in the cell; in a gap of
    1 nm (<< the pixel, << p/(2π ε_r)) the field at the surface is the local σ f/ε0 (σ/ε0 on the disk, 0 off it:
    the charge's field ends on the electrode just above it): its largest and smallest values within 1 % of σ/ε0
    and 0 (the modes' cut at the pixel rings at the edge: 0.993, 0.0021), its mean σ (A/S)/ε0 to round-off."""
    f, p = disk(), 1e-6
    pf = PatternField(f, p, SIG, T, ER)
    e_u = SIG * f.mean() / EPS0
    assert pf.uniform_field() == pytest.approx(e_u, rel=1e-14)
    far = e_u + pf.field_z(50 * p, 3 * p)
    assert np.max(np.abs(far / e_u - 1)) < 1e-3
    thin = (e_u + pf.field_z(1e-9, 0.0)) / (SIG / EPS0)
    assert abs(thin.max() - 1) < 0.01 and abs(thin.min()) < 0.01
    assert thin.mean() == pytest.approx(f.mean(), rel=1e-12)
    assert pattern_nearfield(f, p, p, SIG, T, ER, D0).peak_over_uniform[0] > 2.0  # 100 nm: far from uniform


TINY = {"shape": "pyramid", "pitch": "1um", "base": "0.5um", "height": "0.2um", "E_star": "5MPa", "W": "20mJ/m2",
        "eps": "50nm", "p_max": "20kPa", "p_step": "5kPa", "boundary": "free", "tol": 0.05, "retraction": False}


@pytest.fixture(scope="module")
def tiny():
    from tengsim.design import plan_design, run_design

    return run_design(plan_design(TINY))


def test_design_report_and_dataset_carry_the_near_field(tiny, tmp_path):
    """A tiny design (2.4 s): the charge of its map at the largest pressure kept; the map's A/S is the design's at
    that state within 1 % (the edge pixels), the far field its uniform sheet within 1e-3, and report.md and
    design.nc carry the numbers."""
    import xarray as xr

    from tengsim.design import write_design
    from tengsim.design.nearfield import _released_map, charged_fraction
    from tengsim.design.walk import peak_separation

    nf = tiny.summary["nearfield"]
    m, p_pa = _released_map(tiny.maps)
    assert nf.pressure_Pa == p_pa and abs(p_pa - 20e3) < 0.02 * 20e3
    a = tiny.maps.branch("approach")
    area = float(np.asarray(a["charged_fraction"])[np.argmin(np.abs(np.asarray(a["D"]) - m["D"]))])
    assert nf.area_fraction == pytest.approx(area, rel=0.01)
    assert nf.pitch_x_m == pytest.approx(1e-6) and nf.pitch_y_m == pytest.approx(1e-6)
    assert nf.gaps_m == (*GAPS_M, pytest.approx(1e-6))
    assert all(v > 1.0 for v in nf.peak_over_uniform) and 0 < nf.decay_height_m < 1e-6
    pf = PatternField(charged_fraction(m["H"], peak_separation(tiny.plan)), nf.pitch_x_m, SIG, T, ER)
    far = nf.uniform_field_V_m + pf.field_z(50e-6, 3e-6)
    assert np.max(np.abs(far / (SIG * nf.area_fraction / EPS0) - 1)) < 1e-3
    write_design(tiny, tmp_path, figures=False)
    text = (tmp_path / "report.md").read_text()
    assert "Near field of the charged pattern" in text and f"{nf.peak_over_uniform[1]:.3g}× / " in text
    with xr.open_dataset(tmp_path / "design.nc") as ds:
        assert ds.attrs["nearfield_decay_height_m"] == pytest.approx(nf.decay_height_m, rel=1e-12)
        for g, v in zip(GAP_NAMES, nf.peak_over_uniform):
            assert ds.attrs[f"nearfield_peak_over_uniform_at_{g}"] == pytest.approx(v, rel=1e-12)
        for g, v in zip(GAP_NAMES, nf.voltage_spread_over_uniform):
            assert ds.attrs[f"nearfield_voltage_spread_over_uniform_at_{g}"] == pytest.approx(v, rel=1e-12)


def test_without_maps_the_report_and_dataset_say_so(tiny):
    from tengsim.design.report import report_text

    none = dataclasses.replace(tiny, summary={**tiny.summary, "nearfield": None})
    assert "Near field of the charged pattern: n/a (no maps kept (maps = false)" in report_text(none, [])
    attrs = attributes(None)
    assert attrs["nearfield_decay_height_m"].startswith("n/a: no maps kept")
    assert set(attrs) == set(attributes(tiny.summary["nearfield"]))
    assert "n/a" in report_line(None)
    from tengsim.design.nearfield import design_nearfield

    assert design_nearfield(tiny.maps, dataclasses.replace(tiny.plan, maps=False)) is None
