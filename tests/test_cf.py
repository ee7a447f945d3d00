"""NetCDF by the CF-1.10 conventions: the IOOS compliance checker's CF check passes on a contact result
(maps included), a study.nc and a device run, offline; units parse with pint (cf_xarray's UDUNITS
registry, pint-xarray); D is an auxiliary coordinate; parameters are stored once; files written before
the CF layout still load.

Under the CI floors (xarray 2023.1) cf_xarray and pint-xarray do not import: the tests that need them
are skipped there (pytest.importorskip); the compliance checker itself runs on the floors too.
"""
import json
import math
import socket

import numpy as np
import pytest
import xarray as xr

from tengsim.run.plan import ContactPlan
from tengsim.cli.main import main
from tengsim.results.read import load_result

runner = pytest.importorskip("compliance_checker.runner")

HIGH, MEDIUM = 3, 2
SPHERE = ["contact", "sphere", "--radius", "1um", "--pitch", "2um", "--E-star", "1MPa", "--W", "50mJ/m2",
          "--tabor", "1", "--dx", "0.5", "--d-min", "-0.5", "--d-max", "1", "--d-step", "0.5", "--maps", "1",
          "--quiet"]


@pytest.fixture
def offline(monkeypatch):
    """No network: any connection attempt fails the test (the checker must use its packaged tables)."""
    def refuse(*a, **k):
        raise AssertionError("network access attempted")

    monkeypatch.setattr(socket.socket, "connect", refuse)
    monkeypatch.setattr(socket, "create_connection", refuse)


_SUITE = []


def need(module):
    """The module, or skip: cf_xarray and pint-xarray releases that do not work with the installed xarray
    (the CI floors) fail to import with an ImportError, not only ModuleNotFoundError."""
    import importlib

    try:
        return importlib.import_module(module)
    except ImportError as exc:
        pytest.skip(f"{module} does not import here: {exc}")


def cf_check(path):
    """(failed checks as (weight, section, messages), checker exceptions) of the cf:1.10 check (about 1 s
    a file: its cost grows with the number of variables)."""
    if not _SUITE:
        _SUITE.append(runner.CheckSuite())
        _SUITE[0].load_all_available_checkers()
    cs = _SUITE[0]
    results, errors = cs.run_all(cs.load_dataset(str(path)), ["cf:1.10"], skip_checks=[])["cf:1.10"]
    failed = [(r.weight, r.name, r.msgs) for r in results
              if (r.value[0] < r.value[1] if isinstance(r.value, tuple) else not r.value)]
    return failed, errors


def contact_nc(tmp_path, args, name="c.nc"):
    out = tmp_path / name
    assert main([*args, "--out", str(out)]) == 0
    return out


@pytest.fixture(scope="module")
def sphere_nc(tmp_path_factory):
    """A physical sphere run with maps at D = 1 (approach and retraction), written by `tengsim contact`."""
    return contact_nc(tmp_path_factory.mktemp("sphere"), SPHERE)


def test_contact_nc_passes_the_cf_check(sphere_nc, offline):
    nc = sphere_nc
    failed, errors = cf_check(nc)
    assert errors == {} and failed == []  # every priority: high, medium and low
    ds = xr.load_dataset(nc)
    assert ds.attrs["Conventions"] == "CF-1.10" and ds.attrs["source"].startswith("tengsim ")
    assert "standard_name_vocabulary" not in ds.attrs  # the checker's packaged table, nothing downloaded
    assert {"title", "history", "references"} <= set(ds.attrs)
    assert ds["P"].dims == ("map", "x", "y") and ds.sizes["map"] == 2


def test_contact_layout_units_and_parameters_once(sphere_nc):
    nc = sphere_nc
    ds = xr.load_dataset(nc)
    # D and branch: auxiliary coordinates along 'step' (D repeats across the branches)
    assert "D" in ds.coords and "branch" in ds.coords and ds["D"].dims == ("step",)
    assert set(xr.open_dataset(nc)["F"].encoding["coordinates"].split()) == {"D", "branch"}
    approach = ds.isel(step=np.flatnonzero(ds["branch"].values == "approach")).swap_dims(step="D")
    assert float(approach["F"].sel(D=0.5)) == float(ds["F"].values[(ds["branch"].values == "approach")
                                                                     & (ds["D"].values == 0.5)][0])
    params = json.loads(ds.attrs["params"])
    # parameters once: the JSON text; no parameter repeated as its own attribute (status is the result's)
    assert set(ds.attrs) & set(params) <= {"status"}
    # dimensionless columns: units "1" with their scale as numbers; SI columns in UDUNITS units
    eps, lat = params["eps_m"], params["lateral_m"]
    for k, scale, unit in (("D", eps, "m"), ("min_gap", eps, "m"), ("contact_length", lat, "m"),
                           ("x", lat, "m"), ("H", eps, "m"), ("map_D", eps, "m")):
        a = ds[k].attrs
        assert a["units"] == "1" and a["unit_scale_units"] == unit, k
        assert a["unit_scale"] == pytest.approx(scale, rel=1e-12), k
    assert ds["D"].attrs["unit_scale_text"] == "ε"
    np.testing.assert_allclose(ds["F"] * ds["F"].attrs["unit_scale"], ds["F_N"], rtol=1e-12)
    np.testing.assert_allclose(ds["contact_length"] * ds["contact_length"].attrs["unit_scale"],
                               ds["contact_length_m"], rtol=1e-12)
    assert ds["F"].attrs["unit_scale_units"] == "N" and ds["P"].attrs["unit_scale_units"] == "Pa"
    W = params["W_J_m2"]
    assert ds["P"].attrs["unit_scale"] == pytest.approx(W / eps, rel=1e-12)
    assert (ds["F_N"].attrs["units"], ds["pressure_Pa"].attrs["units"], ds["contact_length_m"].attrs["units"],
            ds["seconds"].attrs["units"]) == ("N", "Pa", "m", "s")
    for k in ("converged", "jump", "on_grid", "in_law_range"):
        assert ds[k].dtype == np.int8 and list(ds[k].attrs["flag_values"]) == [0, 1], k
    for k, v in ds.variables.items():
        assert v.attrs.get("long_name"), k


