"""Run status, per equilibrium and overall: ok, not converged, out of the law's range, under-resolved.

Every row of a :class:`tengsim.results.ContactResult` table carries one ``status`` (the worst of its
problems, in the order of :data:`SEVERITY`); the run's status is the worst row.  The problems are

* ``not_converged`` — the solver stopped before the residual of Eq. (9) reached ``tol``;
* ``out_of_law_range`` — some gap fell below the law's ``g_safe`` (the state is compressed into the
  safe extension of the law, not the physical law);
* ``under_resolved`` — the grid spacing is coarser than the adhesive process zone (below).

Resolution criterion (measured per equilibrium).  Along the X row through the apex, walking out from
the apex on each side, the *cohesive window* ℓ is the distance over which the gap opens from the law's
tensile-peak gap g* (P(g*) = −σ0, the most tensile stress; LJ 9-3: g* = 3^{1/6}) to g0 + h0, where g0
is the contact gap (P(g0) = 0; LJ 9-3: 1) and h0 = W/σ0 the Dugdale range of the law (W = −Φ(g0);
LJ 9-3: h0 = 9√3/16 = 0.974), all as the law declares them (:class:`tengsim.laws.Law`: ``g_peak``,
``max_tension``, ``g_zero``, ``work``, ``cohesive_range``).  Positions are interpolated linearly in
the gap between pixels; ℓ is the smaller of the two sides.  An equilibrium is **under-resolved when
ℓ < 0.75 dx**.  Rows without such an opening edge on the row (no contact, or contact up to the cell
border) are not judged.

Calibration (LJ 9-3 sphere, free kernel, docs/validation.md): ℓ is 0.65–0.73 of the Maugis–Dugdale
cohesive zone c − a at pull-off (Maugis 1992, λ = 1.157 μ), and nearly independent of dx, so the
criterion reads "the Maugis–Dugdale zone is narrower than about one pixel".  Measured at pull-off
(D step 0.25): μ = 3 has ℓ = 0.086–0.095; dx = 0.36 / 0.27 / 0.19 / 0.15 give ℓ/dx = 0.26 / 0.32 / 0.47
/ 0.60 (flagged) and pull-offs +47 / +21 / +8 / +4 % above MD; dx = 0.095 gives 0.90 (ok) and +2.4 %.
μ = 1 (ℓ ≈ 0.33): dx = 0.57 gives 0.57 (flagged), +14 %; dx = 0.36 gives 0.90 (ok), +5.8 % (the
grid-converged LJ value is +4.9 %).  Resolved runs lie within 1.8 % of the finest grid; the full table
is in docs/validation.md.

Pixel snap (a second, a-priori cause of under-resolution).  A law that softens beyond its tensile
peak faster than one pixel is stiff — s = max_g dP/dg × c_pix > 1 (the law's declared
``max_softening``), with c_pix the gap change of a pixel under unit pressure on that pixel alone
(one convolution of the run's kernel) — has no stable state in that band of gaps: pixels snap in and
out one at a time and the contact edge is pinned to the lattice, whatever the process zone.  Every
judged row of such a run is under-resolved.  Measured (docs/validation.md, MD sphere): MD law at
μ = 3, smoothing 0.2, dx 0.05, s = 2.0, pull-off +8.2 % over Maugis with the edge stuck for 0.6 ε of
D; smoothing 0.6 (s = 0.67 / 0.52 at dx 0.05 / 0.035) +0.72 / +0.21 %; μ = 1, smoothing 0.2,
s = 0.79 / 0.38 at dx 0.1 / 0.05: +1.1 / +0.27 %.  LJ 9-3 has s = 0.66 at μ = 3, dx 0.1.  s grows
about as μ^{3/2} dx.

A-priori estimate (stated with every run, ``params['process_zone_estimate']``): at a crack-like
contact edge (JKR limit) the Dugdale zone is ℓ_D = (π/4) E* W/σ0², i.e. π/(4 κ σ0²) in units of the
lateral length with κ = μ^{3/2} (E* = 1/κ, W = 1); it exceeds the MD c − a at pull-off by
8.6 / 3.2 / 1.2 % at μ = 3 / 5 / 8 and bounds it from above for smaller μ (μ = 1: 0.75 vs 0.47).
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from tengsim.errors import TengsimError

OK = "ok"
UNDER_RESOLVED = "under_resolved"
OUT_OF_LAW_RANGE = "out_of_law_range"
NOT_CONVERGED = "not_converged"
#: worst last: a row's status is the worst of its problems, a run's the worst of its rows
SEVERITY = (OK, UNDER_RESOLVED, OUT_OF_LAW_RANGE, NOT_CONVERGED)
#: an equilibrium is under-resolved where its cohesive window ℓ < RESOLUTION · dx
RESOLUTION = 0.75

_LABEL = {NOT_CONVERGED: "not converged", OUT_OF_LAW_RANGE: "out of the law's range",
          UNDER_RESOLVED: "under-resolved"}


class ResultStatusError(TengsimError):
    """A run finished with a status other than 'ok' and ``throw=True`` was asked; ``.result`` has it all."""

    def __init__(self, message: str, result=None):
        super().__init__(message)
        self.result = result


# ---- the law's cohesive window ------------------------------------------------------------------

@dataclass(frozen=True)
class CohesiveWindow:
    """Gaps bounding a law's process zone: g_peak (most tensile P = −sigma0), g0 (P = 0), h0 = W/sigma0."""

    g_peak: float
    g0: float
    sigma0: float
    work: float

    @property
    def h0(self) -> float:
        return self.work / self.sigma0

    @property
    def g_end(self) -> float:
        return self.g0 + self.h0


