"""tengsim calibrate never destroys an input, never shares a folder with another run, never keeps a failure of
the machine as the design's answer (issue 48: the output guard and lock, machine failures, errors by type).

The node solve is replaced where only the guard, the lock or the caching is under test (the real
:func:`tengsim.calibrate.surrogate.solve_node` runs around a replaced ``run_design``), so each test takes
seconds."""
import os
import sys
import time
from dataclasses import dataclass
from typing import ClassVar

import pytest

from tengsim.cli.main import main

G1 = {"shape": "pyramid", "pitch": "1um", "base": "0.5um", "height": "0.2um", "E_star": "10MPa", "eps": "50nm",
      "tol": 0.05}
DATA = "pressure_kPa,voc_V\n5,2\n10,3\n15,4\n20,4.5\n"


def _toml(path, table=G1):
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("[design]\n" + "".join(f"{k} = {v!r}\n".replace("'", '"') for k, v in table.items()))
    return path


def _csv(path, text=DATA):
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    return path


def _one_line(capsys):
    err = capsys.readouterr().err.strip()
    lines = err.splitlines()
    assert lines and lines[-1].startswith("tengsim: error:") and "Traceback" not in err, err[-800:]
    return lines[-1]


class Solved(Exception):
    """Raised by a replaced node solve: the run got past its guard and lock (the old code's defect)."""


@pytest.fixture
def no_solve(monkeypatch):
    """Every node solve raises :class:`Solved`: a test that expects a refusal fails fast if the run starts."""
    def solve(*a, **k):
        raise Solved("a node was solved")

    monkeypatch.setattr("tengsim.calibrate.surrogate.solve_node", solve)


def _calibrate(design, data, out, *extra):
    return main(["calibrate", str(design), "--data", str(data), "--free", "sigma,W", "--out", str(out), "--quiet",
                 *extra])


# ---- data destroyed: the output guard ----------------------------------------------------------------------

@pytest.mark.parametrize("data_name", ["fit.csv", "report.md", "sub/m.csv"])
def test_calibrate_refuses_out_holding_its_data(tmp_path, capsys, no_solve, data_name):
    out = tmp_path / "o"
    data = _csv(out / data_name)
    before = sorted(p.relative_to(out) for p in out.rglob("*"))
    rc = _calibrate(_toml(tmp_path / "d.toml"), data, out)
    line = _one_line(capsys)
    assert rc == 2 and "holds the input" in line and data_name in line, line
    assert data.read_text() == DATA  # the measurement is kept
    assert sorted(p.relative_to(out) for p in out.rglob("*")) == before  # nothing written


def test_calibrate_refuses_out_holding_its_design(tmp_path, capsys, no_solve):
    out = tmp_path / "o"
    design = _toml(out / "material.toml")
    text = design.read_text()
    rc = _calibrate(design, _csv(tmp_path / "m.csv"), out)
    line = _one_line(capsys)
    assert rc == 2 and "holds the input" in line and "material.toml" in line, line
    assert design.read_text() == text and sorted(os.listdir(out)) == ["material.toml"]


def test_calibrate_refuses_out_that_is_a_link_to_its_data(tmp_path, capsys, no_solve):
    """A hard link to the data where the calibration writes its table: refused (the data would be replaced)."""
    data = _csv(tmp_path / "m.csv")
    out = tmp_path / "o"
    out.mkdir()
    os.link(data, out / "fit.csv")
    rc = _calibrate(_toml(tmp_path / "d.toml"), data, out)
    line = _one_line(capsys)
    assert rc == 2 and "fit.csv" in line and "m.csv" in line, line
    assert data.read_text() == DATA


def test_design_refuses_out_holding_its_material(tmp_path, capsys):
    out = tmp_path / "o"
    mat = out / "material.toml"
    mat.parent.mkdir()
    mat.write_text('[material]\nE_star = "10MPa"\nW = "25mJ/m2"\neps = "50nm"\nsigma = "8uC/m2"\n')
    text = mat.read_text()
    rc = main(["design", str(_toml(tmp_path / "d.toml", {**G1, "p_max": "10kPa"})), "--material", str(mat),
               "--out", str(out), "--quiet"])
    line = _one_line(capsys)
    assert rc == 2 and "holds the input" in line and "material.toml" in line, line
    assert mat.read_text() == text and sorted(os.listdir(out)) == ["material.toml"]


