"""The task that runs on a Dask worker: one point, exactly what ``tengsim run`` runs for the same
[contact] table, never raising (a failure is a failed point with its message)."""
from __future__ import annotations

import importlib
import json
import os
import socket
import time

from tengsim.errors import TengsimError

WORKER_ENV = {"OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1",
              "TENGSIM_THREADS": "1", "TENGSIM_FFT_WORKERS": "1"}
"""Environment of every worker: one thread per process (the parallelism is across points)."""


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
        from tengsim.run.plan import plan_contact
        from tengsim.run.resolve import resolve
        from tengsim.run.simulate import simulate

        c0 = time.perf_counter()
        plan = plan_contact(dict(contact))
        res = (simulate if plan.resolve is None else resolve)(plan)  # resolve = 'auto': refined until converged
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
    for module in ("tengsim.run.plan", "tengsim.run.simulate", "xarray"):
        importlib.import_module(module)

    return os.getpid()
