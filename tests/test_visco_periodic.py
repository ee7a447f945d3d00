"""The press repeated with the material's memory (tengsim.visco.periodic, docs/viscoelastic.md "Memory from one press
to the next"): a square load (press in 5 % of the period, hold, release, hold) on a paraboloid, the Repulsive wall,
a standard linear solid E∞ = E1 (E0 = 2 E∞, retardation time τ_c = 2τ), load control, on a coarse 15² grid.

* τ ≪ period: the solid recovers between presses; the steady cycle is the first (to 0.5 %);
* τ ≫ period: it does not; the steady cycle's area at the release is higher than the first press's (the solid stays
  indented between presses) and the presses from rest approach it from below;
* the Anderson-accelerated steady state against a long direct run of periods one after the other (slow).

A closed form (Lee–Radok) needs a contact area that never decreases; here it falls to 0 at every release, and
Ting's non-monotonic solution for a repeated load has no closed periodic form, hence the direct run.
"""
from __future__ import annotations

import numpy as np
import pytest

from tengsim.laws import Repulsive
from tengsim.relaxation import sls
from tengsim.shapes import Paraboloid
from tengsim.visco import SegmentSteps, build_drive, periodic_cycles, square_wave
from tengsim.visco.periodic import TOL, _area_on, schedule

SHAPE, TABOR, DX, P_MAX, T = Paraboloid(0.025, 9.0), 10 ** (2 / 3), 0.6, 0.5, 1.0
STEPS = SegmentSteps(4)
HISTORY = square_wave(0.0, P_MAX, T, 1, rise=0.05, kind="pressure")


def _drive(tau, dx=DX):
    return build_drive(SHAPE, TABOR, dx, sls(1.0, 1.0, tau), law=Repulsive(), tol=1e-5)[0]


def _cycle(res, t=None):
    return _area_on(res, schedule(HISTORY, STEPS) if t is None else t)


def test_a_solid_that_recovers_between_presses_repeats_its_first_cycle():
    """τ = 10⁻³ period: the steady cycle is the first to 0.5 % of its largest A/S at every time (measured 1e-8)."""
    pc = periodic_cycles(_drive(1e-3), HISTORY, STEPS)
    assert pc.converged and pc.change <= TOL
    first, steady = _cycle(pc.first), _cycle(pc.steady)
    assert first.max() > 0.05
    assert np.max(np.abs(steady - first)) <= 5e-3 * first.max()


def test_a_solid_that_does_not_recover_stays_indented_between_presses():
    """τ = 20 periods (τ_c = 40): the steady cycle's A/S at the release is higher than the first press's by more
    than 5 % (measured 0.1060 → 0.1148, +8.3 %), the presses 1, 2, 3 from rest rise towards it, and the steady state
    repeats to the stated tolerance (a plain period from its end)."""
    pc = periodic_cycles(_drive(20.0), HISTORY, STEPS)
    assert pc.converged and pc.change <= TOL and len(pc.periods) == 3
    release = [float(_cycle(r, np.array([0.5 * T]))[0]) for r in (*pc.periods, pc.steady)]
    assert release[-1] > 1.05 * release[0]
    assert release[0] < release[1] < release[2] < release[3]
    # far fewer periods than the ~τ_c/T ln(1/tol) ≈ 280 a direct run would need
    assert pc.evaluations < 30


@pytest.mark.slow
def test_the_accelerated_steady_state_is_that_of_a_long_direct_run():
    """τ = period/2 (τ_c = 1 period): 14 periods driven one after the other (the memory decayed by e^-14) give the
    accelerated steady cycle to 2 × the tolerance (measured 1.4e-5 of the largest A/S, 6 periods driven; the first
    press differs by 16 %)."""
    drive = _drive(0.5, dx=0.45)
    pc = periodic_cycles(drive, HISTORY, STEPS)
    res, end = drive.run_from(HISTORY, STEPS)
    for _ in range(13):
        res, end = drive.run_from(HISTORY, STEPS, start=end)
    direct, steady = _cycle(res), _cycle(pc.steady)
    assert np.max(np.abs(direct - steady)) <= 2 * TOL * steady.max()
    assert np.max(np.abs(_cycle(pc.first) - steady)) > 20 * TOL * steady.max()  # the memory matters here
