"""Parts of tengsim.calibrate checked on their own (no contact solve): the nodes' pressure range against the data's,
and the correlation when σ is unbounded at grid points with no charged area."""
import types

import numpy as np
import pytest


def _prob(free, top, E_bounds=(0.1e6, 10e6), E_ref=1e6):
    from tengsim.calibrate.data import Curve

    c = Curve("c", np.linspace(top / 10, top, 10), np.ones(10), ("approach",) * 10)
    return types.SimpleNamespace(curves=[c], free=free, bounds={"E_star": E_bounds}, E_ref=E_ref)


def test_nodes_reach_the_datas_top_pressure_on_the_datas_own_steps_when_E_star_is_fixed():
    """E* fixed (λ = 1): p_max is the data's top rounded up to 1, 2, 2.5, 5 × 10^k, so data every p_max/20 fall on
    the nodes' own pressures (no interpolation across a jump in A/S between two node pressures)."""
    from tengsim.calibrate.run import _p_max

    assert _p_max(_prob(("sigma", "W", "eps"), 100e3), "g", ("g",)) == pytest.approx(100e3)
    assert _p_max(_prob(("sigma", "W"), 30e3), "g", ("g",)) == pytest.approx(50e3)


def test_nodes_reach_the_datas_top_pressure_at_the_softest_E_star_when_free():
    """E* free: a node at E_ref is read at P·E_ref/E*, so it must reach top·E_ref/E*_min."""
    from tengsim.calibrate.run import _p_max

    p = _p_max(_prob(("sigma", "E_star"), 10e3, (0.5e6, 2e6), 1e6), "g", ("g",))
    assert p >= 10e3 * 1e6 / 0.5e6 and p <= 2 * 1.05 * 10e3 * 1e6 / 0.5e6


def test_correlation_stays_finite_where_a_grid_point_has_no_charged_area():
    """A grid point whose A/S is 0 at every data pressure (c = 0) leaves σ unbounded there; with no likelihood
    weight it must not turn the correlation matrix into NaN."""
    from tengsim.calibrate.fit import _correlation

    prob = types.SimpleNamespace(free=("sigma", "W"), contact_free=("W",), bounds={"sigma": (1e-8, 5e-4)})
    model = types.SimpleNamespace(prob=prob, sigma_hat=lambda b, c: np.where(c > 0, b / np.maximum(c, 1e-300), 1e-8))
    pts = np.log(np.array([[0.01], [0.02], [0.03], [0.04]]))
    dev = np.array([2000.0, 1.0, 0.0, 1.5])  # the c = 0 point is far outside: exp(-1000) = 0 weight
    b = np.array([0.0, 1.0, 1.1, 1.2])
    c = np.array([0.0, 1e5, 1.1e5, 1.2e5])
    names, corr = _correlation(model, pts, dev, 0.0, b, c, 0.01)
    assert names == ("sigma", "W")
    assert np.isfinite(corr).all() and np.allclose(np.diag(corr), 1.0) and abs(corr[0, 1]) <= 1.0


def test_a_bare_bound_read_as_SI_is_refused_where_implausible():
    """--bounds W=10:60 (meant as mJ/m²) is 10–60 J/m²: refused naming --bounds and the value, as a design's
    key is, instead of a later message that blamed the design file; bounds with units pass."""
    import pytest

    from tengsim.calibrate.problem import parse_bounds
    from tengsim.errors import TengsimError

    with pytest.raises(TengsimError, match=r"--bounds W: W = 60 is read as 60 J/m2.*'60mJ/m2'"):
        parse_bounds("W=10:60")
    with pytest.raises(TengsimError, match=r"--bounds eps: eps = 30 is read as 30 m"):
        parse_bounds("eps=30:80")
    assert parse_bounds("W=10mJ/m2:60mJ/m2,eps=3e-8:8e-8") == {"W": pytest.approx((0.01, 0.06)),
                                                                "eps": pytest.approx((3e-8, 8e-8))}


def test_residual_sizes_are_said_in_the_noise_models_unit():
    """The interpolation's error and the noise are said as % of V_OC (relative noise), volts (absolute) or
    multiples of voc_err_V (known errors), never as bare residual numbers."""
    from types import SimpleNamespace

    from tengsim.calibrate.fit import residual_text

    assert residual_text(0.0233, SimpleNamespace(known_errors=False, noise="relative")) == "2.33 % of V_OC"
    assert residual_text(0.5, SimpleNamespace(known_errors=False, noise="absolute")) == "0.5 V"
    assert residual_text(1.2, SimpleNamespace(known_errors=True, noise="relative")) == "1.2 × voc_err_V"


def _jumping_nodes():
    """Synthetic nodes: A/S jumps from about 0.06 to 0.9 at a pressure 20 kPa + 40 kPa × u, u = log W on [0, 1]."""
    from tengsim.calibrate.surrogate import Node

    P = np.linspace(0, 100e3, 21)

    def curve(u):
        return np.where(P < 20e3 + 40e3 * u, 0.05 + 0.05 * P / 100e3, 0.9 + 0.05 * P / 100e3)

    return P, [Node(u, 0.0, True, P, {"approach": curve(u), "retraction": curve(u)}) for u in np.linspace(0, 1, 5)]


