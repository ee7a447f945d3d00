"""No traceback reaches a user: an internal error (any exception that is not a TengsimError) is one line
naming it and the log file that holds its traceback, exit code 70 (EX_SOFTWARE); bad input stays exit 2."""
import re
import tempfile
from pathlib import Path

import pytest

import tengsim.cli.plot as plot_cli
from tengsim.cli.main import INTERNAL_ERROR, main
from tengsim.errors import TengsimError


def _boom(args):
    raise ValueError("something broke\nin two lines")


@pytest.fixture
def broken_plot(monkeypatch):
    monkeypatch.setattr(plot_cli, "run", _boom)  # 'tengsim plot' now fails inside tengsim


def test_internal_error_is_one_line_with_the_log_path(tmp_path, monkeypatch, capsys, broken_plot):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    assert main(["plot", "x.nc"]) == INTERNAL_ERROR == 70
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1 and "Traceback" not in err
    m = re.fullmatch(r"tengsim: internal error: ValueError: something broke in two lines \(traceback in (.+)\)\n", err)
    assert m, err
    log = Path(m.group(1))
    assert log.parent == tmp_path / "cache" / "tengsim"
    text = log.read_text()
    assert "Traceback (most recent call last)" in text and "ValueError: something broke" in text
    assert "command: tengsim plot x.nc" in text and "_boom" in text


def test_internal_error_log_falls_back_to_the_temp_folder(tmp_path, monkeypatch, capsys, broken_plot):
    blocker = tmp_path / "not-a-folder"
    blocker.write_text("")
    monkeypatch.setenv("XDG_CACHE_HOME", str(blocker))  # the cache folder cannot be made
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path / "tmp"))
    (tmp_path / "tmp").mkdir()
    assert main(["plot", "x.nc"]) == 70
    err = capsys.readouterr().err
    assert f"(traceback in {tmp_path / 'tmp' / 'tengsim'}" in err and err.count("\n") == 1


def test_internal_error_without_any_writable_log_folder_is_still_one_line(tmp_path, monkeypatch, capsys,
                                                                          broken_plot):
    blocker = tmp_path / "file"
    blocker.write_text("")
    monkeypatch.setenv("XDG_CACHE_HOME", str(blocker))
    monkeypatch.setattr(tempfile, "tempdir", str(blocker))
    assert main(["plot", "x.nc"]) == 70
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "traceback not saved" in err and "Traceback" not in err


def test_user_errors_stay_exit_2_without_a_log(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))

    def bad(args):
        raise TengsimError("bad value 'x'")

    monkeypatch.setattr(plot_cli, "run", bad)
    assert main(["plot", "x.nc"]) == 2
    assert capsys.readouterr().err == "tengsim: error: bad value 'x'\n"
    assert not (tmp_path / "cache").exists()
