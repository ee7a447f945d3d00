"""Units and the paper's scaling (Eq. 7), path bookkeeping, contact-length definition."""
import math

import numpy as np
import pytest

from tengsim.run.plan import ContactPlan
from tengsim.analysis import tensile_peak_offset
from tengsim.errors import TengsimError
from tengsim.continuation import PathSpec
from tengsim.cases.paper.units import PaperScaling, paper_scaling
from tengsim.units import parse_quantity


@pytest.mark.parametrize("text, kind, value", [
    ("0.59MPa", "pressure", 0.59e6), ("54mJ/m2", "energy/area", 0.054), ("2um", "length", 2e-6),
    ("2µm", "length", 2e-6), ("5.84uC/m2", "charge/area", 5.84e-6), ("1MOhm", "resistance", 1e6),
    ("13.45g", "mass", 0.01345), ("38.71cm", "length", 0.3871), (3.5, None, 3.5), ("1e-3", None, 1e-3),
])
def test_parse_quantity(text, kind, value):
    assert parse_quantity(text, kind) == pytest.approx(value)


@pytest.mark.parametrize("text", ["3 parsecs", "fast", "1.2.3um", "inf"])
def test_parse_quantity_rejects(text):
    with pytest.raises(TengsimError):
        parse_quantity(text, "length")


def test_wrong_dimension_is_named():
    with pytest.raises(TengsimError, match="pressure"):
        parse_quantity("2um", "pressure")


def test_paper_groups_match_notes():
    """NOTES.md: with μ = 0.5, ε ≈ 0.37 µm and N, L̄ = (0.946, 3.78), (2.37, 9.46), (4.73, 18.9)."""
    expect = {"A": (0.946, 3.78), "B": (2.37, 9.46), "C": (4.73, 18.9)}
    for g, (N, cell) in expect.items():
        sc = paper_scaling(g)
        assert sc.eps == pytest.approx(0.37e-6, rel=0.01)
        assert sc.mu == pytest.approx(0.5)
        assert sc.N == pytest.approx(N, rel=2e-3)
        assert sc.cell == pytest.approx(cell, rel=2e-3)
        # λc = Λc ε m/n, f = 3π m² W ε F / n²
        assert sc.length(2 * sc.N) == pytest.approx(sc.m)
        assert sc.force(1.0) == pytest.approx(3 * math.pi * sc.m**2 * sc.W * sc.eps / sc.n**2)


def test_scaling_rejects_base_wider_than_pitch():
    with pytest.raises(TengsimError, match="wider"):
        PaperScaling(0.59e6, 0.054, 3e-6, 1e-6, 2e-6, 1e-7)


def test_path_targets_are_on_the_grid():
    spec = PathSpec(-1.0, 4.0, 0.05)
    t = spec.targets()
    assert len(t) == 101 and t[0] == -1.0 and t[-1] == pytest.approx(4.0)


def test_tensile_peak_innermost():
    """Compressive core, tensile peak at index 3, a deeper spurious minimum at the far edge."""
    f = np.array([5.0, 3.0, 0.5, -1.0, -0.2, -0.1, -0.3, -2.0, -0.5])
    assert tensile_peak_offset(f) == pytest.approx(3 + 0.5 * (0.5 - (-0.2)) / (0.5 - 2 * -1.0 + -0.2))
    # apex is itself the tensile minimum: no contact
    assert tensile_peak_offset(np.array([-1.0, -0.5, -0.2, -0.1])) == 0.0


def test_periodic_overcompression_is_flagged():
    """Periodic cell pressed far beyond flattening: gaps leave the law's range and are flagged."""
    import tengsim as ts

    res = ts.simulate(ContactPlan(ts.Pyramid(0.946, 3.78), 0.5, 0.3, ts.PathSpec(-1, 4, 0.5, retract=False), boundary="periodic"))
    flags = res.table["in_law_range"]
    D = res.table["D"]
    assert flags[D <= 1.0].all()          # before the cell flattens, everything is physical
    assert not flags[-1]                  # at D = 4 (> mean pyramid height 1.73) it is not
    assert "safe limit" in res.params["warning"]