def _declared(law) -> tuple:
    """(σ0, g_peak, g0, W) as the law declares them (``tengsim.laws.Law``: closed forms in the built-in
    laws, a cached numerical search otherwise); a duck-typed law declaring none gets the laws'
    numerical search (cached where the law is hashable)."""
    if not hasattr(law, "max_tension"):
        try:
            return _undeclared(law)
        except TypeError:  # an unhashable duck-typed law: compute without the cache
            return _undeclared.__wrapped__(law)
    s0 = law.max_tension
    if s0 is None or not float(s0) > 0:
        return 0.0, None, None, 0.0
    return float(s0), law.g_peak, law.g_zero, float(law.work or 0.0)


@lru_cache(maxsize=16)
def _undeclared(law) -> tuple:
    from tengsim.laws.base import numeric_window  # only for a law that is no tengsim.laws.Law

    w = numeric_window(law)
    return (0.0, None, None, 0.0) if w is None else (w[1], w[0], w[2], w[3])


def cohesive_window(law) -> CohesiveWindow | None:
    """The law's cohesive window from its declared numbers (``max_tension``, ``g_peak``, ``g_zero``,
    ``work``; :class:`tengsim.laws.Law`); None for a law without tension, e.g. ``Repulsive``."""
    s0, g_peak, g0, work = _declared(law)
    if not (s0 > 0 and work > 0):
        return None
    return CohesiveWindow(float(g_peak), float(g0), s0, work)


def law_softening(law) -> float:
    """Steepest softening of a law beyond its tensile peak, max dP/dg over g* ≤ g ≤ g0 + 2 h0 (W/ε²
    units), as the law declares it (``max_softening``); 0 for a law without tension."""
    w = cohesive_window(law)
    if w is None:
        return 0.0
    if hasattr(law, "max_softening"):
        soft = law.max_softening
    else:  # a duck-typed law declaring none: the laws' numerical search
        from tengsim.laws.base import numeric_softening

        soft = numeric_softening(law, w.g_peak, w.g_end + w.h0)
    return float(max(soft or 0.0, 0.0))


