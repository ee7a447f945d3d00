"""The material with memory: the Prony series, its TOML table, the DMA fit, the SLS closed forms."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import quad

from tengsim.errors import TengsimError
from tengsim.relaxation import Prony, fit_dma, read_dma, read_relaxation, relaxation_from_table, sls, sls_creep
from tengsim.relaxation import sylgard184
from tengsim.visco import MaxwellMemory, StepOperator


def test_table_with_units(tmp_path):
    p = tmp_path / "m.toml"
    p.write_text('[relaxation]\nE_inf = "1MPa"\nbranches = [{E = "0.5MPa", tau = "0.1s"}, {E = "200kPa", tau = "20ms"}]\n')
    m = read_relaxation(p)
    assert m.E_inf == 1e6 and m.E == (5e5, 2e5) and m.tau == pytest.approx((0.1, 0.02))
    assert m.E0 == pytest.approx(1.7e6)
    assert m.relaxation(0.0) == pytest.approx(1.7e6)
    assert m.relaxation(1e3) == pytest.approx(1e6)


@pytest.mark.parametrize("table, words", [
    ({"E_inf": "1MPa", "branches": [{"E": "0.5MPa", "tau": "0.1m"}]}, "tau = '0.1m' is a length"),
    ({"E_inf": "-1MPa"}, "E_inf must be a modulus > 0"),
    ({"E_inf": "1MPa", "branches": [{"E": "0.5MPa"}]}, "branch 1 must be"),
    ({"E_inf": "1MPa", "bogus": 1}, "no key 'bogus'"),
    ({"default": "ecoflex"}, "the one default is 'sylgard184'"),
])
def test_bad_tables_are_refused_naming_the_value(table, words):
    with pytest.raises(TengsimError, match=words.replace("(", r"\(")):
        relaxation_from_table(table)


def test_the_example_and_the_default_are_the_same_series():
    m = read_relaxation(Path(__file__).resolve().parents[1] / "examples" / "relaxation" / "pdms.toml")
    d = sylgard184()
    assert (m.E_inf, m.E, m.tau) == (d.E_inf, d.E, pytest.approx(d.tau))
    f = np.logspace(-2, 2, 9)
    tan = d.loss(f) / d.storage(f)
    assert np.all((0.01 < tan) & (tan < 0.06))  # the loss tangent its doc states


def test_sls_creep_is_the_inverse_of_the_relaxation():
    """∫_0^t E(t − s) dJ(s) = 1 (with the jump J(0) = 1/E0 at s = 0): creep and relaxation are inverse."""
    E_inf, E1, tau = 1.0, 3.0, 0.5
    E = lambda u: E_inf + E1 * np.exp(-u / tau)
    J = lambda s: sls_creep(s, E_inf, E1, tau)
    for t in (0.1, 1.0, 5.0):
        dJ = lambda s: (J(s + 1e-7) - J(s - 1e-7)) / 2e-7
        val = E(t) * J(0.0) + quad(lambda s: E(t - s) * dJ(s), 1e-7, t)[0]
        assert val == pytest.approx(1.0, rel=1e-6)


def test_dma_fit_recovers_a_series_on_its_grid(tmp_path):
    true = Prony(2e6, (1e6, 0.5e6), (1e-2, 1.0))
    f = np.logspace(-2, 3, 21)
    fit = fit_dma(f, true.storage(f), true.loss(f), per_decade=2)
    assert fit.rms_storage < 1e-3 and fit.rms_loss < 1e-2
    t = np.logspace(-4, 2, 13)
    assert np.allclose(fit.prony.relaxation(t), true.relaxation(t), rtol=0.01)
    p = tmp_path / "dma.csv"
    p.write_text("frequency_Hz,storage_MPa,loss_MPa\n" + "\n".join(
        f"{a},{b / 1e6},{c / 1e6}" for a, b, c in zip(f, true.storage(f), true.loss(f))))
    again = read_dma(p, per_decade=2)
    assert again.prony.E_inf == pytest.approx(fit.prony.E_inf, rel=1e-9)
    assert "rms" in again.summary()


def test_dma_fit_states_its_error_on_noisy_data():
    rng = np.random.default_rng(0)
    true = sylgard184()
    f = np.logspace(-2, 2, 17)
    noise = 1 + 0.02 * rng.standard_normal((2, f.size))
    fit = fit_dma(f, true.storage(f) * noise[0], true.loss(f) * noise[1])
    assert 0.005 < fit.rms_storage < 0.04   # the noise shows in the stated error
    assert fit.max_storage >= fit.rms_storage


def test_step_operator_limits_and_exact_update():
    m = sls(1.0, 2.0, 0.5)
    assert StepOperator(m, 1.0, 0.0).E_eff == pytest.approx(3.0)
    assert StepOperator(m, 1.0, 1e4).E_eff == pytest.approx(1.0, rel=1e-4)
    # one branch under a held unit strain: q relaxes exactly as E1 e^{−t/τ}, whatever the step
    mem = MaxwellMemory.rest((1,), 1)
    mem = StepOperator(m, 1.0, 0.0).update(mem, np.ones(1))
    for dt in (0.1, 0.3, 0.6):
        mem = StepOperator(m, 1.0, dt).update(mem, np.ones(1))
    assert mem.q[0][0] == pytest.approx(2.0 * np.exp(-1.0 / 0.5), rel=1e-12)


def test_negative_step_is_refused():
    with pytest.raises(TengsimError, match="time step must be >= 0"):
        sls(1, 1, 1).step_factors(-1.0)


def test_a_jump_inside_a_history_belongs_to_its_own_instant():
    """D: 0 → 1 ε in 1 s, a jump to 2 ε at t = 1 s, held: the step ending at 1 s is at D = 1, the jump's at D = 2."""
    from tengsim.laws import Repulsive
    from tengsim.shapes import Paraboloid
    from tengsim.visco import FixedTimeSteps, History, simulate_history

    r = simulate_history(Paraboloid(1.0, 4.0), 1.0, 0.5, sls(1.0, 1.0, 1.0), History((0, 1, 1, 2), (0, 1, 2, 2)),
                         FixedTimeSteps(0.5), law=Repulsive(), tol=1e-6)
    assert list(np.round(r.t, 9)) == [0, 0.5, 1, 1, 1.5, 2]
    assert list(r["D"]) == [0, 0.5, 1, 2, 2, 2]
