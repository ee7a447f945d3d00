"""A pressed device that snaps: under load it passes the fold, then lands on the state the D path reaches at the
fold's load.  The charged area just above the fold is the landed state's, not a blend of the fold and the next
state the load exceeds (a design's A/S there was read off that blend: group C at 20-30 kPa, 0.34-0.75 where
the device is at 0.92)."""
from __future__ import annotations

import numpy as np
import pytest

from tengsim.run.area import at_pressures, load_control, retraction_control


class _Path:
    """A D path's table, as ContactResult.branch gives it."""

    def __init__(self, approach, retraction=None):
        self._b = {"approach": approach, "retraction": retraction or {k: np.array([]) for k in approach}}

    def branch(self, name):
        return self._b[name]


# a fold at F = 14.5 (A 0.12), the load falling back to -43 while the contact spreads, regained between
# F = -1.9 (A 0.885), 12.5 (A 0.913), then 34.6 (A 0.942): the device lands at F = 14.5 on the rise 12.5-34.6
F = np.array([-1.0, 0.1, 6.0, 14.4, 14.5, 5.3, -43.0, -1.9, 12.5, 34.6, 70.5])
A = np.array([0.0, 0.02, 0.056, 0.113, 0.120, 0.140, 0.568, 0.885, 0.913, 0.942, 0.971])


def test_the_device_lands_on_the_rising_branch_at_the_folds_load():
    Fk, Ak = load_control(_Path({"F": F, "A": A}), "A")
    # zero load first, then the states above every earlier load, and the landing state at the fold's load
    landing = 0.913 + (14.5 - 12.5) / (34.6 - 12.5) * (0.942 - 0.913)  # on the path's segment from 12.5 to 34.6
    assert list(Fk) == pytest.approx([0.0, 0.1, 6.0, 14.4, 14.5, 14.5, 34.6, 70.5])
    assert Ak[4] == pytest.approx(0.120) and Ak[5] == pytest.approx(landing)
    # just above the fold the device is on the landed branch; the old blend from the fold read 0.12-0.94 instead
    ps = np.array([20.0, 30.0])
    got = at_pressures(Fk, Ak, ps)
    want = 0.913 + (ps - 12.5) / (34.6 - 12.5) * (0.942 - 0.913)
    np.testing.assert_allclose(got, want, rtol=1e-12)
    blend = 0.120 + (ps - 14.5) / (34.6 - 14.5) * (0.942 - 0.120)
    assert np.all(got - blend > 0.15)  # the bug this replaces (0.58 and 0.18 low here)
    # below the fold nothing changed: linear between the states the load passes
    assert at_pressures(Fk, Ak, [10.0])[0] == pytest.approx(0.056 + 4 / 8.4 * (0.113 - 0.056))


def test_without_a_snap_the_states_are_the_loads_maxima_only():
    Fmono = np.array([-0.5, 0.5, 1.0, 2.0, 4.0])
    Fk, Ak = load_control(_Path({"F": Fmono, "A": Fmono / 10}), "A")
    assert list(Fk) == pytest.approx([0.0, 0.5, 1.0, 2.0, 4.0]) and list(Ak) == pytest.approx([0.0, 0.05, 0.1,
                                                                                                  0.2, 0.4])


def test_retraction_lands_after_a_pull_off_fold_too():
    # unloading: the load falls to -3 (a fold), rises back to -1 as the contact peels, then falls past -3 again
    Fr = np.array([5.0, 1.0, -2.0, -3.0, -1.0, -2.5, -4.0])
    Ar = np.array([0.9, 0.7, 0.5, 0.45, 0.2, 0.15, 0.1])
    Fk, (Ak,) = retraction_control(_Path({"F": F, "A": A}, {"F": Fr, "A": Ar}), ("A",))
    landing = 0.15 + (-3.0 + 2.5) / (-4.0 + 2.5) * (0.1 - 0.15)
    assert list(Fk) == pytest.approx([-4.0, -3.0, -3.0, -2.0, 1.0, 5.0])
    assert Ak[1] == pytest.approx(landing) and Ak[2] == pytest.approx(0.45)


def test_the_sensor_curve_keeps_the_landing_state_at_the_folds_pressure():
    """The sensor reads V_OC(P) through the states above: at the fold's pressure, given twice, the landing state
    is kept, so the jump lies just below the fold and the curve above it is the landed branch."""
    from tengsim.device.sensor import _curve

    P, V = _curve([0.0, 10.0, 14.5, 14.5, 34.6, 30.0], [0.0, 1.0, 2.0, 9.0, 9.5, 9.4])
    assert list(P) == [0.0, 10.0, 14.5, 34.6] and list(V) == [0.0, 1.0, 9.0, 9.5]


def test_a_landing_segment_that_is_itself_a_jump_lands_on_the_state_after_it():
    """Where the path crosses the fold's load across a jump of the D path (flagged, or y rising ten times faster
    in F than on the next segment), the branch the device lands on is not solved below the jump's far state:
    that state is taken, not a blend across the jump."""
    Fj = np.array([0.2, 0.77, -3.5, 10.4, 78.7])
    Aj = np.array([0.09, 0.094, 0.115, 0.889, 0.924])
    Fk, Ak = load_control(_Path({"F": Fj, "A": Aj}), "A")
    assert list(Fk) == pytest.approx([0.2, 0.77, 0.77, 10.4, 78.7])
    assert Ak[2] == pytest.approx(0.889)  # interpolated it would be 0.352
    flagged = {"F": Fj, "A": Aj, "jump": np.array([False, False, False, True, False])}
    Fj2 = Fj.copy()
    Fj2[4] = 11.0  # the next segment as steep: not a jump by the slopes, but the walk flagged it
    flagged["F"] = Fj2
    assert load_control(_Path(flagged), "A")[1][2] == pytest.approx(0.889)
    flagged["jump"] = np.zeros(5, bool)
    assert load_control(_Path(flagged), "A")[1][2] < 0.5  # neither: linear on the segment
