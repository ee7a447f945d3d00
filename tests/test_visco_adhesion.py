"""Adhesive viscoelastic contact: the pull-off against the rate (docs/validation.md "Viscoelastic contact").

The LJ93 sphere (R = 1, cell 8, μ = 0.5 at E∞, dx = 0.25) on a standard linear solid E0 = 2 E∞, τ = 1 s,
driven in D: −1 → 2 → −1.5 ε.  The pull-off is the most tensile force of the retraction.
"""
from __future__ import annotations

import numpy as np
import pytest

from tengsim.run.plan import ContactPlan
from tengsim.laws import LJ93
from tengsim.relaxation import Prony, sls
from tengsim.shapes import Paraboloid
from tengsim.visco import History, SegmentSteps, simulate_history

SHAPE = Paraboloid(1.0, 8.0)


def pull_off(material, t_load, t_unload):
    h = History((0.0, t_load, t_load + t_unload), (-1.0, 2.0, -1.5))
    r = simulate_history(SHAPE, 0.5, 0.25, material, h, SegmentSteps(28), law=LJ93(), tol=1e-7, E_ref=1.0)
    assert r.ok
    return -float(r["F"][r.t > t_load].min())


@pytest.mark.slow
def test_pull_off_tends_to_the_elastic_values_at_both_rate_limits():
    """A whole cycle 10⁴× faster than τ gives the elastic pull-off at E0, 10⁴× slower the one at E∞ (0.5 %)."""
    mat = sls(1.0, 1.0, 1.0)
    e0, einf = pull_off(Prony(2.0), 1.0, 1.0), pull_off(Prony(1.0), 1.0, 1.0)
    assert abs(e0 / einf - 1) > 0.02               # the two limits differ (Maugis: μ at E0 is 2^{-2/3} of E∞'s)
    assert pull_off(mat, 5e-5, 5e-5) == pytest.approx(e0, rel=0.005)
    assert pull_off(mat, 5e3, 5e3) == pytest.approx(einf, rel=0.005)


@pytest.mark.slow
def test_pull_off_rises_with_the_unloading_rate():
    """Loaded slowly (relaxed, 10⁴ τ), then unloaded in 10⁴ … 10⁻⁴ τ: the pull-off rises with the unloading rate,
    from the elastic value at E∞ (slow) to one above the elastic value at E0 (the contact formed at E∞)."""
    mat = sls(1.0, 1.0, 1.0)
    einf, e0 = pull_off(Prony(1.0), 1.0, 1.0), pull_off(Prony(2.0), 1.0, 1.0)
    po = [pull_off(mat, 1e4, tu) for tu in (1e4, 10.0, 1.0, 1e-4)]
    assert po[0] == pytest.approx(einf, rel=0.005)
    assert all(b > a for a, b in zip(po, po[1:]))
    assert po[-1] > e0


@pytest.mark.slow
def test_jumps_are_located_in_time_where_the_static_path_has_them():
    """μ = 2 (the sphere snaps in and out in several jumps): an elastic material driven in D: −1.5 → 1 → −1.5 ε
    in 1 s each way, steps of 0.1 s bisected at a jump to 0.1/64 s (0.0039 ε of D), has the static path's
    jumps (d_step 0.25 refined 6 levels: the same resolution in D), each within 4 resolutions."""
    from tengsim import PathSpec, simulate
    from tengsim.visco import FixedTimeSteps

    st = simulate(ContactPlan(SHAPE, 2.0, 0.25, PathSpec(-1.5, 1.0, 0.25)))
    tab = st.table
    static = [float(d) for d, j in zip(np.asarray(tab["D"]), np.asarray(tab["jump"])) if j]
    r = simulate_history(SHAPE, 2.0, 0.25, Prony(1.0), History((0, 1, 2), (-1.5, 1.0, -1.5)), FixedTimeSteps(0.1),
                         law=LJ93(), tol=1e-6, dt_min=0.1 / 64)
    found = r.jumps()
    assert len(found) == len(static) >= 4
    res = 2.5 * 0.1 / 64
    for (t, D, _), Ds in zip(found, static):
        assert abs(D - Ds) <= 4 * res + 1e-12, (t, D, Ds)
