"""Classification: each equilibrium's status from its diagnostics, the run's status, and the warning
lines that name where.

Every row of a :class:`tengsim.results.ContactResult` table carries one ``status`` (the worst of its
problems, in the order of :data:`tengsim.status.levels.SEVERITY`); the run's status is the worst
row.  The problems are

* ``not_converged`` — the solver stopped before the residual of Eq. (9) reached ``tol``;
* ``out_of_law_range`` — some gap fell below the law's ``g_safe`` (the state is compressed into the
  safe extension of the law, not the physical law);
* ``under_resolved`` — the grid spacing is coarser than the adhesive process zone, the law snaps
  pixel by pixel, or a walled face is rasterised too coarsely (:mod:`tengsim.status.diagnostics`).

The criteria (:data:`RESOLUTION`, :data:`SNAP_LIMIT`, :data:`FACE_LIMIT`) are calibrated against grid
convergence (benchmarks/status_calibration.py, docs/validation.md); the measures are in
:mod:`tengsim.status.diagnostics`.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from tengsim.status.diagnostics import process_zone_estimate
from tengsim.status.levels import (NOT_CONVERGED, OK, OUT_OF_LAW_RANGE, SEVERITY, UNDER_RESOLVED,
                                   ResultStatusError, Status, overall)

#: an equilibrium is under-resolved where its cohesive window ℓ < RESOLUTION · dx (calibrated on grid convergence:
#: pull-off and jump D within 1 % of the finest grid for every shape and law from ℓ/dx = 1.24 up; 0.83–1.12 missed)
RESOLUTION = 1.2
#: ... or where the run's pixel snap number s > SNAP_LIMIT (lattice trapping: pull-off +1.7 % at s = 0.79)
SNAP_LIMIT = 0.6
#: ... or where a face bounded by walls is known to worse than FACE_LIMIT of its area (pixel-centre sampling;
#: a flat top's pull-off moves as its area to the power 0.8–1, measured on the cube)
FACE_LIMIT = 0.01



def _zone(table: dict) -> tuple[np.ndarray, np.ndarray]:
    """(process zone per row, rows where it was measured: an opening contact edge somewhere on the grid;
    0 or NaN: none, or an older file)."""
    pz = np.asarray(table.get("process_zone", np.full(len(table["D"]), np.nan)), dtype=float)
    with np.errstate(invalid="ignore"):
        return pz, np.isfinite(pz) & (pz > 0)


def _snaps(snap) -> bool:
    return snap is not None and snap == snap and snap > SNAP_LIMIT


def _coarse_face(face) -> bool:
    return face is not None and face == face and face > FACE_LIMIT


def snapping(table: dict, snap: float | None) -> np.ndarray:
    """Rows judged (an opening contact edge) in a run whose pixel snap number > SNAP_LIMIT."""
    if not _snaps(snap):
        return np.zeros(len(table["D"]), bool)
    return _zone(table)[1]


def coarse_faces(table: dict, face: float | None) -> np.ndarray:
    """Rows judged (an opening contact edge) in a run whose walled faces are known to worse than FACE_LIMIT."""
    if not _coarse_face(face):
        return np.zeros(len(table["D"]), bool)
    return _zone(table)[1]


def flags(table: dict, dx: float, snap: float | None = None, face: float | None = None) -> dict:
    """Boolean arrays, one per problem kind, over the rows of a result table (``snap``: the run's
    pixel snap number, :func:`pixel_snap_number`; ``face``: its face uncertainty, :func:`face_uncertainty`)."""
    n = len(table["D"])
    conv = np.asarray(table["converged"]).astype(bool)
    in_range = np.asarray(table.get("in_law_range", np.ones(n))).astype(bool)
    return {NOT_CONVERGED: ~conv, OUT_OF_LAW_RANGE: ~in_range,
            UNDER_RESOLVED: narrow_zone(table, dx) | snapping(table, snap) | coarse_faces(table, face)}


def narrow_zone(table: dict, dx: float) -> np.ndarray:
    """Rows whose measured process zone is below RESOLUTION · dx (0: not measured, older files)."""
    pz, measured = _zone(table)
    return measured & (pz < RESOLUTION * dx)


def row_status(converged: bool, in_range: bool, process_zone: float, dx: float, snap: float | None = None,
               face: float | None = None) -> Status:
    """The status of one equilibrium as it is recorded (the same rules as :func:`classify` on a table)."""
    if not converged:
        return NOT_CONVERGED
    if not in_range:
        return OUT_OF_LAW_RANGE
    measured = process_zone == process_zone and process_zone > 0
    if measured and (process_zone < RESOLUTION * dx or _snaps(snap) or _coarse_face(face)):
        return UNDER_RESOLVED
    return OK


def classify(table: dict, dx: float, snap: float | None = None, face: float | None = None) -> np.ndarray:
    """Per-row status strings: the worst problem of each row (SEVERITY order), 'ok' if none."""
    f = flags(table, dx, snap, face)
    out = np.full(len(table["D"]), OK, dtype=object)
    for kind in SEVERITY[1:]:
        out[f[kind]] = kind
    return out.astype(str)


def _where(table: dict, mask: np.ndarray) -> str:
    parts = []
    br = np.asarray(table["branch"]).astype(str)
    D = np.asarray(table["D"], dtype=float)
    for b in dict.fromkeys(br[mask]):
        d = D[mask & (br == b)]
        parts.append(f"{b} D {d[0]:.4g}" + (f"…{d[-1]:.4g}" if len(d) > 1 else ""))
    return ", ".join(parts)


def _length_text(scaling):
    """In-plane lengths (X units) as the run's user gave them: with a unit in a physical run."""
    if scaling is None:
        return lambda x: f"{x:.3g}"
    from tengsim.units import format_si

    return lambda x: format_si(x * scaling.lateral, "m") if np.isfinite(x) else "nan"


