"""Symmetry-reduced kernels (issue 22 item 3): tengsim.kernels.mirror.MirrorKernel against the full kernel."""
import pickle

import numpy as np
import pytest
from conftest import registered

from tengsim.plugins import KERNELS

from tengsim.errors import TengsimError
from tengsim.grid import Grid, Mirror
from tengsim.kernels import MirrorKernel, make_kernel, make_mirror_kernel

FILMS = [
    {},
    {"thickness": 0.7, "substrate": "bonded", "poisson": 0.3},
    {"thickness": 0.7, "substrate": "bonded", "poisson": 0.5},
    {"thickness": 1.3, "substrate": "frictionless", "poisson": 0.3},
    {"thickness": 0.4, "substrate": "frictionless", "poisson": 0.5},
]
GRIDS = [Grid(9, 9, 0.3, 0.3), Grid(11, 7, 0.2, 0.35), Grid(7, 13, 0.5, 0.25)]  # nx ≠ ny, dx ≠ dy
AXES = [(0,), (1,), (0, 1)]
TOL = 1e-12


def _field(m: Mirror, seed=0):
    return np.random.default_rng(seed).standard_normal(m.reduced_shape)


@pytest.mark.parametrize("boundary", registered("boundary"))
@pytest.mark.parametrize("fp", FILMS, ids=lambda f: "halfspace" if not f else f"{f['substrate']}-{f['poisson']}")
def test_reduced_apply_equals_full_kernel(boundary, fp):
    """reduced.apply(block) = reduce(K unfold(block)) to 1e-12 relative, and the energies agree:
    Σ_full p·Kp = Σ_block weights·p·(Kp), on every grid and mirror (one axis, both)."""
    for g in GRIDS:
        full = make_kernel(boundary, g, 1.3, **fp)
        for axes in AXES:
            m = Mirror(g, axes)
            mk = MirrorKernel(boundary, g, 1.3, m, **fp)
            pb = _field(m, seed=len(axes))
            pf = m.unfold(pb)
            wf = full.apply(pf)
            wb = mk.reduced.apply(pb)
            scale = np.max(np.abs(wf))
            assert np.max(np.abs(wb - m.reduce(wf))) <= TOL * scale, (g, axes)
            e_full, e_block = np.sum(pf * wf), np.sum(m.weights() * pb * wb)
            assert abs(e_full - e_block) <= TOL * abs(e_full) * 10, (g, axes)
            # the public scipy.fft path agrees with the direct one
            assert np.max(np.abs(mk._conv._apply_public(pb) - wb)) <= TOL * scale
            # the full-grid apply: reduce → block → unfold
            assert np.max(np.abs(mk.apply(pf) - wf)) <= TOL * scale


def test_interface_attributes_and_params():
    g = Grid(9, 11, 0.2, 0.2)
    for boundary in KERNELS.names():
        for fp in FILMS:
            full = make_kernel(boundary, g, 0.35, **fp)
            mk = make_mirror_kernel(boundary, g, 0.35, (0, 1), **fp)
            assert mk.params() == full.params()
            assert mk.grid == g and mk.coupling == 0.35 and mk.mirror == Mirror(g, (0, 1))
            assert mk.periodic == full.periodic and mk.pinned_mean == full.pinned_mean
            assert mk.film == full.film
            r = mk.reduced
            assert r.grid == mk.mirror.reduced_grid and r.grid.shape == (5, 6)
            assert (r.periodic, r.pinned_mean, r.coupling) == (mk.periodic, mk.pinned_mean, mk.coupling)
            if boundary == "periodic":
                assert mk.mean_compliance == full.mean_compliance == r.mean_compliance
            if fp:
                assert (mk.thickness, mk.substrate, mk.poisson) == (full.thickness, full.substrate, full.poisson)


def test_out_argument_and_repeated_calls():
    g = Grid(9, 9, 0.25, 0.25)
    for boundary in KERNELS.names():
        mk = make_mirror_kernel(boundary, g, 1.0, (0, 1))
        pb = _field(mk.mirror)
        w1 = mk.reduced.apply(pb)
        out = np.empty(mk.mirror.reduced_shape)
        w2 = mk.reduced.apply(pb, out=out)
        assert w2 is out and np.array_equal(w1, out)
        mk.reduced.apply(2 * pb)  # the returned array is not the next call's buffer
        assert np.array_equal(w1, out) and np.array_equal(mk.reduced.apply(pb), w1)
        full_out = np.empty(g.shape)
        assert mk.apply(mk.mirror.unfold(pb), out=full_out) is full_out


