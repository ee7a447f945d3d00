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


def test_reworded_keeps_the_type_and_its_parts():
    import pickle

    from tengsim.errors import BudgetExceeded
    with pytest.raises(NumberError) as info:
        read_number("1e+400", "pitch")
    exc = info.value
    framed = exc.reworded(prefix="[design] ", suffix=" (with the material of fit.nc)")
    assert type(framed) is NumberError and framed.name == "pitch" and framed.reason == exc.reason
    assert str(framed) == f"[design] {exc} (with the material of fit.nc)"
    back = pickle.loads(pickle.dumps(framed))  # a worker's error reaches the parent whole
    assert type(back) is NumberError and str(back) == str(framed) and back.text == "1e+400"
    budget = pickle.loads(pickle.dumps(BudgetExceeded("over", budget_s=3.0).reworded(prefix="d1: ")))
    assert budget.budget_s == 3.0 and str(budget) == "d1: over"


def test_a_design_number_out_of_range_is_one_line(tmp_path, capsys):
    from tengsim.cli.main import main
    rc = main(["design", "pyramid", "--pitch", "1e+101um", "--base", "0.5um", "--height", "0.2um",
               "--E-star", "1MPa", "--W", "0.05J/m^2", "--eps", "50nm", "--out", str(tmp_path / "o"), "--quiet"])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and err[-1].startswith("tengsim: error:") and "internal error" not in err[-1]
    assert not (tmp_path / "o").exists()
