"""Study results you can trust (issue 21): one status end to end (sweep line, point file, study.csv,
study.nc, optimize), resume that opens and checks every point file, point ids that cover the code and
the input files, and every registered shape through a study with its device observables."""
import csv
import io
import json
from pathlib import Path

import h5py
import numpy as np
import pytest
import xarray as xr

from tengsim import plugins
from tengsim.cli.main import main
from tengsim.errors import TengsimError
from tengsim.status import SEVERITY
from tengsim.study import parse_study, run_study
from tengsim.study.resume import check_resume, resolved_with_provenance
from tengsim.study.worker import compute_point
from tengsim.study.hashing import point_id
from tengsim.study.layout import StudyDir
from tengsim.study.points import check_point, provenance, write_point

# a sphere whose status turns from ok to under_resolved between dx = 0.4 and 0.45.  Issue 22 item 2: it was
# a Maugis–Dugdale sphere at μ = 3, whose dx 0.3 / 0.4 were 'ok' with pull-offs 6 % apart (pixel snap
# number ≈ 12: every grid is under-resolved now); LJ 9-3 at μ = 0.5: dx 0.3 / 0.35-0.4 ok (process zone
# 0.44 >= 1.2 dx), pull-off -0.5275 / -0.5274; dx 0.45-0.5 under_resolved (grid 0.444, zone 0.47), -0.5308
MD = {"shape": "sphere", "radius": 1.0, "cell": 4.0, "law": "lj93", "tabor": 0.5, "dx": 0.5, "d_min": -0.5,
      "d_max": 0.5, "d_step": 0.25}


@pytest.fixture(scope="module")
def client(study_client):
    """The session's 2-worker LocalCluster (conftest.study_client: the one `tengsim sweep --workers 2`
    starts), shared with the other study test modules."""
    return study_client


def md_study(dxs):
    return parse_study({"base": {"contact": dict(MD)}, "axes": {"contact.dx": list(dxs)}}, source="md")


def csv_rows(path):
    return list(csv.DictReader(open(path)))


# ---- one status, end to end ---------------------------------------------------------------------

@pytest.fixture(scope="module")
def md_dir(client, tmp_path_factory):
    """The issue's sweep over dx of an MD sphere (two ok, two under-resolved grids), computed once:
    (study, directory, summary, what the sweep printed).  Tests that damage it work on a copy."""
    study = md_study([0.3, 0.4, 0.45, 0.5])
    out = tmp_path_factory.mktemp("md") / "s"
    err = io.StringIO()
    s = run_study(study, out, client=client, stream=err)
    return study, out, s, err.getvalue()


def copy_of(md_dir, tmp_path):
    import shutil

    return shutil.copytree(md_dir[1], tmp_path / "s")


def test_under_resolved_sweep_reports_under_resolved_everywhere(md_dir):
    """Its last line, study.csv, study.nc, each point file and log.jsonl all say under_resolved for the
    coarse grids (the old sweep said 'ok' for all, with run_status under_resolved beside it)."""
    study, out, s, text = md_dir
    assert (s["ok"], s["under_resolved"], s["failed"], s["pending"]) == (2, 2, 0, 0)
    assert text.splitlines()[-1].endswith("study.csv: 2 ok, 2 under_resolved, 0 failed")
    want = ["ok", "ok", "under_resolved", "under_resolved"]  # dx 0.3, 0.4, 0.45, 0.5
    rows = csv_rows(out / "study.csv")
    assert [r["status"] for r in rows] == want and [r["run_status"] for r in rows] == want
    assert all("under-resolved" in r["message"] for r in rows[2:])  # the run's own warning says why
    ds = xr.load_dataset(out / "study.nc")
    assert ds["status"].values.tolist() == want
    for p, st in zip(study.points, want):
        point = xr.load_dataset(out / "points" / f"{p.id}.nc")
        assert point.attrs["status"] == st and check_point(out / "points" / f"{p.id}.nc", p.id) == (st, None)
    log = [json.loads(x) for x in (out / "log.jsonl").read_text().splitlines()]
    by_id = {e["id"]: e["status"] for e in log if e["event"] == "point"}
    assert [by_id[p.id] for p in study.points] == want


# ---- point files and ids --------------------------------------------------------------------------

def _point_file(tmp_path, pid="abc", **kw):
    r = compute_point(dict(MD, **kw), pid)
    path = tmp_path / f"{pid}.nc"
    write_point(r["data"], path)
    return path, r["status"]