def test_asymmetric_field_is_refused():
    g = Grid(9, 9, 0.25, 0.25)
    for boundary in KERNELS.names():
        mk = make_mirror_kernel(boundary, g, 1.0, (0, 1))
        p = mk.mirror.unfold(_field(mk.mirror))
        p[0, 3] += 1e-6
        with pytest.raises(TengsimError, match="not mirror symmetric"):
            mk.apply(p)
        with pytest.raises(TengsimError, match="not on the"):
            mk.apply(np.ones((9, 7)))
        with pytest.raises(TengsimError, match="block"):
            mk.reduced.apply(np.ones(g.shape))
    # symmetric along X only: fine for an X mirror, refused by an X-and-Y one
    p = make_mirror_kernel("free", g, 1.0, (0,)).mirror.unfold(np.random.default_rng(3).standard_normal((5, 9)))
    make_mirror_kernel("free", g, 1.0, (0,)).apply(p)
    with pytest.raises(TengsimError, match="not mirror symmetric"):
        make_mirror_kernel("free", g, 1.0, (0, 1)).apply(p)


@pytest.mark.parametrize("bad, match", [
    (dict(boundary="halfspace"), "boundary"),
    (dict(coupling=0.0), "coupling"),
    (dict(coupling=-1.0), "coupling"),
    (dict(axes=(2,)), "axes"),
    (dict(axes=()), "axes"),
    (dict(grid=Grid(8, 9, 0.2, 0.2)), "odd"),
    (dict(thickness=-1.0), "thickness"),
    (dict(thickness=1.0, poisson=0.7), "poisson"),
    (dict(thickness=1.0, substrate="glued"), "substrate"),
    (dict(thikness=1.0), "thikness"),
])
def test_bad_inputs_name_the_value(bad, match):
    args = dict(boundary="free", grid=Grid(9, 9, 0.2, 0.2), coupling=1.0, axes=(0, 1))
    args.update(bad)
    with pytest.raises(TengsimError, match=match):
        make_mirror_kernel(args.pop("boundary"), args.pop("grid"), args.pop("coupling"), args.pop("axes"), **args)


def test_mirror_grid_must_be_the_kernels():
    with pytest.raises(TengsimError, match="grid"):
        MirrorKernel("free", Grid(9, 9, 0.2, 0.2), 1.0, Mirror(Grid(11, 9, 0.2, 0.2), (0,)))


def test_pickles_and_memory_is_a_fraction():
    """The kernel pickles (study workers); it holds no full-grid spectrum: its spectrum has at most
    (n + 1)² / 4 ... (2n)² / 4 real entries against the full kernel's complex (2n)·n (free)."""
    g = Grid(39, 39, 0.1, 0.1)
    mk = make_mirror_kernel("free", g, 0.35, (0, 1))
    full = make_kernel("free", g, 0.35)
    assert mk._conv.spectrum.nbytes <= 0.3 * full._spectrum.nbytes
    mk2 = pickle.loads(pickle.dumps(mk))
    pb = _field(mk.mirror)
    assert np.array_equal(mk2.reduced.apply(pb), mk.reduced.apply(pb))
    per = make_mirror_kernel("periodic", g, 0.35, (0, 1))
    assert per._conv.spectrum.nbytes <= 0.6 * make_kernel("periodic", g, 0.35)._spectrum.nbytes


@pytest.mark.parametrize("lines", [2, 3])
def test_chunked_even_transforms(monkeypatch, lines):
    """The periodic kernel transforms its lines in chunks on large grids, two lines per complex FFT:
    force tiny chunks here (odd and even counts)."""
    from tengsim.kernels import dct

    monkeypatch.setattr(dct.MirrorConvolver, "_lines", property(lambda self: lines))
    for g in GRIDS:
        full = make_kernel("periodic", g, 0.8, thickness=0.9, poisson=0.3)
        for axes in AXES:
            mk = make_mirror_kernel("periodic", g, 0.8, axes, thickness=0.9, poisson=0.3)
            pb = _field(mk.mirror, seed=7)
            wf = full.apply(mk.mirror.unfold(pb))
            assert np.max(np.abs(mk.reduced.apply(pb) - mk.mirror.reduce(wf))) <= TOL * np.max(np.abs(wf))


@pytest.mark.parametrize("split", [True, False])
def test_split_and_plain_dct1_agree(monkeypatch, split):
    """The free kernel's DCT-I runs split in half-length transforms on large grids, plain on small ones:
    force each here, on every mirror, half-space and a film."""
    from tengsim.kernels import dct

    monkeypatch.setattr(dct.MirrorConvolver, "SPLIT_MIN", 1 if split else 10**9)
    for g in GRIDS[1:]:
        for fp in ({}, FILMS[3]):
            full = make_kernel("free", g, 0.8, **fp)
            for axes in AXES:
                mk = make_mirror_kernel("free", g, 0.8, axes, **fp)
                assert mk._conv.split is split
                pb = _field(mk.mirror, seed=11)
                wf = full.apply(mk.mirror.unfold(pb))
                scale = np.max(np.abs(wf))
                assert np.max(np.abs(mk.reduced.apply(pb) - mk.mirror.reduce(wf))) <= TOL * scale
                assert np.max(np.abs(mk._conv._apply_public(pb) - mk.mirror.reduce(wf))) <= TOL * scale
