"""Points computed on Dask: the client (a LocalCluster of single-threaded worker processes, or an
existing scheduler, probed first) and :class:`PointRunner`, which submits a batch of points and writes
each result the moment it arrives (through a temporary file, fsync and an atomic rename), shared by
``tengsim sweep`` and ``tengsim optimize``."""
from __future__ import annotations

import os
import time
from pathlib import Path

from tengsim.errors import TengsimError
from tengsim.study.layout import StudyDir
from tengsim.study.progress import SweepProgress
from tengsim.study.resume import append_log
from tengsim.study.worker import WORKER_ENV, compute_point, warm_up

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
2-core machine; with these, 0.4 s (docs/benchmarks.md, "Design studies on Dask").  Read when the cluster
starts; a cluster behind ``--scheduler`` keeps its own configuration."""


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
    # group, and the client alone answers it (one line, the cluster closed), not a traceback per worker;
    # their logs are silenced below CRITICAL: a worker that loses the closing scheduler mid-heartbeat logs an
    # ERROR with a traceback, and what a sweep's user must know of a point (its failure, a dead worker) the
    # client records and says itself
    old = signal.signal(signal.SIGINT, signal.SIG_IGN) if threading.current_thread() is threading.main_thread() \
        else None
    try:
        with dask.config.set(LOCAL_CLUSTER_CONFIG):
            cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, env=dict(WORKER_ENV),
                                   dashboard_address=":0", silence_logs=logging.CRITICAL)
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
                append_log(sd, {"event": "point", "id": pid, "status": r["status"],
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
