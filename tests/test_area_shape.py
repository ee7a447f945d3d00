"""The paper's A/S asks the shape object (its cell and patch family, an array its pattern's); the parameters a
result carries give the same numbers, and are read only where no shape object is at hand (a result read back)."""
import types

import numpy as np
import pytest

from pathlib import Path

from tengsim.run.area import area_fraction, full_length, patch

EXAMPLES = sorted((Path(__file__).parent.parent / "examples" / "own_design").glob("*.toml"))


@pytest.mark.parametrize("path", EXAMPLES, ids=[p.stem for p in EXAMPLES])
def test_the_shape_and_its_parameters_give_the_same_a_s(path):
    from tengsim.design import read_design
    from tengsim.design import plan_design

    shape = plan_design(read_design(str(path))).contact_plan.shape
    params = shape.params()
    res = types.SimpleNamespace(params=params)
    lam = np.linspace(0.0, 1.5 * patch(shape, params)[0], 7)
    assert patch(shape, params) == patch(None, params)
    np.testing.assert_array_equal(area_fraction(res, lam, shape=shape), area_fraction(res, lam))
    a, b = full_length(params, shape), full_length(params)
    assert (np.isnan(a) and np.isnan(b)) or a == b


def test_a_s_asks_the_shape_object_not_the_names():
    class Strip:
        def charged_patch(self):
            return 4.0, "line"

    res = types.SimpleNamespace(params={"shape": "pyramid", "cell": 1.0})  # names that would say a square of side 1
    np.testing.assert_allclose(area_fraction(res, [1.0, 2.0], shape=Strip()), [0.25, 0.5])
    np.testing.assert_allclose(area_fraction(res, [0.5]), [0.25])  # no shape object: the parameters


def test_an_array_answers_its_patterns_patch():
    from tengsim.shapes import Pyramid
    from tengsim.shapes.arrays import Array

    shape = Array(pattern=Pyramid(N=0.9, cell=3.8), K=2)
    params = shape.params()
    assert patch(shape, params) == (3.8, "square") == patch(None, params)
    lam = np.linspace(0.0, 4.0, 5)
    res = types.SimpleNamespace(params=params)
    np.testing.assert_array_equal(area_fraction(res, lam, shape=shape), area_fraction(res, lam))
