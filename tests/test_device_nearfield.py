"""The charged pattern's near field (device/nearfield.py) against a hand Fourier series of strips."""
import math

import numpy as np
import pytest

from tengsim.device import EPS0
from tengsim.device.nearfield import PatternField

P, SIG, T, ER = 10e-6, 50e-6, 100e-6, 3.0


def strips(n=256, cells=64):
    f = np.zeros((n, n))
    f[:cells, :] = 1.0  # charged strips x in [0, w), w = p/4, along y
    return PatternField(f, P, SIG, T, ER), cells / n * P


def hand_series(X, w, gap, z, terms=4000):
    """Strip of width w, period p: s_n = 2 sigma sin(pi n w/p)/(pi n), cos about the strip's centre."""
    e = np.zeros_like(X)
    phi = np.zeros_like(X)
    for m in range(1, terms):
        q = 2 * math.pi * m / P
        s = 2 * SIG * math.sin(math.pi * m * w / P) / (math.pi * m)
        den = EPS0 * (1 / math.tanh(q * gap) + ER / math.tanh(q * T))
        c = np.cos(q * (X - w / 2))
        shape = math.exp(-q * z) * (1 + math.exp(-2 * q * (gap - z))) / (1 - math.exp(-2 * q * gap))
        e += s / den * shape * c
        phi += s / (den * q) * c
    return e, phi


def test_strip_near_field_against_its_fourier_series():
    pf, w = strips()
    X = (np.arange(256) + 0.5) / 256 * P
    for gap, z in ((2e-6, 0.5e-6), (20e-6, 1e-6)):
        e_ref, phi_ref = hand_series(X, w, gap, z)
        e = pf.field_z(gap, z)[:, 0]
        np.testing.assert_allclose(e, e_ref, atol=1e-6 * np.max(np.abs(e_ref)))
        phi = pf.surface_potential(gap)[:, 0]
        np.testing.assert_allclose(phi, phi_ref, atol=2e-3 * np.max(np.abs(phi_ref)))  # 1/n^2 tail past Nyquist
    assert pf.area_fraction == pytest.approx(0.25)


def test_far_field_is_the_uniform_sheet():
    pf, _ = strips()
    near = np.max(np.abs(pf.field_z(50e-6, 0.2e-6)))
    far = np.max(np.abs(pf.field_z(50e-6, 2 * P)))  # two pitches up: exp(-4 pi) of the first mode
    assert near > 0.5 * pf.uniform_field()  # at the surface the patches' field is of the mean's order
    assert far < 1e-5 * pf.uniform_field()
    assert pf.uniform_field() == pytest.approx(SIG * 0.25 / EPS0)


def test_rectangular_cell_strips_along_y_against_the_series():
    """A cell of 3p x p (48 x 256 pixels), strips of width p/4 varying along y: the same hand series with the pitch
    along y (ky/pitch_y); the field does not vary along x."""
    f = np.zeros((48, 256))
    f[:, :64] = 1.0
    pf = PatternField(f, 3 * P, SIG, T, ER, pitch_y_m=P)
    Y = (np.arange(256) + 0.5) / 256 * P
    e_ref, phi_ref = hand_series(Y, P / 4, 2e-6, 0.5e-6)
    e = pf.field_z(2e-6, 0.5e-6)
    np.testing.assert_allclose(e[7], e_ref, atol=1e-6 * np.max(np.abs(e_ref)))
    assert np.ptp(e, axis=0).max() < 1e-9 * np.max(np.abs(e_ref))
    assert PatternField(f, P, SIG, T, ER).pitch_y_m == P  # square by default
