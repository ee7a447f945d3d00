"""Issue 48, items 3 and 6: the one reader of measured data knows what spreadsheets write (a BOM, CRLF, ',' ';' or a
tab, decimal commas refused, mPa not MPa, fields and rows bounded, voltages no σ in bounds can reach refused), and
every calibrate and device option is read by the units/number reader.  Each test failed on the code before; all are
fast (no design is solved: what is refused is refused at planning)."""
import numpy as np
import pytest

from tengsim.calibrate.data import read_curve
from tengsim.cli.main import main
from tengsim.errors import TengsimError

DESIGN = ('[design]\nshape = "pyramid"\npitch = "1um"\nbase = "0.5um"\nheight = "0.2um"\nE_star = "10MPa"\n'
          'eps = "50nm"\ntol = 0.05\n')
MAX_POINTS = 10_000  # tengsim.calibrate.data.MAX_POINTS (a literal, so that this file runs on the old code too)
GOOD = "pressure_kPa,voc_V\n2,6.1\n4,6.4\n6,6.6\n8,6.7\n"


def _csv(tmp_path, content, name="m.csv"):
    f = tmp_path / name
    f.write_bytes(content if isinstance(content, bytes) else content.encode("utf-8"))
    return f


def _refused(tmp_path, capsys, argv, says):
    """calibrate ``argv`` is exit 2, one line holding ``says``, nothing written."""
    (tmp_path / "d.toml").write_text(DESIGN)
    out = tmp_path / "out"
    before = sorted(p.name for p in tmp_path.iterdir())
    rc = main(["calibrate", str(tmp_path / "d.toml"), "--out", str(out), "--quiet", *map(str, argv)])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and len(err.splitlines()) == 1 and "internal error" not in err, err
    assert says in err, err
    assert not out.exists() and sorted(p.name for p in tmp_path.iterdir()) == before
    return err


# ---- what spreadsheets write -----------------------------------------------------------------------------
def test_bom_csv_is_read(tmp_path):
    """Excel's "CSV UTF-8" starts with a byte-order mark: read, not "no pressure column"; so is UTF-16 (Excel's
    "Unicode text", tab-separated)."""
    c = read_curve(_csv(tmp_path, b"\xef\xbb\xbf" + GOOD.encode()))
    assert c.pressure.tolist() == [2e3, 4e3, 6e3, 8e3] and c.voc.tolist() == [6.1, 6.4, 6.6, 6.7]
    c16 = read_curve(_csv(tmp_path, GOOD.replace(",", "\t").encode("utf-16"), "u16.csv"))
    assert c16.voc.tolist() == [6.1, 6.4, 6.6, 6.7]


def test_crlf_and_trailing_empty_fields_are_read(tmp_path):
    c = read_curve(_csv(tmp_path, "pressure_kPa,voc_V,\r\n2,6.1,\r\n4,6.4,,\r\n"))
    assert c.voc.tolist() == [6.1, 6.4]


@pytest.mark.parametrize("sep", [";", "\t"])
def test_semicolon_and_tab_separators_are_read(tmp_path, sep):
    c = read_curve(_csv(tmp_path, GOOD.replace(",", sep)))
    assert c.pressure.tolist() == [2e3, 4e3, 6e3, 8e3] and c.voc.tolist() == [6.1, 6.4, 6.6, 6.7]


@pytest.mark.parametrize("content, says", [
    ("pressure_kPa;voc_V\n2;6.1\n4,6.4\n", "line 3: 1 value for 2 columns (pressure_kPa, voc_V); this line is "
                                           "separated by ',', the header by ';'"),
    ("pressure_kPa voc_V\n2 6.1\n", "the header 'pressure_kPa voc_V' is one column: separate the columns with ',', "
                                    "';' or a tab"),
])
def test_a_separator_that_is_the_problem_is_named_not_the_unit(tmp_path, content, says):
    with pytest.raises(TengsimError) as e:
        read_curve(_csv(tmp_path, content))
    assert says in str(e.value) and "unit" not in str(e.value)


@pytest.mark.parametrize("content, says", [
    ("pressure_kPa,voc_V\n2,6,1\n4,6.4\n", "line 2: 3 values for 2 columns (pressure_kPa, voc_V); a decimal comma? "
                                           "write 6.1, not 6,1"),
    ("pressure_kPa;voc_V\n2;6,1\n4;6.4\n", "line 2: voc_V = '6,1' has a decimal comma: write 6.1"),
    ('pressure_kPa,voc_V\n2,"6,1"\n4,6.4\n', "voc_V = '6,1' has a decimal comma: write 6.1"),
])
def test_decimal_comma_refused(tmp_path, capsys, content, says):
    """'2,6,1' meant as 6.1 V was read as 6 V with the '1' dropped, exit 0; now one line, exit 2."""
    _refused(tmp_path, capsys, ["--data", _csv(tmp_path, content)], says)


def test_a_row_with_more_fields_than_the_header_is_refused(tmp_path):
    with pytest.raises(TengsimError, match=r"line 3: 3 values for 2 columns"):
        read_curve(_csv(tmp_path, "pressure_kPa,voc_V\n2,6.1\n4,6.4,7\n"))