# ---- two runs on one folder: the lock --------------------------------------------------------------------

def test_calibrate_refused_at_once_while_a_design_holds_its_out(tmp_path, capsys, no_solve):
    from tengsim.outfolder import folder_lock

    out = tmp_path / "o"
    with folder_lock(out, holder="tengsim design"):
        t0 = time.monotonic()
        rc = _calibrate(_toml(tmp_path / "d.toml"), _csv(tmp_path / "m.csv"), out)
        line = _one_line(capsys)
        assert time.monotonic() - t0 < 20
    assert rc == 2 and "in use by another tengsim run" in line, line
    assert str(out) in line and "tengsim design" in line and f"pid {os.getpid()}" in line, line
    assert not out.exists()  # made for the lock alone: removed again


def test_design_refused_while_a_calibration_holds_its_out(tmp_path, capsys, monkeypatch):
    """A design started on a calibration's --out while it runs (inside its node solve) is refused at once."""
    out = tmp_path / "o"
    seen = {}

    def solve(*a, **k):  # the first run, inside its lock: a design on the same folder now
        seen["rc"] = main(["design", str(_toml(tmp_path / "d2.toml", {**G1, "W": "25mJ/m2", "p_max": "10kPa"})),
                           "--out", str(out), "--quiet"])
        seen["line"] = _one_line(capsys)
        raise KeyboardInterrupt

    monkeypatch.setattr("tengsim.calibrate.surrogate.solve_node", solve)
    assert _calibrate(_toml(tmp_path / "d.toml"), _csv(tmp_path / "m.csv"), out) == 130
    assert seen["rc"] == 2 and "in use" in seen["line"] and "tengsim calibrate" in seen["line"], seen
    assert not (out / "design.nc").exists() and not (out / "report.md").exists()


def test_two_calibrations_on_one_out_the_second_refused_at_once(tmp_path, capsys, monkeypatch):
    out = tmp_path / "o"
    design, data = _toml(tmp_path / "d.toml"), _csv(tmp_path / "m.csv")
    seen = {}

    def solve(table, folder, *a, **k):
        t0 = time.monotonic()
        seen["rc"] = _calibrate(design, data, out)
        seen["seconds"] = time.monotonic() - t0
        seen["line"] = _one_line(capsys)
        raise KeyboardInterrupt

    monkeypatch.setattr("tengsim.calibrate.surrogate.solve_node", solve)
    assert _calibrate(design, data, out) == 130
    assert seen["rc"] == 2 and seen["seconds"] < 20, seen
    assert "in use by another tengsim run" in seen["line"] and str(out) in seen["line"], seen
    assert "resolve.nc" not in seen["line"] and "tengsim calibrate" in seen["line"]


def test_two_calibrations_through_the_api_never_share_their_designs(tmp_path, no_solve):
    from tengsim.calibrate import calibrate, plan_calibration
    from tengsim.errors import TengsimError
    from tengsim.outfolder import folder_lock

    prob = plan_calibration([_toml(tmp_path / "d.toml")], [_csv(tmp_path / "m.csv")], "sigma,W")
    with folder_lock(tmp_path / "o" / "designs", holder="tengsim calibrate"):
        with pytest.raises(TengsimError, match="in use by another tengsim run"):
            calibrate(prob, tmp_path / "o")


# ---- failures of the machine are not results ------------------------------------------------------------

def test_calibrate_preflights_a_solver_this_machine_lacks(tmp_path, capsys, no_solve, monkeypatch):
    """--solver pk-jax without JAX: one line, exit 2, nothing written (no .failed.txt, no advice on the bounds)."""
    monkeypatch.setitem(sys.modules, "jax", None)  # `import jax` fails as where it is not installed
    out = tmp_path / "o"
    rc = _calibrate(_toml(tmp_path / "d.toml"), _csv(tmp_path / "m.csv"), out, "--solver", "pk-jax")
    line = _one_line(capsys)
    assert rc == 2 and "needs JAX" in line and "bounds" not in line, line
    assert not out.exists()


def _node(tmp_path, monkeypatch, exc):
    """solve_node's answer (and the designs folder) when the design run raises ``exc``."""
    from tengsim.calibrate.surrogate import node_table, solve_node

    def run_design(*a, **k):
        raise exc

    monkeypatch.setattr("tengsim.design.run_design", run_design)
    table = node_table(G1, 25e-3, 50e-9, 10e6, 50e3)
    folder = tmp_path / "designs"
    return solve_node(table, folder, 0.0, 0.0), folder


