"""Strict JSON for summaries: no NaN or Infinity tokens (RFC 8259), missing values as null."""
from __future__ import annotations

import numpy as np


def json_safe(obj):
    """``obj`` with every non-finite float (NaN, ±inf) replaced by None, so that it is strict JSON."""
    if isinstance(obj, dict):
        return {k: json_safe(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [json_safe(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return json_safe(obj.tolist())
    if isinstance(obj, (float, np.floating)):
        return float(obj) if np.isfinite(obj) else None
    if isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, np.bool_):
        return bool(obj)
    return obj
