"""The finished grids of an automatic refinement kept on disk, so a killed run resumes where it stopped."""
from __future__ import annotations

import dataclasses
import math

from tengsim.errors import TengsimError


class Checkpoint:
    """The finished grids of a refinement writing ``out`` (``resolve = 'auto'`` with a row stream), kept in
    :func:`checkpoint_path`: after each grid, the finest grid's result (NetCDF, written atomically) with the
    levels so far and the table's digest in its parameters; read back by ``--resume`` (the grids are not
    computed again); removed with the partial file once the result is saved
    (:meth:`tengsim.results.RowStream.finish`)."""

    KEY = "resolve_checkpoint"

    def __init__(self, path, digest: str):
        self.path, self.digest = path, digest

    @classmethod
    def of(cls, sink, cfg: dict):
        """The checkpoint of the run streaming to ``sink`` (a RowStream: its ``out``), None without one."""
        import hashlib

        from tengsim import io

        out = getattr(sink, "out", None)
        if out is None:
            return None
        cfg = {k: v for k, v in cfg.items() if k not in ("out", "plot")}
        digest = hashlib.sha256(io.dumps(dict(sorted(cfg.items()))).encode()).hexdigest()[:16]
        from tengsim.results import checkpoint_path

        return cls(checkpoint_path(out), digest)

    def save(self, levels, phases, res) -> None:
        from tengsim import io

        from tengsim.run.judge import GridRecord

        levels = [GridRecord.of(lv).as_dict() for lv in levels]  # each finished grid as the file keeps it
        kept = {self.KEY: io.dumps({"digest": self.digest, "levels": levels, "phases": list(phases)})}
        dataclasses.replace(res, params={**res.params, **kept}).save(self.path)

    def stored_digest(self) -> str | None:
        """The digest the kept file was written with (None: no file, or not a checkpoint)."""
        import json

        from tengsim.results.read import load_result

        if not self.path.is_file():
            return None
        try:
            _, res = load_result(self.path)
            return str(json.loads(res.params[self.KEY])["digest"])
        except (TengsimError, KeyError, TypeError, ValueError, OSError):
            return None

    def load(self):
        """(levels, phases, result) kept by an interrupted run of this table, or None if there is none."""
        import json

        from tengsim.results.read import load_result

        if not self.path.is_file():
            return None
        try:
            _, res = load_result(self.path)
            rec = json.loads(res.params[self.KEY])
            res = dataclasses.replace(res, params={k: v for k, v in res.params.items() if k != self.KEY})
        except (TengsimError, KeyError, TypeError, ValueError) as exc:
            raise TengsimError(f"--resume: {self.path} is not a refinement checkpoint ({exc}); delete it to "
                               "start afresh") from None
        if rec.get("digest") != self.digest:
            raise TengsimError(f"--resume: {self.path} was written by another run (its [contact] table "
                               "differs); delete it to start afresh")
        from tengsim.run.judge import GridRecord

        levels = rec["levels"]
        for lv in levels:  # strict JSON wrote NaN as null
            lv["obs"] = {k: (math.nan if v is None else v) for k, v in lv["obs"].items()}
        return [GridRecord.of(lv) for lv in levels], rec["phases"], res


def open_checkpoint(keep, key: str, d_max: float, say=None):
    """(the :class:`Checkpoint` in the file ``keep`` of the run ``key`` on the D range ``d_max``, what it holds or
    None): each finished grid is kept there, and a run of the same key and path takes its grids back instead of
    computing them again; grids of the same key on a shorter path (a first pass) are replaced quietly, those of
    another key with a line (``say(text)``, if given)."""
    ck = Checkpoint(keep, f"{key}@{d_max!r}")
    try:
        found = ck.load()
    except TengsimError:
        if not (ck.stored_digest() or "").startswith(key + "@") and say is not None:
            say(f"{keep} holds grids of another design or input: they are replaced")
        keep.unlink()
        found = None
    if found is not None and say is not None:
        say(f"taking back {len(found[0])} finished grid(s) from {keep}")
    keep.parent.mkdir(parents=True, exist_ok=True)
    return ck, found
