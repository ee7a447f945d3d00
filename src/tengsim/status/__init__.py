"""Run status, per equilibrium and overall: ok, not converged, out of the law's range, under-resolved.

- :mod:`~tengsim.status.levels`: the :class:`Status` enum, its order of severity and its aggregation
  (:func:`overall`), and :class:`ResultStatusError`;
- :mod:`~tengsim.status.diagnostics`: what is measured — the law's cohesive window, the process zone at
  every contact edge (:class:`EdgeScan`), the pixel snap number, the uncertainty of walled faces;
- :mod:`~tengsim.status.classify`: what it decides — each row's status, the run's, the warning lines.
"""
from tengsim.status.classify import (FACE_LIMIT, RESOLUTION, SNAP_LIMIT, attach, classify, coarse_faces, flags,
                                     narrow_zone, problems, raise_for_status, row_status, snapping, warning_lines)
from tengsim.status.diagnostics import (EDGE_QUANTILE, WALL_FACTOR, WALL_RATIO, WALL_STEP, CohesiveWindow, EdgeScan,
                                        cohesive_window, edge_process_zone, face_uncertainty, law_softening,
                                        pixel_compliance, pixel_snap_number, process_zone_estimate,
                                        process_zone_width)
from tengsim.status.levels import (NOT_CONVERGED, OK, OUT_OF_LAW_RANGE, SEVERITY, UNDER_RESOLVED, ResultStatusError,
                                   Status, overall)

__all__ = [
    "EDGE_QUANTILE", "FACE_LIMIT", "NOT_CONVERGED", "OK", "OUT_OF_LAW_RANGE", "RESOLUTION", "SEVERITY", "SNAP_LIMIT",
    "UNDER_RESOLVED", "WALL_FACTOR", "WALL_RATIO", "WALL_STEP", "CohesiveWindow", "EdgeScan", "ResultStatusError",
    "Status", "attach", "classify", "coarse_faces", "cohesive_window", "edge_process_zone", "face_uncertainty",
    "flags", "law_softening", "narrow_zone", "overall", "pixel_compliance", "pixel_snap_number", "problems",
    "process_zone_estimate", "process_zone_width", "raise_for_status", "row_status", "snapping", "warning_lines",
]