def pixel_compliance(kernel) -> float:
    """Gap change of the centre pixel under unit pressure on it alone (one convolution)."""
    g = kernel.grid
    p = np.zeros((g.nx, g.ny))
    c = (g.nx // 2, g.ny // 2)
    p[c] = 1.0
    return float(abs(np.asarray(kernel.apply(p))[c]))


def pixel_snap_number(law, kernel) -> float:
    """s = (steepest softening of the law) × (pixel compliance); s > 1: pixels snap one at a time."""
    soft = law_softening(law)
    return soft * pixel_compliance(kernel) if soft > 0 else 0.0


def process_zone_estimate(law, coupling: float) -> float:
    """A-priori Dugdale zone ℓ_D = (π/4) E* W/σ0² = π W/(4 κ σ0²) (lateral units, κ the coupling); NaN
    for a law without tension.  Johnson & Greenwood (1997); equals MD c − a at the sphere's pull-off
    for large λ."""
    w = cohesive_window(law)
    if w is None:
        return float("nan")
    return float(np.pi * w.work / (4.0 * coupling * w.sigma0**2))


# ---- the measured, per-equilibrium process zone -------------------------------------------------

def _rise(h: np.ndarray, level: float, start: int = 0) -> float:
    """First fractional index >= start where h rises through ``level`` (NaN if it never does)."""
    above = h[start:] >= level
    k = int(np.argmax(above))
    if not above[k]:
        return float("nan")
    i = start + k
    if i == 0:
        return float("nan")
    a, b = h[i - 1], h[i]
    return i - 1 + (level - a) / (b - a)


def _window_1d(g: np.ndarray, w: CohesiveWindow) -> float:
    """Index distance over which the gap profile g (apex first) opens from g_peak to g_end; NaN if none."""
    if g[0] >= w.g_peak:
        return float("nan")
    a = _rise(g, w.g_peak)
    if a != a:
        return float("nan")
    c = _rise(g, w.g_end, int(a))
    return c - a


def process_zone_width(H: np.ndarray, dx: float, apex: tuple[int, int], law) -> float:
    """Measured cohesive window ℓ of one equilibrium (module docstring): the distance along the X row
    through ``apex`` over which the gap g = H + 1 opens from g* to g0 + h0, the smaller of the two
    sides; NaN if the row has no such edge or the law has no tension."""
    w = cohesive_window(law)
    if w is None:
        return float("nan")
    row = np.asarray(H, dtype=float)[:, apex[1]] + 1.0
    i0 = apex[0]
    sides = [_window_1d(row[i0:], w), _window_1d(row[i0::-1], w)]
    sides = [s for s in sides if s == s]
    return float(min(sides) * dx) if sides else float("nan")


# ---- classification -----------------------------------------------------------------------------

def _zone(table: dict) -> tuple[np.ndarray, np.ndarray]:
    """(process zone per row, rows where it was measured: an opening edge on the apex row; 0 or NaN:
    none, or an older file)."""
    pz = np.asarray(table.get("process_zone", np.full(len(table["D"]), np.nan)), dtype=float)
    with np.errstate(invalid="ignore"):
        return pz, np.isfinite(pz) & (pz > 0)


def snapping(table: dict, snap: float | None) -> np.ndarray:
    """Rows judged (an opening contact edge on the apex row) in a run whose pixel snap number > 1."""
    if not (snap is not None and snap > 1.0):
        return np.zeros(len(table["D"]), bool)
    return _zone(table)[1]


def flags(table: dict, dx: float, snap: float | None = None) -> dict:
    """Boolean arrays, one per problem kind, over the rows of a result table (``snap``: the run's
    pixel snap number, :func:`pixel_snap_number`)."""
    n = len(table["D"])
    conv = np.asarray(table["converged"]).astype(bool)
    in_range = np.asarray(table.get("in_law_range", np.ones(n))).astype(bool)
    return {NOT_CONVERGED: ~conv, OUT_OF_LAW_RANGE: ~in_range,
            UNDER_RESOLVED: narrow_zone(table, dx) | snapping(table, snap)}


def narrow_zone(table: dict, dx: float) -> np.ndarray:
    """Rows whose measured process zone is below RESOLUTION · dx (0: not measured, older files)."""
    pz, measured = _zone(table)
    return measured & (pz < RESOLUTION * dx)


def row_status(converged: bool, in_range: bool, process_zone: float, dx: float, snap: float | None = None) -> str:
    """The status of one equilibrium as it is recorded (the same rules as :func:`classify` on a table)."""
    if not converged:
        return NOT_CONVERGED
    if not in_range:
        return OUT_OF_LAW_RANGE
    measured = process_zone == process_zone and process_zone > 0
    if measured and (process_zone < RESOLUTION * dx or (snap is not None and snap > 1.0)):
        return UNDER_RESOLVED
    return OK


def classify(table: dict, dx: float, snap: float | None = None) -> np.ndarray:
    """Per-row status strings: the worst problem of each row (SEVERITY order), 'ok' if none."""
    f = flags(table, dx, snap)
    out = np.full(len(table["D"]), OK, dtype=object)
    for kind in SEVERITY[1:]:
        out[f[kind]] = kind
    return out.astype(str)


def overall(statuses) -> str:
    """The worst status of the rows (``'ok'`` for an empty run)."""
    s = set(np.asarray(statuses).astype(str).tolist())
    return max(s, key=SEVERITY.index) if s else OK


def _where(table: dict, mask: np.ndarray) -> str:
    parts = []
    br = np.asarray(table["branch"]).astype(str)
    D = np.asarray(table["D"], dtype=float)
    for b in dict.fromkeys(br[mask]):
        d = D[mask & (br == b)]
        parts.append(f"{b} D {d[0]:.4g}" + (f"…{d[-1]:.4g}" if len(d) > 1 else ""))
    return ", ".join(parts)


def problems(result) -> list[tuple[str, str]]:
    """(kind, one-line description naming where) for each problem kind present, worst first."""
    t, dx, p = result.table, result.grid.dx, result.params
    snap = p.get("pixel_snap_number")
    f = flags(t, dx, snap)
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
            if p.get("load_not_met"):  # load control: the outer solve on D missed a load (tengsim.loadpath)
                text += f" or load not met to f_tol = {p.get('f_tol', '?')}"
            text += f" {where}"
        elif kind == OUT_OF_LAW_RANGE:
            text = (f"gaps below the law's safe limit g_safe = {p.get('g_safe', '?')} {where} (compressed "
                    "beyond the physical law; with the periodic kernel this happens once the whole cell is "
                    "flattened)")
        else:
            parts = []
            narrow = m & narrow_zone(t, dx)
            if narrow.any():
                pz = float(np.nanmin(np.asarray(t["process_zone"], dtype=float)[narrow]))
                est = p.get("process_zone_estimate", float("nan"))
                parts.append(f"process zone {pz:.3g} < {RESOLUTION:g} dx = {RESOLUTION * dx:.3g} (dx = {dx:.3g}; "
                             f"cohesive window g* → g0 + h0 on the apex row; a-priori Dugdale estimate {est:.3g}; "
                             f"resolved for dx <= {pz / RESOLUTION:.3g})")
            if snapping(t, snap).any():
                parts.append(f"the law softens faster than one pixel is stiff (max dP/dg × pixel compliance = "
                             f"{snap:.3g} > 1): pixels snap one at a time and the contact edge is pinned to the "
                             f"grid; refine dx to about {dx / snap:.3g} or below, or soften the law (md: a larger "
                             "smoothing)")
            text = "; ".join(parts) + f" {where}"
        out.append((kind, f"{_LABEL[kind]}: {text}"))
    return out


def warning_lines(result) -> list[str]:
    """One line per problem kind, ready for the CLI's 'tengsim: warning: ' prefix."""
    return [text for _, text in problems(result)]


def attach(result, law, coupling: float) -> None:
    """Add the run-level status to ``result``, whose rows were classified as they were recorded
    (:class:`tengsim.continuation.Recorder`, :func:`row_status`): the a-priori process-zone estimate,
    the criterion, the overall status and the warning lines (``params['warning']``, joined)."""
    result.params["process_zone_estimate"] = process_zone_estimate(law, coupling)
    result.params["resolution_criterion"] = f"process_zone >= {RESOLUTION:g} dx and pixel_snap_number <= 1"
    if "status" not in result.table:  # a table from elsewhere (an older file): classify it here, once
        result.table["status"] = classify(result.table, result.grid.dx, result.params.get("pixel_snap_number"))
    result.params["status"] = overall(result.table["status"])
    lines = warning_lines(result)
    if lines:
        result.params["warning"] = "; ".join(lines)
    else:
        result.params.pop("warning", None)


def raise_for_status(result) -> None:
    """Raise :class:`ResultStatusError` (carrying ``result``) unless the overall status is 'ok'."""
    s = result.status
    if s != OK:
        lines = warning_lines(result)
        raise ResultStatusError(f"run status {s}: " + "; ".join(lines), result)
