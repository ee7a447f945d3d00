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
:class:`PointRunner` is that machinery (client, warm-up, compute a batch, close), shared by
:func:`run_study` and :func:`tengsim.study.optimize.optimize_study`.
"""
from __future__ import annotations

import json
import os
import socket
import sys
import time
from pathlib import Path

from tengsim.errors import ConfigValueError, TengsimError
from tengsim.progress import Progress
from tengsim.study.layout import StudyDir

WORKER_ENV = {"OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1",
              "TENGSIM_THREADS": "1", "TENGSIM_FFT_WORKERS": "1"}
"""Environment of every worker: one thread per process (the parallelism is across points)."""

LOCAL_CLUSTER_CONFIG = {
    "distributed.admin.tick.interval": "1s",  # event-loop watchdog: 20 ms by default
    "distributed.admin.system-monitor.interval": "2s",
    "distributed.admin.system-monitor.gil.enabled": False,
    "distributed.admin.system-monitor.disk": False,
    "distributed.worker.profile.enabled": False,  # the 10 ms stack sampler of every running task
    "distributed.worker.memory.monitor-interval": "1s",
    # a worker holds only the point it runs (default 1.1: a second one queued per thread), so a worker
    # that dies (out of memory, killed) takes no other point down with it; a point lasts seconds, the
    # hand-over milliseconds
    "distributed.scheduler.worker-saturation": 1.0,
}
"""Dask settings of the LocalCluster a sweep starts.  With the defaults an idle 2-worker cluster burns
about 3 CPU-seconds per 20 s (15 % of a core) in monitors, taken from the points it runs on a
2-core machine; with these, 0.4 s (benchmarks/results/sweep_scaling.md).  Read when the cluster
starts; a cluster behind ``--scheduler`` keeps its own configuration."""


# ---- the task that runs on a worker --------------------------------------------------------------

def _worker_setup(plugins: str = "") -> None:
    """Pin threads and import the client's plugin modules (``TENGSIM_PLUGINS``) on a worker."""
    for k, v in WORKER_ENV.items():  # for workers of an external scheduler (LocalCluster sets them already)
        os.environ.setdefault(k, v)
    if plugins and not os.environ.get("TENGSIM_PLUGINS"):
        os.environ["TENGSIM_PLUGINS"] = plugins
    from tengsim.plugins import load_plugins

    load_plugins()


def compute_point(contact: dict, pid: str, plugins: str = "", expect: dict | None = None) -> dict:
    """Run one point (exactly what ``tengsim run`` runs for the same [contact] table) on a worker.

    ``plugins``: the client's ``TENGSIM_PLUGINS`` (modules a worker imports before the point, so a
    study of user shapes or laws runs on workers that only have the modules installed).  ``expect``:
    the client's :func:`tengsim.study.points.provenance` of the point (what its id covers); a worker
    that sees another (another tengsim, plugin source or input file) does not compute it: a failed
    point naming the difference.
    Never raises: returns {'status': the run's status (tengsim.status: 'ok', 'under_resolved',
    'out_of_law_range', 'not_converged') or 'failed', 'message', 'data' (the result's xarray Dataset
    with its attrs; the client writes it), 'seconds', 'host', 'pid', 'started', 'finished'}.
    """
    import traceback

    from tengsim._version import __version__
    from tengsim.study.points import provenance, provenance_difference

    t0 = time.time()
    c0 = time.perf_counter()
    info = {"host": socket.gethostname(), "pid": os.getpid(), "started": t0}
    try:
        _worker_setup(plugins)
        prov = provenance(contact)
        if expect is not None and prov != expect:
            raise TengsimError(f"the worker on {info['host']} would compute this point with other code or "
                               f"input than the client's ({provenance_difference(expect, prov)}); not computed")
        from tengsim.run.resolve import run_contact  # resolve = 'auto': refined until converged

        c0 = time.perf_counter()
        res = run_contact(dict(contact))
    except Exception as exc:  # noqa: BLE001 - recorded as a failed point, the others go on
        msg = str(exc) if isinstance(exc, TengsimError) else \
            f"{type(exc).__name__}: {exc}\n{traceback.format_exc(limit=-3)}"
        return {**info, "status": "failed", "message": msg.strip(), "seconds": time.perf_counter() - c0,
                "finished": time.time(), "data": None}
    seconds = time.perf_counter() - c0
    status = res.status  # the run's own status, the one the point reports everywhere
    message = str(res.params.get("warning", ""))
    ds = res.to_dataset()
    ds.attrs.update({"point_id": pid, "status": status, "message": message, "compute_seconds": seconds,
                     "tengsim_version": __version__, "host": info["host"], "worker_pid": info["pid"],
                     "started_unix": t0, "finished_unix": time.time(),
                     "point_contact": json.dumps(contact, sort_keys=True, default=str),
                     "point_provenance": json.dumps(prov, sort_keys=True)})
    return {**info, "status": status, "message": message, "seconds": seconds, "finished": time.time(),
            "data": ds}