def test_check_point_finds_every_kind_of_bad_file(tmp_path):
    """A sound file gives its run status; an empty, truncated, other point's or altered file is named
    as such (no exception), and a file without a digest (an older format) is not trusted."""
    good, status = _point_file(tmp_path)
    assert status == "under_resolved"  # compute_point reports the run's own status (dx 0.5)
    assert check_point(good, "abc") == (status, None)
    empty = tmp_path / "empty.nc"
    empty.write_bytes(b"")
    assert "unreadable" in check_point(empty, "abc")[1]
    cut = tmp_path / "cut.nc"
    cut.write_bytes(good.read_bytes()[:2000])
    assert "unreadable" in check_point(cut, "abc")[1]
    assert check_point(good, "xyz") == (None, "holds point abc, not xyz")
    altered = tmp_path / "altered.nc"
    altered.write_bytes(good.read_bytes())
    with h5py.File(altered, "r+") as f:
        f["F"][0] = f["F"][0] + 1.0  # a changed number, the digest as it was
    assert "content digest" in check_point(altered, "abc")[1]
    attrs = tmp_path / "attrs.nc"
    attrs.write_bytes(good.read_bytes())
    with h5py.File(attrs, "r+") as f:
        f.attrs["status"] = "ok" if status != "ok" else "under_resolved"  # a status edited after the fact
    assert "content digest" in check_point(attrs, "abc")[1]
    old = tmp_path / "old.nc"
    old.write_bytes(good.read_bytes())
    with h5py.File(old, "r+") as f:
        del f.attrs["content_digest"]
    assert "no content digest" in check_point(old, "abc")[1]
    assert "unreadable" in check_point(tmp_path / "none.nc", "abc")[1]


def test_point_files_are_synced_before_and_after_the_rename(tmp_path, monkeypatch):
    """atomic_path (every point file, study.csv, ...): the temporary file's data are synced before the
    rename (so no OS crash leaves an empty file under the final name), the directory after it."""
    import os

    import tengsim.io

    seen = []
    real = tengsim.io._fsync

    def spy(path, flags=0):
        seen.append((Path(path), bool(flags & getattr(os, "O_DIRECTORY", 0)), (tmp_path / "p.nc").exists()))
        real(path, flags)

    monkeypatch.setattr(tengsim.io, "_fsync", spy)
    r = compute_point(dict(MD), "abc")
    write_point(r["data"], tmp_path / "p.nc")
    (f, f_dir, f_final), (d, d_dir, d_final) = seen
    assert f.name.startswith(".p.nc.") and not f_dir and not f_final  # the data, before the rename
    assert d == tmp_path and d_dir and d_final                         # the directory entry, after it
    assert check_point(tmp_path / "p.nc", "abc")[1] is None and not list(tmp_path.glob(".*.part"))