def problems(result) -> list[tuple[str, str]]:
    """(kind, one-line description naming where) for each problem kind present, worst first."""
    t, dx, p = result.table, result.grid.dx, result.params
    snap, face = p.get("pixel_snap_number"), p.get("face_uncertainty")
    f = flags(t, dx, snap, face)
    n = len(t["D"])
    out = []
    for kind in reversed(SEVERITY[1:]):
        m = f[kind]
        k = int(m.sum())
        if not k:
            continue
        where = f"at {k} of {n} equilibria ({_where(t, m)})"
        if kind == NOT_CONVERGED:
            text = f"residual of Eq. (9) above tol = {p.get('tol', '?')}"
            if p.get("load_not_met"):  # load control: the outer solve on D missed a load (tengsim.continuation.load)
                text += f" or load not met to f_tol = {p.get('f_tol', '?')}"
            text += f" {where}"
            if _snaps(snap) and p.get("solver", "fast") == "fast":  # stiff at the pixel: the homotopy's case
                text += (f" (pixel snap number {snap:.3g}: a cold start of a law stiffer than a pixel converges "
                         "faster with solver = 'homotopy')")
        elif kind == OUT_OF_LAW_RANGE:
            text = (f"gaps below the law's safe limit g_safe = {p.get('g_safe', '?')} {where} (compressed "
                    "beyond the physical law; with the periodic kernel this happens once the whole cell is "
                    "flattened)")
        else:
            parts = []
            L = _length_text(getattr(result, "scaling", None))
            narrow = m & narrow_zone(t, dx)
            if narrow.any():
                pz = float(np.nanmin(np.asarray(t["process_zone"], dtype=float)[narrow]))
                est = p.get("process_zone_estimate", float("nan"))
                parts.append(f"process zone {L(pz)} < {RESOLUTION:g} dx = {L(RESOLUTION * dx)} (dx = {L(dx)}; "
                             f"cohesive window g* → g0 + h0 at the narrowest contact edge; a-priori Dugdale "
                             f"estimate {L(est)}; "
                             f"resolved for dx <= {L(pz / RESOLUTION)})")
            if snapping(t, snap).any():
                parts.append(f"the law softens faster than one pixel is stiff (max dP/dg × pixel compliance = "
                             f"{snap:.3g} > {SNAP_LIMIT:g}): pixels snap one at a time and the contact edge is "
                             f"pinned to the grid; refine dx to about {L(dx * SNAP_LIMIT / snap)} or below, or soften "
                             "the law (md: a larger smoothing)")
            if coarse_faces(t, face).any():
                parts.append(f"a flat face bounded by walls is known to {100 * face:.2g} % of its area > "
                             f"{100 * FACE_LIMIT:g} % (each wall lies somewhere within half a pixel); refine dx to "
                             f"about {L(dx * FACE_LIMIT / face)} or below")
            text = "; ".join(parts) + f" {where}"
        out.append((kind, f"{kind.label}: {text}"))
    return out


def warning_lines(result) -> list[str]:
    """One line per problem kind, ready for the CLI's 'tengsim: warning: ' prefix."""
    return [text for _, text in problems(result)]


def attach(result, law, coupling: float):
    """``result`` with its run-level status (a new result; ``result`` is left as it was).  Its rows were
    classified as they were recorded (:class:`tengsim.continuation.Recorder`, :func:`row_status`); added
    are the a-priori process-zone estimate, the criterion, the overall status and the warning lines
    (``params['warning']``, joined)."""
    table, params = result.table, dict(result.params)
    params["process_zone_estimate"] = process_zone_estimate(law, coupling)
    params["resolution_criterion"] = (f"process_zone >= {RESOLUTION:g} dx and pixel_snap_number <= "
                                      f"{SNAP_LIMIT:g} and face_uncertainty <= {FACE_LIMIT:g}")
    if "status" not in table:  # a table from elsewhere (an older file): classify it here, once
        table = {**table, "status": classify(table, result.grid.dx, params.get("pixel_snap_number"),
                                             params.get("face_uncertainty"))}
    params["status"] = overall(table["status"])
    params.pop("warning", None)
    lines = warning_lines(dataclasses.replace(result, table=table, params=params))
    if lines:
        params["warning"] = "; ".join(lines)
    return dataclasses.replace(result, table=table, params=params)


def raise_for_status(result) -> None:
    """Raise :class:`ResultStatusError` (carrying ``result``) unless the overall status is 'ok'."""
    s = result.status
    if s != OK:
        lines = warning_lines(result)
        raise ResultStatusError(f"run status {s}: " + "; ".join(lines), result)
