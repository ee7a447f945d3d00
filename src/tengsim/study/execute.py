"""Running a study on Dask: validate every point, submit, write each finished point atomically, resume.

The files of a study directory are named by :class:`tengsim.study.layout.StudyDir`.

Points are computed on a ``dask.distributed`` client: a LocalCluster (one single-threaded worker
process per core, BLAS/FFT threads pinned to 1) or an existing scheduler.  The client writes each
result the moment it arrives (``as_completed``), through a temporary file, fsync and an atomic rename
(:func:`tengsim.study.points.write_point`), so a sweep killed at any moment (the OS included) keeps
every finished point and never holds a half-written one.  A point's status is its run's
(tengsim.status) or 'failed'.  On --resume every point file is opened and checked (its id, its content
digest) before it is trusted; a bad one is reported, kept aside and computed again.  A point's id
covers its code and input files (:mod:`tengsim.study.points`), so a resume never mixes results of two
versions, plugin sources or input files.
:class:`~tengsim.study.runner.PointRunner` is that machinery (client, warm-up, compute a batch, close),
shared by :func:`run_study` and :func:`tengsim.study.optimize.optimize_study`.

Here the sweep itself (:func:`run_study`); apart: the check before anything runs
(:mod:`~tengsim.study.validate`), the directory's state and resume (:mod:`~tengsim.study.resume`), the
worker's task (:mod:`~tengsim.study.worker`), the Dask client (:mod:`~tengsim.study.runner`) and the
progress line (:mod:`~tengsim.study.progress`).
"""
from __future__ import annotations

import sys
import time
from pathlib import Path

from tengsim.errors import TengsimError
from tengsim.study.layout import StudyDir
from tengsim.study.progress import SweepProgress
from tengsim.study.resume import append_log, check_resume, resolved_with_provenance, verify_points
from tengsim.study.runner import PointRunner
from tengsim.study.validate import validate
from tengsim.status.levels import Status


def run_study(study, out, *, workers=None, scheduler=None, client=None, resume=False, retry_failed=False,
              quiet=False, stream=None) -> dict:
    """Validate, then compute the study's missing points on Dask and assemble DIR/study.nc and study.csv.

    ``client`` (an existing dask Client) overrides ``workers``/``scheduler``.  Returns a summary dict.
    Nothing is written if validation, the directory check or the connection fails.
    """
    from tengsim.io import write_json
    from tengsim.plugins import load_plugins

    load_plugins()  # the client plans the points with the same registries as its workers
    stream = stream or sys.stderr
    say = (lambda m: None) if quiet else (lambda m: print(m, file=stream, flush=True))
    if workers is not None and scheduler is not None:
        raise TengsimError("give either --workers or --scheduler, not both")
    valid, invalid = validate(study, local=scheduler is None and client is None)
    sd = StudyDir(Path(out))
    if sd.root.exists() and not sd.root.is_dir():
        raise TengsimError(f"--out {sd.root} is a file, not a directory")
    check_resume(study, sd, resume)
    with PointRunner(sd, workers=workers, scheduler=scheduler, client=client) as runner, sd.lock("sweep"):
        from tengsim.io import check_writable

        check_resume(study, sd, resume)  # again, now that no other sweep can write here
        check_writable(sd.spec)
        say(f"sweep: {len(study.points)} points ({len(valid) + len(invalid)} distinct computations) on "
            f"{runner.n_workers} worker(s); dashboard {runner.client.dashboard_link}")
        sd.points.mkdir(parents=True, exist_ok=True)
        if sd.drop_partial():
            say("sweep: removed the temporary files of point writes a kill interrupted")
        write_json(sd.spec, resolved_with_provenance(study))
        statuses = verify_points(sd, set(valid) | set(invalid), say, "sweep")
        done, failures = set(statuses), sd.failures()
        for pid, msg in invalid.items():
            if pid not in done and (pid not in failures or retry_failed):
                write_json(sd.failed(pid), {"id": pid, "status": "failed", "stage": "validation",
                                            "message": msg, "contact": _contact_of(study, pid)})
        failures = sd.failures()
        # --retry-failed: every point not finished 'ok' (failed, or finished with another status)
        redo = {pid for pid, st in statuses.items() if st != Status.OK} if retry_failed else set()
        todo = [pid for pid in valid if (pid not in done or pid in redo) and (pid not in failures or retry_failed)]
        n_total = len(valid) + len(invalid)
        n_failed = len((failures - done) - set(todo))
        bar = SweepProgress(n_total, len((done - set(todo)) & (set(valid) | set(invalid))), n_failed, quiet,
                            stream)
        if len(todo) < len(valid):
            say(f"sweep: {len(valid) - len(todo)} point(s) already in {sd.points}, {len(todo)} to compute")
        if redo & set(todo):
            say(f"sweep: --retry-failed: computing again {len(redo & set(todo))} finished point(s) whose status "
                "is not ok")
        append_log(sd, {"event": "start", "time": time.time(), "todo": todo})
        if todo:
            runner.warm_up()
        t0, t0_unix = time.perf_counter(), time.time()
        computed = runner.compute(valid, todo, bar)
        t_compute = time.perf_counter() - t0
        bar.close()
    from tengsim.study.dataset import build_study

    import dask

    t0 = time.perf_counter()
    with dask.config.set(scheduler="synchronous"), sd.lock("sweep"):
        summary = build_study(sd.root)
    summary.update(computed=computed, compute_phase_s=t_compute, compute_phase_start_unix=t0_unix,
                   assemble_s=time.perf_counter() - t0)
    say(f"sweep: wrote {sd.dataset_nc} and {sd.dataset_csv}: {status_counts(summary)}")
    return summary


def status_counts(summary: dict) -> str:
    """'3 ok, 2 under_resolved, 0 failed': the count of every status (ok and failed always, the others
    when some point has them), as a sweep's last line reports them."""
    from tengsim.study.dataset import STATUSES

    return ", ".join(f"{summary.get(s, 0)} {s}" for s in STATUSES
                     if s in (Status.OK, "failed") or summary.get(s, 0))


def _contact_of(study, pid):
    for p in study.points:
        if p.id == pid:
            return p.contact
    return None