def warm_up(plugins: str = "") -> int:
    """Import the solver stack (and the client's plugins) on a worker, before the first point."""
    try:
        _worker_setup(plugins)
    except TengsimError:
        pass  # the points report it, each as a failed point with the message
    import tengsim.run.plan  # noqa: F401
    import tengsim.run.simulate  # noqa: F401
    import xarray  # noqa: F401

    return os.getpid()


# ---- validation ---------------------------------------------------------------------------------

def estimated_cost(plan) -> float:
    """Relative cost of a planned point: pixels × log2(pixels) (one convolution) × path rows.

    Only orders the submissions (the longest first, so that a short point, not a long one, ends a
    sweep); an estimate that fails gives 1.  The path rows count one per step of each branch."""
    import math

    try:
        g = plan.shape.grid(plan.dx)
        npix = g.nx * g.ny * (1 if plan.boundary == "periodic" else 4)
        spec = plan.path
        if hasattr(spec, "f_step"):
            rows = 2 * (spec.f_max - spec.f_min) / spec.f_step
        else:
            rows = 2 * (spec.d_max - spec.d_min) / spec.d_step
        return float(npix * math.log2(max(npix, 2)) * max(rows, 1.0))
    except Exception:  # noqa: BLE001 - an estimate only
        return 1.0


def validate(study) -> tuple[dict, dict]:
    """Plan every distinct point (no solving).  Returns ({id: contact table} of the valid points,
    {id: message} of the invalid ones), the valid ones longest first (:func:`estimated_cost`).
    An error that every point shares is an error in the study file: raised as one TengsimError
    before anything is written."""
    from tengsim.run.plan import plan_contact
    from tengsim.study.observe import device_values

    valid, invalid, first, cost = {}, {}, None, {}
    for p in study.points:
        device_values(p.tables["device"])  # a bad device value is a study error
        pid = p.id
        if pid in valid or pid in invalid:
            continue
        try:
            plan = plan_contact(dict(p.contact))
        except ConfigValueError as exc:  # a malformed value in the file: the whole study is refused
            where = ", ".join(f"{k} = {v!r}" for k, v in p.axes.items())
            raise TengsimError(f"{study.source or 'study'}: {exc}" + (f" (at {where})" if where else "")) from None
        except TengsimError as exc:
            invalid[pid] = str(exc)
            if first is None:
                first = (p, str(exc))
            continue
        valid[pid] = p.contact
        cost[pid] = estimated_cost(plan)
    if not valid:
        if first is None:
            raise TengsimError(f"{study.source or 'study'}: no points")
        p, msg = first
        where = ", ".join(f"{k} = {v!r}" for k, v in p.axes.items())
        raise TengsimError(f"{study.source or 'study'}: {msg}" + (f" (at {where})" if where and len(invalid) == 1
                                                                  else ""))
    order = sorted(valid, key=lambda pid: -cost[pid])  # stable: equal estimates keep the study's order
    return {pid: valid[pid] for pid in order}, invalid


# ---- directory state (the layout: tengsim.study.layout) --------------------------------------------

def check_resume(study, sd: StudyDir, resume: bool) -> None:
    """Refuse to mix two studies in one directory; on --resume the new study may only add points, and
    its points must be computed by the same code from the same input as the stored ones (the same ids:
    :mod:`tengsim.study.points`)."""
    if not sd.spec.exists():
        if sd.points.is_dir() and any(sd.points.iterdir()):
            raise TengsimError(f"{sd.root} holds points but no study.json; use another --out")
        return
    if not resume:
        raise TengsimError(f"{sd.root} already holds a study; add --resume to continue it, or use another --out")
    try:
        old = json.loads(sd.spec.read_text())
        old_ids = {p["id"] for p in old["points"]}
        old_axes = {json.dumps(p["axes"], sort_keys=True) for p in old["points"]}
    except (OSError, ValueError, KeyError, TypeError) as exc:
        raise TengsimError(f"cannot read {sd.spec}: {exc}") from None
    new_ids = {p.id for p in study.points}
    new_axes = {json.dumps(p.axes, sort_keys=True) for p in study.points}
    lost = old_ids - new_ids
    if lost and old_axes <= new_axes:
        # the same axis values give other ids: the table changed (the base), or what else the id covers
        _check_same_code(old["points"], lost, study, sd)
    if lost or not old_axes <= new_axes:
        n = len(lost) or len(old_axes - new_axes)
        raise TengsimError(f"the study file changed: {n} point(s) of {sd.spec} are not in it any more "
                           "(a resumed study may only add points); use another --out")


