"""A design's charged area: the 2-D contact area by default (the paper's Λc as ``area = "paper"``), no pull-off
where the law has no tension, full contact interpolated inside the asked range, and the area a device reads from
the contact result equal to the design's."""
import math

import numpy as np
import pytest

from tengsim.design import plan_design, run_design

CUBE = {"shape": "cube", "pitch": "1um", "half_width": "0.2um", "height": "0.3um", "E_star": "5MPa",
        "W": "20mJ/m2", "eps": "50nm", "p_max": "40kPa", "p_step": "5kPa", "law": "repulsive", "boundary": "free",
        "tol": 0.05}


@pytest.fixture(scope="module")
def cube():
    return run_design(plan_design(CUBE))


def test_repulsive_cube_charges_its_top_and_has_no_pull_off(cube):
    s = cube.summary
    assert math.isnan(s["pull_off_N"]) and math.isnan(s["pull_off_Pa"])
    assert any("no pull-off" in n for n in cube.notes)
    A = cube.dataset["charged_area_fraction"].sel(branch="approach").values
    top = (0.4 / 1.0) ** 2
    assert np.nanmax(A) <= top * 1.02                      # never more than the top (the old Λc²: the cell)
    assert "2-D contact area" in s["charged_area_definition"]


def test_full_contact_interpolated_inside_the_asked_range(cube):
    from tengsim.design.curves import FULL_CONTACT_AREA_FRACTION, _full_fraction, _params, _shape, crossing, states
    st = states(cube.finest, cube.plan)["approach"]
    full = _full_fraction(cube.finest, _params(cube.finest, cube.plan), _shape(cube.plan))
    p = cube.summary["full_contact_Pa"]
    if math.isfinite(p):
        assert p <= cube.plan.pressures[-1]
        assert np.interp(p, st["P"], st["area"]) == pytest.approx(FULL_CONTACT_AREA_FRACTION * full, rel=1e-6)
    assert crossing([0.0, 10.0, 20.0], [0.0, 0.5, 1.0], 0.95) == pytest.approx(19.0)
    assert crossing([0.0, 10.0], [0.0, 0.5], 0.95) != crossing([0.0, 10.0], [0.0, 0.5], 0.95)  # never: NaN


def test_area_from_the_contact_result_equals_the_designs(cube, tmp_path):
    from tengsim.device.areas import area_table_from_contact
    from tengsim.results.write import save
    path = tmp_path / "contact.nc"
    save(cube.finest, path)
    tab = area_table_from_contact(path)
    ps = np.asarray(cube.plan.pressures, float)
    A = cube.dataset["charged_area_fraction"].sel(branch="approach").values
    ok = np.isfinite(A) & (ps >= tab.pressure_Pa[0]) & (ps <= tab.pressure_Pa[-1])
    assert np.count_nonzero(ok) >= 3
    assert np.allclose(tab(ps[ok]), A[ok], rtol=1e-9, atol=1e-12)


def test_paper_definition_stays_available(cube):
    from tengsim.design.curves import states
    import dataclasses
    paper = dataclasses.replace(cube.plan, area="paper")
    a = states(cube.finest, paper)["approach"]["area"]
    c = states(cube.finest, cube.plan)["approach"]["area"]
    assert not np.allclose(a, c)                              # Λc² of a flat top without a tensile peak: not its top
    with pytest.raises(Exception, match="area must be one of"):
        plan_design({**CUBE, "area": "greenwood"})


def test_a_result_written_without_the_column_reads_with_the_papers_area(cube, tmp_path):
    """A contact file of an older tengsim (no charged_fraction column) still reads; its A/S is the paper's, said."""
    from tengsim.results.read import load_result
    from tengsim.results.write import save
    from tengsim.run.area import loaded_area
    path = tmp_path / "new.csv"
    save(cube.finest, path)
    lines = path.read_text().splitlines()
    head = next(i for i, l in enumerate(lines) if not l.startswith("#"))
    j = lines[head].split(",").index("charged_fraction")
    old = lines[:head] + [",".join(c for k, c in enumerate(l.split(",")) if k != j) for l in lines[head:]]
    (tmp_path / "old.csv").write_text("\n".join(old) + "\n")
    _, res = load_result(tmp_path / "old.csv")
    assert "charged_fraction" not in res.table
    F, L, A, notes = loaded_area(res)
    assert len(A) == len(F) > 2 and any("paper's definition" in n for n in notes)