def test_units_parse_with_pint_and_pint_xarray(sphere_nc):
    need("pint_xarray")
    cfu = need("cf_xarray.units")
    ureg = cfu.units
    ds = xr.load_dataset(sphere_nc)
    q = ds[["F_N", "pressure_Pa", "contact_length_m", "D", "P"]].pint.quantify()
    assert q["F_N"].data.units == ureg.newton and q["pressure_Pa"].data.units == ureg.pascal
    assert q["contact_length_m"].data.units == ureg.meter and q["D"].data.dimensionless
    q = ds.pint.quantify(unit_registry=ureg)  # every variable with units, by cf_xarray's UDUNITS registry
    assert str(q["F_N"].pint.to("mN").data.units) == "millinewton"
    for k, v in ds.variables.items():
        for attr in ("units", "unit_scale_units"):
            if attr in v.attrs:
                ureg.Unit(v.attrs[attr])  # parses
    D_m = ds["D"].values * ureg.Quantity(ds["D"].attrs["unit_scale"], ds["D"].attrs["unit_scale_units"])
    assert D_m.to("nm").magnitude == pytest.approx(ds["D"].values * json.loads(ds.attrs["params"])["eps_m"] * 1e9)


def test_round_trip_and_resave_keep_the_cf_metadata(tmp_path, sphere_nc):
    nc = sphere_nc
    kind, res = load_result(nc)
    assert kind == "contact" and len(res.maps) == 2
    ds = xr.load_dataset(nc)
    np.testing.assert_array_equal(res.table["D"], ds["D"].values)
    np.testing.assert_array_equal(res.table["branch"], ds["branch"].values)
    np.testing.assert_array_equal(res.maps[1]["P"], ds["P"].values[1])
    again = tmp_path / "again.nc"
    res.save(again)  # the scales come back from the parameters: the same metadata as the checked file
    b = xr.load_dataset(again)
    for k, v in ds.variables.items():
        assert b[k].attrs.keys() == v.attrs.keys(), k
        for a, x in v.attrs.items():
            if isinstance(x, str):
                assert b[k].attrs[a] == x, (k, a)
            else:
                np.testing.assert_allclose(b[k].attrs[a], x, rtol=1e-12, err_msg=f"{k}.{a}")
    assert {k: v for k, v in b.attrs.items() if k != "seconds"} == {k: v for k, v in ds.attrs.items()
                                                                    if k != "seconds"}


def test_file_of_the_previous_layout_still_loads(tmp_path, sphere_nc):
    """Before CF: D, branch, map_D, map_branch data variables, prose units, every simple parameter twice."""
    ds = xr.load_dataset(sphere_nc)
    params = json.loads(ds.attrs["params"])
    old = ds.reset_coords(["D", "branch", "map_D", "map_branch"])
    old["D"].attrs = {"units": "ε = 1.35721e-07 m (rigid approach, Eq. 7)"}
    old.attrs = {k: v for k, v in ds.attrs.items() if k not in ("Conventions", "title", "source", "history",
                                                                  "references")}
    old.attrs.update({k: v for k, v in params.items() if isinstance(v, (int, float, str))
                      and not isinstance(v, bool)})
    old.to_netcdf(tmp_path / "old.nc", engine="h5netcdf")
    _, res = load_result(tmp_path / "old.nc")
    _, new = load_result(sphere_nc)
    assert set(res.table) == set(new.table)
    for k in new.table:
        np.testing.assert_array_equal(res.table[k], new.table[k], err_msg=k)
    assert res.params == new.params and len(res.maps) == 2 and res.status == new.status


@pytest.mark.parametrize("bad, msg", [("{not json", "not JSON"), ("[1, 2]", "not a JSON object")])
def test_broken_params_attribute_is_one_clear_error(tmp_path, sphere_nc, bad, msg):
    from tengsim.errors import TengsimError

    ds = xr.load_dataset(sphere_nc)
    ds.attrs["params"] = bad
    ds.to_netcdf(tmp_path / "bad.nc", engine="h5netcdf")
    with pytest.raises(TengsimError, match=msg):
        load_result(tmp_path / "bad.nc")


