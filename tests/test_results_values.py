"""Results are values (issue 28 item 5): a ContactResult is frozen, complete when made, and every change
is a new result that leaves the old one as it was."""
import dataclasses

import numpy as np
import pytest

from tengsim import status
from tengsim.cases.paper.units import paper_scaling
from tengsim.grid import Grid
from tengsim.laws import LJ93
from tengsim.results import CURVE_COLUMNS, ContactResult
from tengsim.status import Status


def _rows(n=4):
    return [dict(branch="approach" if i < n // 2 else "retraction", D=float(i), F=0.1 * i, contact_length=0.5,
                 area_repulsive=0.0, converged=True, residual=0.0, iterations=1, n_conv=1, on_grid=True,
                 jump=False, min_gap=0.0, max_pressure=0.0, min_pressure=0.0, energy=0.0, seconds=0.0,
                 in_law_range=i != 1, process_zone=float("nan")) for i in range(n)]


def test_a_contact_result_is_frozen_and_takes_its_parameters_when_made():
    res = ContactResult.from_rows(_rows(), [], Grid(5, 5, 0.1, 0.1), params={"tol": 1e-6}, units={"F": "x"})
    assert res.params == {"tol": 1e-6} and res.units == {"F": "x"}
    for name, value in (("params", {}), ("table", {}), ("scaling", None), ("units", {})):
        with pytest.raises(dataclasses.FrozenInstanceError):
            setattr(res, name, value)
    assert list(res.columns[: len(CURVE_COLUMNS)]) == CURVE_COLUMNS


def test_with_physical_and_attach_give_new_results_and_leave_the_old_one_alone():
    res = ContactResult.from_rows(_rows(), [], Grid(5, 5, 0.1, 0.1), params={"tol": 1e-6, "g_safe": 0.6})
    table, params = dict(res.table), dict(res.params)
    sc = paper_scaling("A")
    phys = res.with_physical(sc)
    assert phys is not res and phys.scaling is sc and res.scaling is None
    np.testing.assert_allclose(phys.table["F_N"], sc.force(res.table["F"]))
    assert "F_N" not in res.table and res.units == {} and phys.units
    done = status.attach(phys, LJ93(), 1.0)
    assert done.params["status"] == Status.OUT_OF_LAW_RANGE == "out_of_law_range"  # row 1 is out of range
    assert "status" not in phys.params and "warning" not in phys.params
    assert res.table.keys() == table.keys() and res.params == params  # untouched throughout


def test_status_is_a_str_enum_that_aggregates_to_the_worst():
    assert status.overall([]) is Status.OK
    assert status.overall(["ok", "under_resolved", "not_converged"]) is Status.NOT_CONVERGED
    assert [str(s) for s in status.SEVERITY] == ["ok", "under_resolved", "out_of_law_range", "not_converged"]
    assert {"ok": 1}[Status.OK] == 1 and f"{Status.UNDER_RESOLVED}" == "under_resolved"
    assert status.row_status(True, True, float("nan"), 0.1) is Status.OK
    assert status.row_status(True, True, 0.05, 0.1) is Status.UNDER_RESOLVED  # ℓ < 1.2 dx
