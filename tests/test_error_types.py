"""Errors told by type and their parts, never by their text (issue 49 item 8)."""
import pytest

from tengsim.continuation.load import joined_misses, misses_in
from tengsim.errors import ConfigValueError, NumberError
from tengsim.units import read_number


@pytest.mark.parametrize("text, reason", [
    ("0_5", ": no underscores in numbers"),
    ("1e200", " is out of range"),
    ("1" * 80, " is not a number (a number or quantity is at most"),
])
def test_number_error_carries_its_parts(text, reason):
    with pytest.raises(NumberError) as info:
        read_number(text, "gap")
    exc = info.value
    assert isinstance(exc, ConfigValueError)
    assert exc.name == "gap" and exc.text == text and exc.reason.startswith(reason)
    assert str(exc) == exc.named("gap") and str(exc).startswith("gap = " + repr(text)[:10])
    assert exc.named(None).startswith(repr(text)[:20]) and "gap" not in exc.named(None)
    assert exc.named("--opt 0_5%", value=False) == "--opt 0_5%" + exc.reason


def test_number_error_not_finite():
    with pytest.raises(NumberError) as info:
        read_number("inf", "width")
    assert str(info.value) == "width must be finite, got 'inf'"
    assert info.value.named("--nodes", value=False) == "--nodes must be finite, got 'inf'"


def test_plain_text_is_a_value_error_not_a_number_error():
    with pytest.raises(ValueError) as info:
        read_number("5nm", "gap")
    assert not isinstance(info.value, NumberError)


def test_missed_loads_round_trip():
    misses = ["approach: load 1 not met: |F - target| = 0.1 > f_tol = 0.01 (D in [1, 2])",
              "retraction: load 0.5 not met: |F - target| = 0.2 > f_tol = 0.01 (D in [3, 4], bisection)"]
    assert misses_in({"load_not_met": joined_misses(misses)}) == misses
    assert misses_in({}) == [] and misses_in({"load_not_met": ""}) == []