def test_dimensionless_run_with_observers_passes_the_cf_check(tmp_path, offline):
    """A dimensionless pyramid (scales in words only) with maps and observer columns."""
    import tengsim as ts

    class Apex:
        columns = ("P_apex", "H_apex", "cells_x")
        units = {"P_apex": "W/ε", "cells_x": "cells"}

        def __call__(self, eq, ctx):
            return {"P_apex": eq.P[ctx.apex], "H_apex": eq.H[ctx.apex], "cells_x": 1.0}

    res = ts.simulate(ContactPlan(ts.Pyramid(0.946, 3.78), 0.5, 0.4, ts.PathSpec(-0.5, 0.5, 0.5, maps_at=(0.5,)), observers=[Apex()]))
    res.save(tmp_path / "o.nc")
    ds = xr.load_dataset(tmp_path / "o.nc")
    assert ds.sizes["map"] == 2 and ds["D"].attrs == {"long_name": "rigid approach D of the plate (Eq. 7)",
                                                       "units": "1", "unit_scale_text": "ε"}
    assert ds["contact_length"].attrs["unit_scale_text"] == "ℓ with ℓ = ε m/n"
    assert ds["P_apex"].attrs["units"] == "1" and ds["P_apex"].attrs["unit_scale_text"] == "W/ε (Eq. 8)"
    assert "units" not in ds["cells_x"].attrs and "cells" in ds["cells_x"].attrs["comment"]  # not UDUNITS
    assert "units" not in ds["H_apex"].attrs and ds["H_apex"].attrs["long_name"]
    assert cf_check(tmp_path / "o.nc") == ([], {})


@pytest.fixture(scope="module")
def study_nc(tmp_path_factory):
    """A 2-point physical study on an in-process Dask client (about 2 s)."""
    from distributed import Client

    from tengsim.study import parse_study, run_study

    out = tmp_path_factory.mktemp("study") / "s"
    base = {"shape": "sphere", "radius": "1um", "pitch": "2um", "E_star": "1MPa", "W": "50mJ/m2", "tabor": 1.0,
            "dx": 0.5, "d_min": -0.5, "d_max": 1.5, "d_step": 0.5}
    study = parse_study({"base": {"contact": base}, "axes": {"contact.tabor": [1.0, 1.2]},
                         "observables": {"pressures": ["5kPa", "1kPa"]}}, source="test")
    with Client(processes=False, n_workers=1, threads_per_worker=1, dashboard_address=None) as c:
        run_study(study, out, client=c, quiet=True)
    return out / "study.nc"


def test_study_nc_passes_the_cf_check(study_nc, offline):
    failed, errors = cf_check(study_nc)
    assert errors == {}
    assert [f for f in failed if f[0] >= HIGH] == []
    # CF names too (§2.3: letters, digits, '_'): the axis 'contact.tabor' is 'contact_tabor', its key kept
    assert failed == [], failed
    ds = xr.load_dataset(study_nc)
    assert ds.attrs["Conventions"] == "CF-1.10"
    assert ds["V_OC"].dims == ("contact_tabor", "applied_pressure") and ds["applied_pressure"].attrs["units"] == "Pa"
    assert ds["contact_tabor"].attrs["tengsim_key"] == "contact.tabor"
    v5 = ds["V_OC_at"].swap_dims(pressure_named="pressure_label").sel(pressure_label="5kPa")
    np.testing.assert_array_equal(v5.values, ds["V_OC_at"].values[:, 0])
    assert list(ds["pressure_named_Pa"].values) == [5e3, 1e3]
    assert ds["jump_in_D"].attrs["units"] == "1" and ds["jump_in_D"].attrs["unit_scale_text"] == "ε"
    assert ds["hysteresis_J_m2"].attrs["units"] == "J/m2"
    for k, v in ds.variables.items():
        assert v.attrs.get("long_name"), k


def test_study_units_parse_with_pint(study_nc):
    cfu = need("cf_xarray.units")
    ds = xr.load_dataset(study_nc)
    for k, v in ds.variables.items():
        if "units" in v.attrs:
            cfu.units.Unit(v.attrs["units"])


def test_device_nc_passes_the_cf_check(tmp_path, offline):
    from tengsim.cases.paper.device import fig7_params, fig7_waveform
    from tengsim.device.dynamics import simulate

    r = simulate(fig7_params(), fig7_waveform(), 0.004, dt_out=1e-4)
    r.to_dataset().to_netcdf(tmp_path / "d.nc", engine="h5netcdf")  # plain xarray writes it CF-clean too
    assert cf_check(tmp_path / "d.nc") == ([], {})
    ds = xr.load_dataset(tmp_path / "d.nc")
    assert ds["area"].attrs["units"] == "m2" and json.loads(ds.attrs["params"])
    assert math.isclose(float(ds["t"][-1]), 0.004, rel_tol=1e-9)