@pytest.mark.parametrize("col", ["pressure_mPa", "pressure_MPA", "pressure (mpa)"])
def test_pressure_mPa_not_read_as_MPa(tmp_path, col):
    """The unit was lower-cased before matching: pressure_mPa (millipascal) was read as MPa.  Refused with the
    accepted spellings; kPa/Pa, whose case cannot mislead, are read in any case."""
    with pytest.raises(TengsimError, match=r"mPa would be millipascal, MPa megapascal; write the unit as "
                                           r"pressure_Pa, pressure_kPa or pressure_MPa"):
        read_curve(_csv(tmp_path, GOOD.replace("pressure_kPa", col)))
    assert read_curve(_csv(tmp_path, GOOD.replace("pressure_kPa", "pressure_MPa"))).pressure[0] == 2e6
    assert read_curve(_csv(tmp_path, GOOD.replace("pressure_kPa", "Pressure_KPA"))).pressure[0] == 2e3


def test_a_long_field_is_one_line_not_an_internal_error(tmp_path, capsys):
    """A field over csv's 131 072 characters crashed with exit 70."""
    _refused(tmp_path, capsys, ["--data", _csv(tmp_path, "pressure_kPa,voc_V\n2," + "9" * 140_000 + "\n")],
             "line 2: 140002 characters, more than a measured curve's line (4096 at most)")


def test_a_million_rows_are_refused_while_reading(tmp_path, capsys):
    """10⁶ rows ran past 150 s with no output: the count is bounded, checked while streaming (the message names
    the first line past the bound)."""
    body = "".join(f"{i},{1 + i * 1e-6:.6f}\n" for i in range(1, 10**6))
    _refused(tmp_path, capsys, ["--data", _csv(tmp_path, "pressure_kPa,voc_V\n" + body)],
             f"line {MAX_POINTS + 2}: more than {MAX_POINTS} points")


def test_a_folder_as_data_says_it_is_a_folder(tmp_path, capsys):
    (tmp_path / "m").mkdir()
    _refused(tmp_path, capsys, ["--data", tmp_path / "m"], "is a folder, not a CSV file")


def test_an_underscore_in_a_measured_value_is_refused(tmp_path):
    with pytest.raises(TengsimError, match=r"line 3: voc_V = '6_4': no underscores"):
        read_curve(_csv(tmp_path, "pressure_kPa,voc_V\n2,6.1\n4,6_4\n"))


# ---- voltages that no σ in bounds can reach --------------------------------------------------------------
def test_all_zero_voltages_are_refused_with_the_reason(tmp_path, capsys):
    """All voltages 0 crashed with a log-scale error (exit 70)."""
    _refused(tmp_path, capsys, ["--data", _csv(tmp_path, "pressure_kPa,voc_V\n2,0\n4,0\n6,0\n8,0\n")],
             "every voc_V is 0 V: nothing to fit")


def test_picovolt_data_are_refused_with_the_reason(tmp_path, capsys):
    """1e-12 V data exited 0 with "noise 7.38e+11 %": below one pixel of the largest grid at the lowest σ."""
    err = _refused(tmp_path, capsys, ["--data", _csv(tmp_path, "pressure_kPa,voc_V\n2,1e-12\n4,1e-12\n6,2e-12\n"
                                                               "8,2e-12\n")],
                   "its largest voltage 2e-12 V is below what the design can give at any σ within bounds")
    assert "check the voltage's unit" in err


# ---- --bounds -------------------------------------------------------------------------------------------
@pytest.mark.parametrize("bounds, says", [
    ("W=10mJ/m2", "--bounds W='10mJ/m2': give W=LOW:HIGH, e.g. W=20mJ/m2:200mJ/m2"),
    ("W=", "--bounds W='': give W=LOW:HIGH"),
    ("W=1mJ/m2:2mJ/m2:3mJ/m2", "give W=LOW:HIGH"),
    ("W10mJ/m2:20mJ/m2", "give NAME=LOW:HIGH"),
])
def test_a_bound_without_its_colon_is_one_line_not_an_internal_error(tmp_path, capsys, bounds, says):
    _refused(tmp_path, capsys, ["--data", _csv(tmp_path, GOOD), "--bounds", bounds], says)


def test_a_bound_outside_the_allowed_range_says_the_range(tmp_path, capsys):
    """W=1e5mJ/m2:1e6mJ/m2 blamed the design file for a W it does not contain and asked for a unit that was given."""
    err = _refused(tmp_path, capsys, ["--data", _csv(tmp_path, GOOD), "--bounds", "W=1e5mJ/m2:1e6mJ/m2"],
                   "--bounds W: 1e+05 mJ/m² to 1e+06 mJ/m² is outside the allowed range 1 µJ/m² to 10 J/m²")
    assert "d.toml" not in err and "give it with its unit" not in err