def test_point_id_covers_version_plugins_and_input_files(tmp_path, monkeypatch):
    """The id changes with the tengsim version, a plugin module's source and an input file's bytes, and
    only with them (the same table, code and data: the same id)."""
    import tengsim._version

    c = dict(MD)
    a = point_id(c)
    assert point_id(dict(MD)) == a and len(a) == 16
    monkeypatch.setattr(tengsim._version, "__version__", "9.9.9")
    assert point_id(c) != a
    monkeypatch.undo()
    assert point_id(c) == a
    name = "tengsim_trust_plugin_" + tmp_path.name.replace("-", "_")
    mod = tmp_path / f"{name}.py"
    mod.write_text("X = 1\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setenv("TENGSIM_PLUGINS", name)
    b = point_id(c)
    assert b != a and provenance(c)["plugins"] == {name: provenance(c)["plugins"][name]}
    mod.write_text("X = 22\n")
    assert point_id(c) != b
    monkeypatch.delenv("TENGSIM_PLUGINS")
    assert point_id(c) == a
    topo = tmp_path / "topo.txt"
    topo.write_text("0 1 0\n1 2 1\n0 1 0\n")
    t = {"shape": "topography", "file": str(topo), "physical_size": "2um"}
    d1 = point_id(t)
    topo.write_text("0 1 0\n1 3 1\n0 1 0\n")
    assert point_id(t) != d1 and set(provenance(t)["inputs"]) == {"file"}


def test_resume_refuses_points_of_other_code_or_input(tmp_path, monkeypatch):
    """Same study file, but the tengsim version or an input file changed: --resume names what changed
    and refuses (never mixing results of two codes or two files); an unchanged study resumes."""
    import tengsim._version

    topo = tmp_path / "topo.txt"
    topo.write_text("0 1 0\n1 2 1\n0 1 0\n")
    cfg = {"base": {"contact": {"shape": "topography", "file": str(topo), "physical_size": "2um",
                                "E_star": "1MPa", "W": "50mJ/m2", "tabor": 0.5}},
           "axes": {"contact.tabor": [0.5, 0.6]}}
    sd = StudyDir(tmp_path / "s")
    sd.root.mkdir()
    sd.spec.write_text(json.dumps(resolved_with_provenance(parse_study(cfg))))
    check_resume(parse_study(cfg), sd, resume=True)  # nothing changed
    monkeypatch.setattr(tengsim._version, "__version__", "9.9.9")
    with pytest.raises(TengsimError, match=r"2 point\(s\) .* computed by other code .*tengsim .* → 9\.9\.9"):
        check_resume(parse_study(cfg), sd, resume=True)
    monkeypatch.undo()
    topo.write_text("0 1 0\n1 3 1\n0 1 0\n")
    with pytest.raises(TengsimError, match="input file of key 'file' changed.*use another --out"):
        check_resume(parse_study(cfg), sd, resume=True)


def test_worker_with_other_code_does_not_compute(tmp_path):
    """A worker whose provenance differs from the client's (another tengsim, plugin or input file)
    returns a failed point naming the difference, without computing."""
    want = dict(provenance(MD), tengsim="0.0-client")
    r = compute_point(dict(MD), "p", expect=want)
    assert r["status"] == "failed" and r["data"] is None
    assert "other code or input" in r["message"] and "tengsim 0.0-client →" in r["message"]


# ---- resume that cannot be fooled ----------------------------------------------------------------

def test_bad_point_files_are_reported_and_recomputed_on_resume(md_dir, tmp_path, client):
    """The issue's emptied file, plus a file of another point under this name and a file whose numbers
    changed: --resume names each, keeps it aside as <id>.nc.bad and computes the point again; the
    untouched point is not recomputed.  --retry-failed then recomputes every point not finished 'ok'."""
    study = md_dir[0]
    out = copy_of(md_dir, tmp_path)
    sd = StudyDir(out)
    ids = [p.id for p in study.points]  # dx 0.3, 0.4 (ok), 0.45, 0.5 (under_resolved)
    sd.nc(ids[0]).write_bytes(b"")                           # emptied (an OS crash before the data reached disk)
    sd.nc(ids[1]).write_bytes(sd.nc(ids[3]).read_bytes())   # another point's file under this name
    with h5py.File(sd.nc(ids[2]), "r+") as f:               # changed numbers
        f["F"][1] = 0.0
    untouched = sd.nc(ids[3]).stat().st_mtime_ns
    err = io.StringIO()
    s = run_study(study, out, client=client, resume=True, stream=err)
    text = err.getvalue()
    assert sorted(s["computed"]) == sorted(ids[:3]) and (s["ok"], s["under_resolved"], s["failed"]) == (2, 2, 0)
    assert "is unreadable" in text and f"holds point {ids[3]}, not {ids[1]}" in text
    assert "does not match its content digest" in text and text.count("computing the point again") == 3
    assert "1 point(s) already in" in text and "3 to compute" in text
    for pid in ids[:3]:
        assert (sd.points / f"{pid}.nc.bad").exists() and check_point(sd.nc(pid), pid)[1] is None
    assert sd.nc(ids[3]).stat().st_mtime_ns == untouched
    log = [json.loads(x) for x in sd.log.read_text().splitlines()]
    assert sorted(e["id"] for e in log if e["event"] == "bad_point_file") == sorted(ids[:3])
    # --retry-failed: every point not finished ok (the two under-resolved ones), and only those
    s2 = run_study(study, out, client=client, resume=True, retry_failed=True, quiet=True)
    assert sorted(s2["computed"]) == sorted(ids[2:])


def test_dataset_never_trusts_a_bad_point_file(md_dir, tmp_path):
    """Assembling study.csv from a directory holding a damaged point file: a failed row naming the fault
    (never the file's numbers)."""
    from tengsim.study.dataset import build_study

    study = md_dir[0]
    sd = StudyDir(copy_of(md_dir, tmp_path))
    with h5py.File(sd.nc(study.points[0].id), "r+") as f:
        f["F"][1] = 0.0
    s = build_study(sd.root)
    assert s["failed"] == 1 and s["ok"] == 1
    row = next(r for r in csv_rows(sd.dataset_csv) if r["id"] == study.points[0].id)
    assert row["status"] == "failed" and "content digest" in row["message"] and row["pull_off_F"] == ""


# ---- optimize takes only ok points ----------------------------------------------------------------

OPT = {"base": {"contact": dict(MD)}, "axes": {"contact.dx": {"start": 0.3, "stop": 0.6}},
       "objective": {"maximize": "pull_off_F", "maxiter": 1, "popsize": 5, "seed": 3}}


def test_pick_optimum_takes_only_candidate_statuses():
    """The choice itself (no cluster): the best point whose status is a candidate; with none, the best
    of any, not feasible, with a message naming the statuses and the --accept that would take them;
    neighbours nearest first with their statuses."""
    from tengsim.study.optimize import FAILED, PENALTY, parse_accept, parse_objective, pick_optimum

    study = parse_study(OPT, source="opt")
    obj = parse_objective(study)
    from tengsim.study.sampling import point_at

    pts = [point_at(study, [x]) for x in (0.3, 0.35, 0.45, 0.5, 0.6)]
    pull = [-0.178, -0.168, -0.153, -0.153, -0.165]
    status = ["ok", "ok", "under_resolved", "under_resolved", "failed"]

    def scored(cands):
        return {p.id: ((-v if st in cands else PENALTY - v) if st != "failed" else FAILED, st, v)
                for p, v, st in zip(pts, pull, status)}

    best, r = pick_optimum(study, obj, pts, scored(("ok",)), ("ok",))
    assert best is pts[1] and r["feasible"] and r["status"] == "ok" and r["value"] == -0.168
    assert [q["status"] for q in r["neighbours"]] == ["ok", "under_resolved"]  # dx 0.3 and 0.45 nearest
    assert r["statuses"] == {"ok": 2, "under_resolved": 2, "failed": 1}
    cands = parse_accept(["under_resolved"])
    best, r = pick_optimum(study, obj, pts, scored(cands), cands)
    assert r["status"] == "under_resolved" and r["value"] == -0.153
    best, r = pick_optimum(study, obj, pts[2:], scored(("ok",)), ("ok",))
    assert not r["feasible"] and np.isnan(r["value"]) and r["status"] == "under_resolved"
    assert "no evaluated point is a candidate" in r["message"] and "--accept under_resolved" in r["message"]
    assert parse_accept("under_resolved,not_converged") == ("ok", "under_resolved", "not_converged")
    with pytest.raises(TengsimError, match="'okay' is not a run status"):
        parse_accept(["okay"])


@pytest.mark.slow
def test_optimize_takes_only_ok_points_unless_told(tmp_path, client):
    """Maximising the pull-off force over dx: the least tensile pull-off is a coarse grid's artefact
    (under_resolved); the optimum is the best ok point, its status and its neighbours' are reported.
    With accept=['under_resolved'] (resumed: the stored points are not computed again) the artefact wins."""
    from tengsim.study.optimize import optimize_study

    err = io.StringIO()
    r = optimize_study(parse_study(OPT, source="opt"), tmp_path / "o", client=client, stream=err)
    rows = csv_rows(tmp_path / "o" / "study.csv")
    ok = [float(x["pull_off_F"]) for x in rows if x["status"] == "ok"]
    other = [float(x["pull_off_F"]) for x in rows if x["status"] == "under_resolved"]
    assert ok and other and max(other) > max(ok)  # the artefact is there to be picked
    assert r["feasible"] and r["status"] == "ok" and r["value"] == pytest.approx(max(ok), rel=1e-12)
    assert r["accepted_statuses"] == ["ok"] and sum(r["statuses"].values()) == r["evaluations"] == len(rows)
    near = r["neighbours"]
    assert len(near) == 2 and all(q["status"] in SEVERITY for q in near)
    assert [q["distance"] for q in near] == sorted(q["distance"] for q in near)
    saved = json.loads((tmp_path / "o" / "optimum.json").read_text())
    assert saved["status"] == "ok" and saved["neighbours"] == json.loads(json.dumps(near))
    assert "(status ok)" in err.getvalue()
    files = {f.name: f.stat().st_mtime_ns for f in (tmp_path / "o" / "points").glob("*.nc")}
    r2 = optimize_study(parse_study(OPT, source="opt"), tmp_path / "o", client=client, resume=True,
                        accept=["under_resolved"], quiet=True)
    after = {f.name: f.stat().st_mtime_ns for f in (tmp_path / "o" / "points").glob("*.nc")}
    assert all(after[k] == v for k, v in files.items())  # (other values steer the search to other points too)
    rows = csv_rows(tmp_path / "o" / "study.csv")
    best = max(float(x["pull_off_F"]) for x in rows if x["status"] in ("ok", "under_resolved"))
    assert r2["status"] == "under_resolved" and r2["value"] == pytest.approx(best, rel=1e-12)


@pytest.mark.slow
def test_optimize_without_an_ok_point_says_so(tmp_path, client):
    """Every evaluated point under-resolved: not feasible, value NaN, and the message says which statuses
    were found and that --accept under_resolved would take them."""
    from tengsim.study.optimize import optimize_study

    cfg = dict(OPT, axes={"contact.dx": {"start": 0.45, "stop": 0.6}},
               objective=dict(OPT["objective"], popsize=2))
    r = optimize_study(parse_study(cfg, source="opt"), tmp_path / "o", client=client, quiet=True)
    assert not r["feasible"] and np.isnan(r["value"]) and r["status"] == "under_resolved"
    assert "no evaluated point is a candidate" in r["message"] and "--accept under_resolved" in r["message"]
    assert r["statuses"] == {"under_resolved": r["evaluations"]}


def test_cli_optimize_bad_accept_value(tmp_path, capsys):
    f = tmp_path / "o.toml"
    f.write_text('[base.contact]\nshape = "sphere"\nradius = 1.0\ncell = 4.0\n[axes]\n'
                 '"contact.dx" = { start = 0.3, stop = 0.6 }\n[objective]\nmaximize = "pull_off_F"\n')
    rc = main(["optimize", str(f), "--out", str(tmp_path / "o"), "--accept", "under_resolvd"])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and len(err.splitlines()) == 1 and "'under_resolvd'" in err and "under_resolved" in err
    assert not (tmp_path / "o").exists()


# ---- every registered shape through a study ------------------------------------------------------

MATERIAL = {"E_star": "0.59MPa", "W": "54mJ/m2", "boundary": "periodic", "dx": "0.25um", "d_min": -1.0,
            "d_max": 3.0, "d_step": 0.5}
PHYSICAL = {
    "pyramid": {"pitch": "2um", "base": "1um", "height": "0.7um"},
    "sphere": {"radius": "2um", "pitch": "2um"},
    "cone": {"slope": 1.0, "pitch": "2um", "height": "0.5um"},
    "hemisphere": {"radius": "0.5um", "pitch": "2um"},
    "flat_punch": {"radius": "0.5um", "pitch": "2um"},
    "cube": {"half_width": "0.5um", "height": "0.5um", "pitch": "2um"},
    "line": {"half_width": "0.5um", "height": "0.5um", "pitch": "2um"},
    "sinusoid": {"wavelength": "2um", "amplitude": "0.2um"},
    "rough": {"cell": "2um", "rms_height": "0.1um", "short_cutoff": "0.6um"},
    "topography": {"file": "TOPO", "physical_size": "2um", "unit": "um"},
    # the crash: group A pyramids, K = 2, physical units
    "array": {"pattern": "pyramid", "K": 2, "pitch": "2um", "base": "1um", "height": "0.7um"},
}
"""A physical [contact] table of each registered shape (a new shape needs one here)."""
SLOW_SHAPES = {"topography", "cone", "hemisphere", "flat_punch", "cube", "sinusoid"}
"""Shapes run only in the slow suite (each ~1 s; the topography imports SurfaceTopography, ~2 s): the
default suite keeps a square, a disc, a line and the array."""
FILLED = ("pull_off_F", "pull_off_Pa", "area_fraction_0", "S_V_per_kPa", "S_to_Pa", "V_sat",
          "hysteresis", "hysteresis_J_m2", "V_OC_1kPa", "V_OC_10kPa", "V_OC_100kPa")
"""Columns every shape fills in a physical study that reaches 100 kPa."""
MAY_BE_EMPTY = {
    "jump_in_D": "no jump-in on the approach (observe: NaN when there is none)",
    "jump_out_D": "no jump-out on the retraction",
    "transition_D": "no known full-contact length for the shape (observe.full_length)",
    "adhesive_full_contact": "no known full-contact length for the shape (observe.full_length)",
    # the sensor's numbers (tengsim.device.sensor), each NaN with its reason there
    "knee_Pa": "one line fits V_OC(P) below the saturation (R2 >= 0.99): no knee",
    "S_above_knee_V_per_kPa": "no knee",
    "P_sat_Pa": "V_OC does not level off within the range",
    "S_rel_per_kPa": "V_OC is 0 at the lowest pressure: no baseline V0",
    "linear_range_Pa": "no line from the lowest pressure fits with R2 >= 0.99 (the reason in the message)",
    "linear_R2": "as linear_range_Pa",
}
"""Columns that may be empty, each with its documented reason."""


def _shape_params():
    return [pytest.param(n, marks=pytest.mark.slow) if n in SLOW_SHAPES else n for n in plugins.SHAPES.names()]


@pytest.mark.parametrize("shape", _shape_params())
def test_every_shape_runs_a_physical_study_with_device_observables(shape, tmp_path, client):
    """A 2-point study of each registered shape in physical units: no point fails, study.csv has the
    device observables (V_OC at 1, 10, 100 kPa, sensitivity, saturation) filled; an empty cell only in
    a column with a documented reason."""
    assert shape in PHYSICAL, f"shape {shape!r} has no physical table in this test: add one to PHYSICAL"
    table = dict(PHYSICAL[shape])
    if table.get("file") == "TOPO":
        x = np.linspace(-1, 1, 16)
        X, Y = np.meshgrid(x, x, indexing="ij")
        np.savetxt(tmp_path / "topo.txt", 0.5 * np.exp(-(X**2 + Y**2) / 0.2))
        table["file"] = str(tmp_path / "topo.txt")
    study = parse_study({"base": {"contact": {"shape": shape, **MATERIAL, **table}},
                         "axes": {"contact.tabor": [0.5, 0.6]}}, source=shape)
    s = run_study(study, tmp_path / "s", client=client, quiet=True)
    assert s["failed"] == 0 and sum(s[k] for k in SEVERITY) == 2
    rows = csv_rows(tmp_path / "s" / "study.csv")
    assert len(rows) == 2
    for r in rows:
        assert r["status"] in SEVERITY and r["status"] == r["run_status"]
        empty = [k for k in FILLED if r[k] == ""]
        assert not empty, f"{shape}: empty {empty}; message: {r['message']}"
        unexplained = [k for k, v in r.items() if v == "" and k not in MAY_BE_EMPTY and k != "message"]
        assert not unexplained, f"{shape}: empty {unexplained}"
        v = [float(r[f"V_OC_{p}"]) for p in ("1kPa", "10kPa", "100kPa")]
        assert all(0 < x <= 5.84e-6 * 400e-6 / (2.40 * 8.8541878128e-12) * (1 + 1e-12) for x in v)


def test_array_of_identical_cells_has_its_patterns_observables(tmp_path, client):
    """An array of K × K identical pyramids (no scatter) has the pressure observables of one pyramid
    (A/S per cell; pull-off per area), and with the array_area observer A/S is the sum over its cells."""
    base = {**MATERIAL, **PHYSICAL["pyramid"], "tabor": 0.5}
    study = parse_study({"base": {"contact": base},
                         "axes": {"contact.shape": ["pyramid", "array"], "contact.observers": ["", "array_area"]}},
                        source="arr")
    run_study(study, tmp_path / "s", client=client, quiet=True)
    ds = xr.load_dataset(tmp_path / "s" / "study.nc")
    pyr = ds.sel({"contact_shape": "pyramid", "contact_observers": ""})
    arr = ds.sel({"contact_shape": "array", "contact_observers": ""})
    obs = ds.sel({"contact_shape": "array", "contact_observers": "array_area"})
    assert float(arr["pull_off_Pa"]) == pytest.approx(float(pyr["pull_off_Pa"]), rel=1e-6)
    # the 2-D charged area of identical cells is the pattern's, whether or not the array_area observer runs
    np.testing.assert_allclose(arr["V_OC_at"].values, pyr["V_OC_at"].values, rtol=0.02)
    np.testing.assert_allclose(obs["V_OC_at"].values, pyr["V_OC_at"].values, rtol=0.02)
    assert float(arr["V_OC_at"].isel(pressure_named=0)) > 0  # 1 kPa
    assert "paper's definition" not in str(arr["message"].values)  # the charged area, not the Λc fallback
