"""One definition of each number (issue 49 item 6): ε0 in tengsim.constants, Eq. 12's and Eq. 17's V_OC per charge
in tengsim.device.formulas, "full contact" in tengsim.run.area, each used by every command; the numbers unchanged."""
import re
from pathlib import Path

import numpy as np
import pytest

SRC = Path(__file__).resolve().parent.parent / "src" / "tengsim"


def _defined(pattern):
    return sorted(str(p.relative_to(SRC)) for p in SRC.rglob("*.py") if re.search(pattern, p.read_text(), re.M))


def test_eps0_defined_once_in_constants():
    import tengsim.constants as c
    import tengsim.device as d
    import tengsim.device.params as dp

    assert _defined(r"^EPS0\s*=") == ["constants.py"]
    assert d.EPS0 is c.EPS0 and dp.EPS0 is c.EPS0 and c.EPS0 == 8.8541878128e-12


def test_eq12_and_eq17_per_charge_defined_once_and_unchanged():
    from tengsim.constants import EPS0
    from tengsim.device.formulas import eq12_volts_per_charge, eq17_volts_per_charge, voc_apart, voc_polymer

    assert not _defined(r"T\s*/\s*\(\s*\w*\.?eps_r\s*\*\s*EPS0\)|gap\s*/\s*EPS0")  # no re-derivation left
    A = np.linspace(0.0, 1.0, 7)
    old12 = 5.84e-6 * A * 400e-6 / (2.4 * EPS0)
    np.testing.assert_allclose(voc_polymer(A, 5.84e-6, 2.4, 400e-6), old12, rtol=1e-12, atol=0)
    np.testing.assert_allclose(voc_apart(5.84e-6, A, 1e-4, 1.0), 5.84e-6 * A * 1e-4 / EPS0, rtol=1e-12, atol=0)
    assert eq12_volts_per_charge(2.4, 400e-6) == 400e-6 / (2.4 * EPS0)
    assert float(eq17_volts_per_charge(1e-4)) == 1e-4 / EPS0


def test_calibration_factor_is_the_device_formula():
    from types import SimpleNamespace

    from tengsim.calibrate.problem import Problem
    from tengsim.device.formulas import eq12_volts_per_charge, eq17_volts_per_charge

    plan = SimpleNamespace(T=300e-6, eps_r=3.1, gap=2e-4)
    for voc, want in (("eq12", eq12_volts_per_charge(3.1, 300e-6)), ("eq17", float(eq17_volts_per_charge(2e-4)))):
        prob = Problem((plan,), ({},), (), ("sigma",), {}, {}, voc=voc)
        assert prob.factor(0) == want


def test_full_contact_one_definition_each_named_for_what_it_measures():
    from tengsim.design import curves
    from tengsim.run.area import ADHESIVE_FULL_CONTACT_LENGTH_FRACTION, FULL_CONTACT_AREA_FRACTION
    from tengsim.study.observe import OBSERVABLE_DEFAULTS, parse_observables

    assert curves.FULL_CONTACT_AREA_FRACTION is FULL_CONTACT_AREA_FRACTION == 0.95
    assert OBSERVABLE_DEFAULTS["full_contact_fraction"] == ADHESIVE_FULL_CONTACT_LENGTH_FRACTION == 0.9
    assert parse_observables({})["full_contact_fraction"] == pytest.approx(0.9)
    assert not _defined(r"^FULL_CONTACT_FRACTION\s*=")