@pytest.mark.parametrize("which", ["budget", "budget_stop", "memory", "memory_error"])
def test_a_node_stopped_by_the_machine_is_not_kept_as_failed(tmp_path, monkeypatch, which):
    from tengsim.errors import BudgetExceeded, MemoryRefused
    from tengsim.run.budget import BudgetSpent

    exc = {"budget": BudgetExceeded("expected to take 12 min, over the budget: a larger --budget", 600.0),
           "budget_stop": BudgetSpent("d: stopped at the budget of 10 min; run with a larger --budget", 600.0),
           "memory": MemoryRefused("a 4096×4096 grid needs about 9 GiB of memory, but 2 GiB is available"),
           "memory_error": MemoryError()}[which]
    node, folder = _node(tmp_path, monkeypatch, exc)
    assert not node.ok and node.machine and not node.cached
    assert not list(folder.glob("*.failed.txt"))  # the next run tries it again
    assert "--budget" not in node.message and "tries it again" in node.message, node.message


def test_the_designs_own_failure_is_kept(tmp_path, monkeypatch):
    from tengsim.errors import GeometryError

    node, folder = _node(tmp_path, monkeypatch, GeometryError("a pyramid wider than its cell"))
    assert not node.ok and not node.machine
    assert len(list(folder.glob("*.failed.txt"))) == 1


def test_an_interrupted_node_is_not_kept_as_failed(tmp_path, monkeypatch):
    with pytest.raises(KeyboardInterrupt):
        _node(tmp_path, monkeypatch, KeyboardInterrupt())
    assert not list((tmp_path / "designs").glob("*.failed.txt"))


def test_no_design_for_the_machines_reason_gives_no_advice_on_the_design(tmp_path):
    import numpy as np

    from tengsim.calibrate.surrogate import Node, Surrogate
    from tengsim.errors import TengsimError

    s = Surrogate(np.linspace(0, 1e4, 21), [Node(0.0, 0.0, False, message="out of memory on this machine; not "
                                                 "kept as failed: the next run tries it again", machine=True)],
                  (1.0, 1.0), (0,))
    with pytest.raises(TengsimError, match="stopped by this machine") as e:
        s.rbf("approach")
    assert "tol" not in str(e.value) and "bounds" not in str(e.value)


def test_a_nodes_key_covers_the_content_of_its_topography_file(tmp_path):
    from tengsim.calibrate.surrogate import node_key

    h = tmp_path / "h.csv"
    h.write_text("0,1\n1,0\n")
    table = {"shape": "topography", "file": str(h), "W": 0.025}
    first = node_key(table)
    st = h.stat()
    h.write_text("0,2\n2,0\n")  # the same size; a later modification time, as an edit gives
    os.utime(h, ns=(st.st_atime_ns, st.st_mtime_ns + 10**9))
    assert node_key(table) != first
    assert node_key({"shape": "pyramid", "W": 0.025}) == node_key({"W": 0.025, "shape": "pyramid"})


def test_ctrl_c_names_the_folder_of_the_finished_designs(tmp_path, capsys, monkeypatch):
    out = tmp_path / "o"
    calls = []

    def solve(table, folder, *a, **k):
        calls.append(1)
        if len(calls) == 2:
            raise KeyboardInterrupt
        folder.mkdir(parents=True, exist_ok=True)
        (folder / "0123456789abcdef.nc").write_bytes(b"")  # a finished design (the solve is replaced)
        from tengsim.calibrate.surrogate import Node

        return Node(0.0, 0.0, False, message="replaced")

    monkeypatch.setattr("tengsim.calibrate.surrogate.solve_node", solve)
    assert _calibrate(_toml(tmp_path / "d.toml"), _csv(tmp_path / "m.csv"), out) == 130
    err = capsys.readouterr().err
    assert str(out / "designs") in err and "takes them back" in err and "said where above" not in err, err


# ---- errors by type, statuses by value ------------------------------------------------------------------

