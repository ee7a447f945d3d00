"""A design's jump-in pressure: the pressed device's first snap into contact within the asked range (the fold of
the load-controlled approach, where its A/S steps), never a jump past p_max where the walk presses the law's wall;
n/a with its reason where there is none."""
import dataclasses
import math

import numpy as np
import pytest

from tengsim.design import plan_design, run_design
from tengsim.design.curves import snap_in, summarize

# periodic (the default): the apex is drawn in at zero load, the land snaps into contact at a small positive load
TINY = {"shape": "pyramid", "pitch": "1um", "base": "0.5um", "height": "0.2um", "E_star": "5MPa", "W": "20mJ/m2",
        "eps": "50nm", "p_max": "20kPa", "p_step": "10kPa", "tol": 0.05, "maps": False}


@pytest.fixture(scope="module")
def tiny():
    return run_design(plan_design(TINY))


def test_jump_in_is_where_the_pressed_device_snaps(tiny):
    res = tiny.finest
    s = tiny.summary
    p = s["jump_in_Pa"]
    assert 0 < p <= 20e3 and "jump_in_Pa" not in s["reasons"]
    a = res.branch("approach")
    P, A = res.scaling.pressure(1.0) * np.asarray(a["F"]), np.asarray(a["charged_fraction"])
    i = int(np.flatnonzero(P == p)[0])              # the state just before the snap, on the path
    assert np.all(P[:i] < p) and P[i + 1] < p       # the highest load so far, and the load then falls
    land = i + 1 + int(np.flatnonzero(P[i + 1:] > p)[0])
    assert A[land] > A[i] + 0.3                     # the land snaps into contact: A/S steps across it
    Aq = tiny.dataset["charged_area_fraction"].sel(branch="approach").values
    assert Aq[0] < A[i] + 1e-9  # below the jump-in: the approach before it
    # the asked pressure above it (10 kPa, below the first path state whose load exceeds the fold's) reads the
    # branch the device lands on, between that state and the one before it, not a blend from the fold
    # (tests/test_snap_landing.py)
    assert P[land] > 10e3 and A[land - 1] - 1e-9 <= Aq[1] <= A[land] + 1e-9


def test_design_nc_keeps_the_states_passed_with_the_snap_at_its_own_pressure(tiny):
    """design.nc's state_* variables: the states a pressed device passes, the asked pressures' A/S read off them,
    and the snap a step at the jump-in pressure (two states at one pressure), not a ramp between asked pressures."""
    from tengsim.run.area import at_pressures

    ds = tiny.dataset
    sp = ds["state_pressure"].sel(branch="approach").values
    sa = ds["state_charged_area_fraction"].sel(branch="approach").values
    ok = np.isfinite(sp)
    sp, sa = sp[ok], sa[ok]
    assert ds["state_pressure"].attrs["units"] == "Pa" and np.all(np.diff(sp) >= 0)
    asked = ds["charged_area_fraction"].sel(branch="approach").values
    P = ds["pressure"].values
    np.testing.assert_allclose(np.clip(at_pressures(sp, sa, P), 0, 1), asked, atol=1e-12)
    at = np.flatnonzero(sp == tiny.summary["jump_in_Pa"])
    assert len(at) == 2 and sa[at[1]] > sa[at[0]] + 0.3  # the fold, and where the device lands at its load


def test_a_jump_the_walk_records_past_p_max_is_not_the_jump_in(tiny):
    """A D-controlled jump recorded in the wall (past p_max, the contact growing) was taken as the design's
    jump-in: a pressure above p_max.  (The design's approach stops one step past p_max, so the walk records two
    rows there.)"""
    res = tiny.finest
    t = dict(res.table)
    P = res.scaling.pressure(1.0) * np.asarray(t["F"])
    k = int(np.flatnonzero((t["branch"] == "approach") & (P > 20e3))[1])
    t["jump"] = np.asarray(t["jump"], bool).copy()
    t["jump"][:] = False
    t["jump"][k] = True
    for name, grow in (("contact_length", 1.0), ("charged_fraction", 0.01)):
        t[name] = np.asarray(t[name], float).copy()
        t[name][k] = t[name][k - 1] + grow
    moved = dataclasses.replace(res, table=t)
    assert [j.kind for j in moved.jumps] == ["jump-in"] and P[k - 1] > 20e3
    s, _, _ = summarize(moved, tiny.plan)
    assert s["jump_in_Pa"] == tiny.summary["jump_in_Pa"] <= 20e3


def test_snap_in_takes_the_first_fold_inside_the_range_only():
    P = [-5.0, -9, -2, 1, 3, 2, 1, 4, 6, 5.9999, 7, 30, 20, 40]
    A = [0.0, 0, 0.01, 0.02, 0.03, 0.04, 0.05, 0.5, 0.55, 0.551, 0.56, 0.6, 0.7, 0.9]
    assert snap_in(P, A, (0, 10)) == 3               # the fold at 3, landing at 4 with the area grown
    assert snap_in(P, A, (3.5, 10)) != snap_in(P, A, (3.5, 10))  # NaN: the dip at 6 is noise (< 1e-3 p_max)
    assert math.isnan(snap_in(P, A, (5, 25)))        # the fold at 30 is past p_max: never taken
    assert snap_in(P, A, (5, 35)) == 30
    no_growth = list(A)
    no_growth[7] = 0.03
    assert math.isnan(snap_in(P, no_growth, (0, 4)))  # the area does not grow: not a snap into contact
    assert math.isnan(snap_in([-1, -3, 0.5, 1, 2], [0, 0.1, 0.2, 0.3, 0.4], (0, 10)))  # drawn in at rest only


def test_no_snap_in_the_range_is_na_with_its_reason(tiny):
    plan = dataclasses.replace(tiny.plan, pressures=(0.0, 300.0, 600.0))  # the range ends below the land's snap
    s, _, _ = summarize(tiny.finest, plan)
    assert math.isnan(s["jump_in_Pa"])
    why = s["reasons"]["jump_in_Pa"]
    assert "no jump into contact" in why and "600 Pa" in why and "drawn in at zero load" in why


def test_a_second_pass_walks_every_grid_to_the_extended_path():
    """The false "reached only … kPa, give a lower p_max": a finer grid walks only to where the grid before it
    reached p_max (plus a margin) and may fall short; the run's second pass must not cut the finer grids' paths
    again at the same D, or it fails the same way and blames p_max."""
    from tengsim.design import plan_design, run_design
    from tengsim.design.walk import grid_path
    from tengsim.run.reach import reach as _reach

    plan = plan_design({"shape": "pyramid", "pitch": "1um", "base": "0.5um", "height": "0.2um", "E_star": "5MPa",
                        "W": "20mJ/m2", "eps": "50nm", "p_max": "20kPa", "p_step": "10kPa", "tol": 0.05,
                        "maps": False})
    prev = run_design(plan).finest
    ok, D_hit, _, _ = _reach(prev, plan.pressures[-1])
    assert ok
    d_max = D_hit + 50.0
    cut = grid_path(plan, d_max)(prev)
    full = grid_path(plan, d_max, cut=False)(prev)
    assert cut.d_max < d_max - 10 and full.d_max == pytest.approx(d_max)