def _check_same_code(old_points, lost, study, sd) -> None:
    """Stored points whose table is unchanged but whose id is not: computed by other code or from other
    input.  One TengsimError saying what changed (a resumed study never mixes their results)."""
    from tengsim.study.points import provenance, provenance_difference
    from tengsim.study.spec import canonical

    new = {json.dumps(p.axes, sort_keys=True): p for p in study.points}
    n, why = 0, ""
    for o in old_points:
        if o["id"] not in lost:
            continue
        p = new.get(json.dumps(o["axes"], sort_keys=True))
        if p is None or canonical(o["tables"]["contact"]) != canonical(p.contact):
            return  # the table itself changed: the study file changed
        n += 1
        if not why:
            why = (provenance_difference(o["provenance"], provenance(p.contact)) if o.get("provenance")
                   else "written by an older tengsim, before point ids covered the code and input files")
    raise TengsimError(f"{n} point(s) in {sd.points} were computed by other code or from other input "
                       f"({why or 'their ids differ'}); a resumed study never mixes their results with new "
                       "ones: use another --out")


# ---- progress -----------------------------------------------------------------------------------

class SweepProgress(Progress):
    """A sweep's :class:`tengsim.progress.Progress`: done/total, failed, rate and ETA, updated per point.

    Only the text is the sweep's; stream, terminal detection, writing and :meth:`close` are Progress's:
    one updating line on a TTY, a plain line per finished point otherwise."""

    def __init__(self, total, done=0, failed=0, quiet=False, stream=None):
        super().__init__(quiet=quiet, stream=stream)
        self.total, self.done, self.failed = total, done, failed
        self.start_done = done + failed

    def text(self) -> str:
        """``sweep: N/total points (k failed), R points/h, ETA h:mm:ss``."""
        n = self.done + self.failed - self.start_done
        dt = time.perf_counter() - self.t0
        rate = n / dt * 3600 if dt > 0 and n else 0.0
        left = self.total - self.done - self.failed
        eta = _hms(left / rate * 3600) if rate > 0 else "?"
        return (f"sweep: {self.done + self.failed}/{self.total} points ({self.failed} failed), "
                f"{rate:.4g} points/h, ETA {eta}")

    def update(self, status=None):
        """Count one finished point (``status``: 'failed' or another) and report; ``None`` only reports."""
        if status == "failed":
            self.failed += 1
        elif status is not None:
            self.done += 1
        if self.quiet:
            return
        if self.tty:
            self._write(f"\r{self.text():<78}")
            self.active = True
            if self.done + self.failed >= self.total:
                self.close()
        else:
            self._write(self.text() + "\n")


def _hms(s):
    s = int(round(s))
    return f"{s // 3600}:{s // 60 % 60:02d}:{s % 60:02d}"


# ---- the client ---------------------------------------------------------------------------------

CONNECT_TIMEOUT_S = 3.0
"""How long :func:`connect` tries to reach a ``--scheduler`` address before it gives up (seconds)."""


MAX_HANDSHAKE = 1 << 20
"""The largest first message (bytes) a Dask scheduler's handshake may announce: its own is a few hundred."""