def test_a_repeated_bound_is_refused(tmp_path, capsys):
    _refused(tmp_path, capsys, ["--data", _csv(tmp_path, GOOD), "--bounds", "W=20mJ/m2:200mJ/m2,W=30mJ/m2:40mJ/m2"],
             "--bounds W is given twice")


def test_bounds_on_a_parameter_not_free_are_refused(tmp_path, capsys):
    _refused(tmp_path, capsys, ["--data", _csv(tmp_path, GOOD), "--free", "sigma,W", "--bounds", "eps=30nm:300nm"],
             "--bounds eps: eps is not free (--free sigma,W): its bounds would be ignored")


def test_bounds_within_the_allowed_range_are_read_in_SI():
    from tengsim.calibrate.problem import parse_bounds

    b = parse_bounds("sigma=1uC/m2:100uC/m2,W=20mJ/m2:200mJ/m2,eps=30nm:300nm", ("sigma", "W", "eps"))
    assert b == {"sigma": pytest.approx((1e-6, 1e-4)), "W": pytest.approx((0.02, 0.2)),
                 "eps": pytest.approx((3e-8, 3e-7))}


# ---- the other options ----------------------------------------------------------------------------------
@pytest.mark.parametrize("argv, says", [
    (["--expected-noise", "0_5%"], "--expected-noise 0_5%: no underscores in numbers"),
    (["--nodes", "0_4"], "argument --nodes: '0_4': no underscores in numbers"),
    (["--zooms", "1_0"], "argument --zooms: '1_0': no underscores in numbers"),
    (["--nodes", "4.5"], "argument --nodes: '4.5' is not a whole number"),
    (["--expected-noise", "-1%"], "--expected-noise -1%: a positive noise below 100 %"),
    (["--noise", "absolute", "--expected-noise", "-5mV"], "--expected-noise -5mV: a positive noise"),
])
def test_calibrate_options_are_read_by_the_number_reader(tmp_path, capsys, argv, says):
    """'--expected-noise 0_5%' was read as 5 %, '--nodes 0_4' as 4; '--expected-noise -1%' said "expected one
    argument" (argparse took it for an option)."""
    _refused(tmp_path, capsys, ["--data", _csv(tmp_path, GOOD), *argv], says)


def test_expected_noise_in_millivolts_is_read():
    from tengsim.cli.calibrate import _expected_noise

    assert _expected_noise("50mV", "absolute") == pytest.approx(0.05)
    assert _expected_noise("2 %", "relative") == pytest.approx(0.02)


def test_a_value_starting_with_a_dash_hints_at_the_equals_form(tmp_path, capsys):
    err = _refused(tmp_path, capsys, ["--data", _csv(tmp_path, GOOD), "--bounds", "-W"], "expected one argument")
    assert "--option=VALUE" in err


# ---- the device's options -------------------------------------------------------------------------------
def _area_nc(path):
    import xarray as xr

    p = np.array([0.0, 5e3, 10e3, 20e3])
    a = np.array([0.05, 0.1, 0.15, 0.2])
    xr.Dataset({"charged_area_fraction": (("branch", "applied_pressure"), np.stack([a, a]))},
               coords={"branch": ["approach", "retraction"], "pressure": ("applied_pressure", p)}
               ).to_netcdf(path, engine="h5netcdf")
    return path


@pytest.mark.parametrize("argv, says", [
    (["--pressure", "-5kPa"], "the pressure must be > 0 kPa, got -5 kPa"),
    (["--pressure", "-0.5MPa"], "the pressure must be > 0 MPa, got -0.5 MPa"),
    (["--pressure", "-5000"], "the pressure must be > 0 Pa, got -5000 Pa"),
    (["--electrode-area", "-4cm2"], "--electrode-area must be > 0, got '-4cm2'"),
    (["--electrode-area", "4kg"], "--electrode-area = '4kg' is a mass, expected an area"),
])
def test_device_answers_in_the_users_unit(tmp_path, capsys, argv, says):
    """'--pressure -5kPa' was answered in Pa ("got -5000 Pa")."""
    area = _area_nc(tmp_path / "a.nc")
    out = tmp_path / "x.csv"
    assert main(["device", "design", "--area-from", str(area), *argv, "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and says in err and not out.exists(), err


def test_electrode_area_takes_units_and_a_bare_number_is_SI():
    """--electrode-area took a "plain number" in m² where every other option takes units: now an area with its
    unit (the prefix squared: 4cm2 is 4e-4 m²), a bare number SI (m²) as every bare number is."""
    from tengsim.device.config import DEVICE_TABLE
    from tengsim.units import parse_quantity

    f = DEVICE_TABLE.fields["area_m2"]
    for text, si in (("4cm2", 4e-4), ("4 cm²", 4e-4), ("1e-4m2", 1e-4), ("400mm^2", 4e-4), ("4e-4", 4e-4)):
        assert f.parse(text) == pytest.approx(si, rel=1e-12), text
    assert parse_quantity("2um", "length") == pytest.approx(2e-6)  # lengths keep their linear prefix
    assert parse_quantity("5N/m2", "pressure") == 5.0
