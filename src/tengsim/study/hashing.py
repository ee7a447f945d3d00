"""A point's identity: the canonical JSON of what it computes and the short SHA-256 digest of it."""
from __future__ import annotations

import hashlib
import json

import numpy as np


def canonical(obj) -> str:
    """Canonical JSON: sorted keys, no spaces, integers that are whole floats written as floats."""
    return json.dumps(_norm(obj), sort_keys=True, separators=(",", ":"), ensure_ascii=False)


def _norm(x):
    if isinstance(x, dict):
        return {str(k): _norm(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_norm(v) for v in x]
    if isinstance(x, bool) or x is None or isinstance(x, str):
        return x
    if isinstance(x, (int, float, np.integer, np.floating)):
        return float(x)
    return str(x)


def normalised(x):
    """``x`` as its canonical JSON reads back (whole floats as floats, keys as strings)."""
    return json.loads(canonical(x))


def point_id(contact: dict, provenance: dict | None = None) -> str:
    """Deterministic id of a contact computation: the first 16 hex digits of the SHA-256 of the canonical
    JSON of its table and its ``provenance`` (default :func:`tengsim.study.points.provenance`: the
    point-file format, the tengsim version, the plugin modules' and the input files' digests), so that
    other code or data never gives a point the id of this one."""
    if provenance is None:
        from tengsim.study.points import provenance as current

        provenance = current(contact)
    return hashlib.sha256(canonical({"contact": contact, "provenance": provenance}).encode()).hexdigest()[:16]