def probe_scheduler(address: str, timeout: float) -> None:
    """Refuse a ``tcp://host:port`` (or ``host:port``) address where no Dask scheduler answers, within
    ``timeout`` seconds: a Dask scheduler greets a new connection at once with a short handshake (an
    8-byte little-endian frame length, then the frame); a server that says nothing (HTTP, SSH waiting
    for its client) or announces an absurd length is named and refused, before dask waits on it or
    allocates what it announces.  Other schemes (tls://, inproc://, ...) are left to dask."""
    import socket
    import struct
    from urllib.parse import urlsplit

    from tengsim.errors import shown

    text = str(address)
    if "://" in text and not text.startswith("tcp://"):
        return
    try:
        parts = urlsplit(text if "://" in text else f"tcp://{text}")
        host, port = parts.hostname, parts.port
    except ValueError:
        raise TengsimError(f"--scheduler {shown(text)} is not an address host:port") from None
    if not host or port is None:
        raise TengsimError(f"--scheduler {shown(text)} is not an address tcp://host:port")
    try:
        with socket.create_connection((host, port), timeout=timeout) as sock:
            sock.settimeout(timeout)
            head = b""
            while len(head) < 8:
                chunk = sock.recv(8 - len(head))
                if not chunk:
                    raise TengsimError(f"cannot reach the dask scheduler at {shown(text)}: the server closed the "
                                       "connection without a Dask greeting")
                head += chunk
    except TengsimError:
        raise
    except socket.timeout:
        raise TengsimError(f"cannot reach the dask scheduler at {shown(text)}: the server there sent no Dask "
                           f"greeting within {timeout:g} s (is it a Dask scheduler?)") from None
    except OSError as exc:
        raise TengsimError(f"cannot reach the dask scheduler at {shown(text)}: {exc.strerror or exc}") from None
    (length,) = struct.unpack("<Q", head)
    if not 0 < length <= MAX_HANDSHAKE:
        raise TengsimError(f"cannot reach the dask scheduler at {shown(text)}: the server there is not a Dask "
                           f"scheduler (its first message announces {length} bytes)")


def connect(workers=None, scheduler=None, timeout: float | None = None):
    """A dask Client: on ``scheduler`` (an address) or on a new LocalCluster; returns (client, cluster).

    An unreachable scheduler is a TengsimError naming the address after ``timeout`` seconds (default
    :data:`CONNECT_TIMEOUT_S`)."""
    timeout = CONNECT_TIMEOUT_S if timeout is None else timeout
    if workers is not None and scheduler is not None:
        raise TengsimError("give either --workers or --scheduler, not both")
    try:
        from dask.distributed import Client, LocalCluster
    except ImportError:  # pragma: no cover - a dependency
        raise TengsimError("tengsim sweep needs dask[distributed]: pip install 'dask[distributed]'") from None
    if scheduler is not None:
        probe_scheduler(scheduler, timeout)
        try:
            client = Client(scheduler, timeout=f"{timeout}s")
        except (OSError, TimeoutError, ValueError) as exc:
            raise TengsimError(f"cannot reach the dask scheduler at {scheduler!r}: {exc}") from None
        return client, None
    if workers is not None and (not isinstance(workers, int) or workers < 1):
        raise TengsimError(f"--workers must be a positive integer, got {workers!r}")
    import logging
    import signal
    import threading

    import dask

    n = workers or os.cpu_count() or 1
    # the worker processes start with SIGINT ignored: a terminal's Ctrl-C reaches the whole process
    # group, and the client alone answers it (one line, the cluster closed), not a traceback per worker
    old = signal.signal(signal.SIGINT, signal.SIG_IGN) if threading.current_thread() is threading.main_thread() \
        else None
    try:
        with dask.config.set(LOCAL_CLUSTER_CONFIG):
            cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, env=dict(WORKER_ENV),
                                   dashboard_address=":0", silence_logs=logging.ERROR)
    finally:
        if old is not None:
            signal.signal(signal.SIGINT, old)
    return Client(cluster), cluster


class PointRunner:
    """Computes planned points into a study directory on Dask: the one runner of ``tengsim sweep`` and
    ``tengsim optimize``.

    Used as a context manager: entering connects (a new LocalCluster of ``workers`` processes, or the
    scheduler at ``scheduler``) unless ``client`` (an existing dask Client) is given; leaving closes
    only what it started.  :meth:`compute` submits a batch of points and writes each result the moment
    it arrives (``DIR/points/<id>.nc`` or ``<id>.failed.json``, one ``log.jsonl`` line), atomically.
    The workers import the client's ``TENGSIM_PLUGINS`` (read on entering).
    """

    def __init__(self, sd: StudyDir, *, workers=None, scheduler=None, client=None):
        self.sd = sd if isinstance(sd, StudyDir) else StudyDir(Path(sd))
        self.workers, self.scheduler = workers, scheduler
        self.client = client
        self._own = None
        self.plugins = ""

    def __enter__(self) -> "PointRunner":
        if self.client is None:
            client, cluster = connect(self.workers, self.scheduler)
            self.client, self._own = client, (client, cluster)
        self.plugins = os.environ.get("TENGSIM_PLUGINS", "")
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def close(self) -> None:
        """Close the client and cluster this runner started (a given client stays open)."""
        if self._own is not None:
            own, self._own = self._own, None
            _close(*own)
            self.client = None

    @property
    def n_workers(self) -> int:
        return len(self.client.scheduler_info().get("workers", {}))

    def warm_up(self) -> None:
        """Import the solver stack and the plugins on every worker, before the first point."""
        self.client.run(warm_up, self.plugins)

    def compute(self, contacts: dict, todo, progress: SweepProgress | None = None) -> list:
        """Compute the points ``todo`` (ids; submitted in this order, first with the highest priority),
        ``contacts`` mapping each id to its [contact] table; write each as it finishes and report it to
        ``progress``.  Returns the ids computed (in completion order).  An interrupt cancels the rest."""
        todo = list(todo)
        progress = progress if progress is not None else SweepProgress(len(todo), quiet=True)
        return _compute(self.client, contacts, todo, self.sd, progress, self.plugins)


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
    valid, invalid = validate(study)
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
        redo = {pid for pid, st in statuses.items() if st != "ok"} if retry_failed else set()
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
        _append_log(sd, {"event": "start", "time": time.time(), "todo": todo})
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
                     if s in ("ok", "failed") or summary.get(s, 0))