def test_the_budget_counts_the_runs_own_cpu_time_not_a_busy_machines_clock():
    from types import SimpleNamespace

    from tengsim.run.budget import BudgetSpent, RunClock, deadline

    ask = SimpleNamespace(budget_s=5.0, name="d")
    busy = RunClock(time.monotonic() - 60.0, RunClock.now().cpu)  # a minute by the clock, no CPU time of ours
    deadline(None, ask, None, busy)("approach", 0.0, 1, 2)  # not stopped: the run has had none of its budget
    with pytest.raises(BudgetSpent, match="CPU time"):
        deadline(None, ask, None, RunClock(time.monotonic() - 60.0, RunClock.now().cpu - 60.0))("approach")
    with pytest.raises(BudgetSpent, match="wall time"):  # a GPU run: the host waits, the clock counts
        deadline(None, ask, None, busy, cpu=False)("approach")


@dataclass
class _Resumable:
    """A solver that resumes from its state and must not be asked to (persist would call :meth:`solve`)."""

    max_iter: int = 5
    resumes_from_state: ClassVar[bool] = True

    def solve(self, problem, state):
        raise AssertionError("persisted")


def test_persist_reads_the_cap_by_value_not_by_the_message():
    from dataclasses import replace

    import numpy as np

    from tengsim.continuation.walker import persist
    from tengsim.solvers.types import Equilibrium, State

    z = np.zeros((2, 2))
    eq = Equilibrium(State(z, z), z, z, 1.0, False, 5, 5, 0.0, 0.0, "not converged in 5 iterations", capped=False)
    assert persist(_Resumable(), None, eq) is eq  # its message reads like a cap; its value says it is not one
    with pytest.raises(AssertionError, match="persisted"):  # a cap, whatever the message says: gone on from
        persist(_Resumable(), None, replace(eq, message="stopped", capped=True))


def test_no_error_is_classified_by_its_text():
    import pathlib
    import re

    src = pathlib.Path(__file__).resolve().parents[1] / "src" / "tengsim"
    # a literal looked for in an error's text ("memory" not in str(exc)), a message read for its status
    bad = re.compile(r"""["'][^"']*["']\s+(not\s+)?in\s+str\((exc|e|err)\)|str\((exc|e|err)\)\.startswith|"""
                     r"""message\)?\.startswith\(""")
    hits = [f"{p}:{i}" for p in src.rglob("*.py") for i, ln in enumerate(p.read_text().splitlines(), 1)
            if bad.search(ln)]
    assert not hits, hits


# ---- estimates that hold -----------------------------------------------------------------------------------

def test_the_expected_designs_count_the_whole_run_not_the_first_grid(tmp_path):
    """The README's calibration (W free, ε fixed, 4 nodes, 2 zooms, 3 refinements): 37 designs expected (it made
    34), 42 at most (the old estimate counted the first grid's 4)."""
    from tengsim.calibrate import plan_calibration
    from tengsim.calibrate.checks import expected_designs

    prob = plan_calibration([_toml(tmp_path / "d.toml")], [_csv(tmp_path / "m.csv")], "sigma,W")
    batches, most = expected_designs(prob, 4, 2, 3, 1, 1)
    assert batches == [4, 5, 4, 5, 4, 5, 5, 5] and most == 42
    prob2 = plan_calibration([_toml(tmp_path / "d.toml")], [_csv(tmp_path / "m.csv")], "sigma,W,eps")
    assert expected_designs(prob2, 3, 1, 0, 2, 2) == ([18, 18, 18, 18], 72)


def test_calibrate_says_the_whole_runs_time_after_the_first_design(tmp_path, capsys, monkeypatch):
    from tengsim.calibrate.surrogate import Node

    calls = []

    def solve(table, folder, u, v, *a, **k):
        calls.append(1)
        if len(calls) == 3:
            raise KeyboardInterrupt
        return Node(u, v, False, message="replaced", seconds=30.0)

    monkeypatch.setattr("tengsim.calibrate.surrogate.solve_node", solve)
    rc = main(["calibrate", str(_toml(tmp_path / "d.toml")), "--data", str(_csv(tmp_path / "m.csv")), "--free",
               "sigma,W", "--bounds", "W=10mJ/m2:60mJ/m2", "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert rc == 130
    assert "the calibration: about 37 designs (at most 42" in err, err
    # after the first design (30 s): the 36 left at 30 s each, 18 min
    assert "the whole calibration: about 18.0 min more (36 designs expected at 30 s each" in err, err