def test_the_jump_is_interpolated_to_where_it_moves_between_nodes_not_blended_at_fixed_pressure():
    from tengsim.calibrate.surrogate import Surrogate

    P, nodes = _jumping_nodes()
    u = 0.375  # between the nodes at 0.25 (jump at 30 kPa) and 0.5 (40 kPa): the truth jumps at 35 kPa
    q = np.linspace(20e3, 50e3, 31)
    # the truth as a node there would give it: its curve on the 5 kPa steps, linear between (the jump from 30 to 35)
    truth = np.interp(q, P, np.where(P < 35e3, 0.05 + 0.05 * P / 100e3, 0.9 + 0.05 * P / 100e3))
    new = Surrogate(P, nodes, (1.0, 1.0), (0,)).area([u], [0.0], [1.0], q, ["approach"] * len(q))[0]
    old = Surrogate(P, nodes, (1.0, 1.0), (0,), "pressure").area([u], [0.0], [1.0], q, ["approach"] * len(q))[0]
    assert np.max(np.abs(new - truth)) < 0.03, np.c_[q, new, truth]
    assert new[q == 29e3] < 0.1 and new[q == 36e3] > 0.9
    # the blend at a fixed pressure: half-jumped between the two nodes' jumps (a plateau no design has)
    assert np.max(np.abs(old - truth)) > 0.3
    assert np.any((old > 0.3) & (old < 0.7) & (q >= 36e3)), np.c_[q, old]


def test_level_interpolation_is_exact_at_its_nodes():
    from tengsim.calibrate.surrogate import Surrogate

    P, nodes = _jumping_nodes()
    s = Surrogate(P, nodes, (1.0, 1.0), (0,))
    for n in nodes:
        got = s.area([n.u], [0.0], [1.0], P, ["approach"] * len(P))[0]
        assert np.max(np.abs(got - n.area["approach"])) < 2e-3


def test_warnings_say_when_the_fitted_noise_or_the_interpolations_error_is_too_large():
    from types import SimpleNamespace

    from tengsim.calibrate.run import warnings

    rel = SimpleNamespace(known_errors=False, noise="relative", n_points=60, free=("sigma", "W"))
    fit = SimpleNamespace(scale=0.02, dev_min=0.0)
    assert warnings(rel, fit, 0.01, 0.02) == ()  # a fit within its noise, an interpolation within it
    w = warnings(rel, SimpleNamespace(scale=0.08, dev_min=0.0), 0.01, 0.02)
    assert len(w) == 1 and "8 % of V_OC is 4 × the expected 2 % of V_OC" in w[0]
    w = warnings(rel, fit, 0.05, None)
    assert len(w) == 1 and "interpolation's own error (5 % of V_OC" in w[0] and "exceeds the fitted noise" in w[0]
    assert "tol" not in w[0]  # designs without a tol said: no advice on it
    coarse = SimpleNamespace(**vars(rel), plans=[SimpleNamespace(rel_tol=0.05)])  # designs coarser than the 2 % noise
    w = warnings(coarse, fit, 0.05, None)
    assert "The designs' tol 0.05 (A/S to about 5 %) exceeds that noise" in w[0] and "tol = 0.01" in w[0]
    fine = SimpleNamespace(**vars(rel), plans=[SimpleNamespace(rel_tol=0.01)])
    assert "tol" not in warnings(fine, fit, 0.05, None)[0]
    assert len(warnings(rel, SimpleNamespace(scale=0.15, dev_min=0.0), 0.01, None)) == 1  # large with none expected
    known = SimpleNamespace(known_errors=True, noise="relative", n_points=60, free=("sigma", "W"))
    assert warnings(known, SimpleNamespace(scale=1.0, dev_min=58 * 1.1), 0.1) == ()
    w = warnings(known, SimpleNamespace(scale=1.0, dev_min=58 * 9.0), 0.1)
    assert len(w) == 1 and "3 × the stated errors" in w[0]


def test_a_snap_between_two_asked_pressures_is_read_off_the_states_passed_not_off_a_ramp_one_step_wide():
    """The paper's group C at W 50 and 58 mJ/m² snaps at 15.7 and 13.5 kPa, both inside a 5 kPa step of the nodes'
    pressures: between them (W 54: 14.5 kPa) the point measured at 15 kPa is on the landed branch.  Read off the
    nodes' states the interpolation puts the snap between the two; read off the asked pressures it is a ramp
    from 10 to 20 kPa, and the point at 15 kPa half-way down it."""
    from tengsim.calibrate.surrogate import Node, Surrogate

    P = np.linspace(0, 100e3, 21)

    def states(p_snap):
        sp = np.r_[np.linspace(0, p_snap, 12), p_snap, np.linspace(p_snap, 100e3, 30)[1:]]
        sa = np.r_[0.02 + 0.1 * sp[:12] / p_snap, 0.9 + 0.05 * sp[12:] / 100e3]
        return sp, sa

    def node(u, p_snap):
        sp, sa = states(p_snap)
        tab = np.interp(P, sp, sa)
        return Node(u, 0.0, True, P, {"approach": tab, "retraction": tab}, states={"approach": (sp, sa),
                                                                                "retraction": (sp, sa)})

    nodes = [node(0.0, 15.7e3), node(1.0, 13.5e3)]
    q = np.array([14e3, 14.4e3, 15e3, 15.5e3])
    got = Surrogate(P, nodes, (1.0, 1.0), (0,)).area([0.5], [0.0], [1.0], q, ["approach"] * 4)[0]
    truth = np.where(q < 14.6e3, 0.02 + 0.1 * q / 14.6e3, 0.9 + 0.05 * q / 100e3)  # the snap half-way: 14.6 kPa
    assert np.max(np.abs(got - truth)) < 0.02, np.c_[q, got, truth]
    before, after = nodes[0].area_at("approach", [15.0e3, 15.8e3])  # the node's own, on either side of its snap
    assert before < 0.13 and after > 0.9
    bare = [Node(n.u, n.v, True, P, n.area) for n in nodes]  # the asked pressures only
    ramp = Surrogate(P, bare, (1.0, 1.0), (0,)).area([0.5], [0.0], [1.0], q, ["approach"] * 4)[0]
    assert abs(ramp[2] - truth[2]) > 0.3, ramp