def resolved_with_provenance(study) -> dict:
    """:meth:`Study.resolved` with each point's provenance (what its id covers besides its table), so
    that a refused resume can say what changed."""
    from tengsim.study.points import provenance

    spec = study.resolved()
    for p in spec["points"]:
        p["provenance"] = provenance(p["tables"]["contact"])
    return spec


def verify_points(sd: StudyDir, ids, say=None, who: str = "sweep") -> dict:
    """Open and check every point file of ``ids`` under ``sd`` (:func:`tengsim.study.points.check_point`).
    Returns {id: run status} of the sound ones.  A bad one (unreadable, empty, another point's, not
    matching its content digest) is reported through ``say``, logged, and moved aside to
    ``points/<id>.nc.bad`` (kept for inspection), so that it is computed again."""
    from tengsim.study.points import check_point

    out = {}
    for pid in sorted(sd.done() & set(ids)):
        status, why = check_point(sd.nc(pid), pid)
        if status is not None:
            out[pid] = status
            continue
        bad = sd.points / f"{pid}.nc.bad"
        os.replace(sd.nc(pid), bad)
        if say is not None:
            say(f"{who}: point file {sd.nc(pid)} {why}: moved to {bad.name}, computing the point again")
        _append_log(sd, {"event": "bad_point_file", "id": pid, "problem": why, "moved_to": bad.name,
                         "time": time.time()})
    return out


def _contact_of(study, pid):
    for p in study.points:
        if p.id == pid:
            return p.contact
    return None


def _append_log(sd, entry):
    with open(sd.log, "a") as fh:
        fh.write(json.dumps(entry, default=str) + "\n")
        fh.flush()


def _compute(client, valid, todo, sd, bar, plugins="") -> list:
    """Submit ``todo``; write each result as it completes.  Returns the ids computed here."""
    import dask
    from dask.distributed import as_completed

    from tengsim.io import interrupts_held, write_json
    from tengsim.study.points import provenance, write_point

    futures = {client.submit(compute_point, valid[pid], pid, plugins, provenance(valid[pid]),
                             key=f"tengsim-point-{pid}", pure=False, priority=len(todo) - k): pid
               for k, pid in enumerate(todo)}  # todo is longest first (validate); keep that order
    computed = []
    try:
        for fut in as_completed(list(futures)):
            pid = futures[fut]
            try:
                r = fut.result()
            except Exception as exc:  # noqa: BLE001 - a worker died (KilledWorker) or the task was lost
                r = {"status": "failed", "message": f"{type(exc).__name__}: {exc}", "seconds": None,
                     "data": None}
            with interrupts_held():  # a point's files and log line are written whole
                if r["status"] == "failed":
                    write_json(sd.failed(pid), {"id": pid, "status": "failed", "stage": "compute",
                                                "message": r["message"], "contact": valid[pid],
                                                **{k: r.get(k) for k in ("seconds", "host", "pid")}})
                else:
                    with dask.config.set(scheduler="synchronous"):  # local file: no distributed write lock
                        write_point(r["data"], sd.nc(pid))
                    try:
                        sd.failed(pid).unlink()
                    except FileNotFoundError:
                        pass
                computed.append(pid)
                _append_log(sd, {"event": "point", "id": pid, "status": r["status"],
                                 "seconds": r.get("seconds"), "host": r.get("host"),
                                 "worker_pid": r.get("pid"), "time": time.time()})
            bar.update(r["status"])
            fut.release()
    except BaseException:
        client.cancel(list(futures))
        raise
    return computed


def _close(client, cluster):
    import contextlib

    with contextlib.suppress(Exception):
        client.close(timeout=5)
    if cluster is not None:
        with contextlib.suppress(Exception):
            cluster.close(timeout=5)
