"""The model of a measured curve: converged designs on a grid of (W, ε), interpolated, with its own error.

**What the contact depends on.**  A design solves the dimensionless problem (heights in ε, Eq. 9) whose coupling is
κ = W ℓ/(E* ε²) and whose pressures are in units of W/ε (:class:`tengsim.units.Scaling`).  Multiplying W and E* by
the same λ keeps κ and multiplies every pressure by λ, so A/S(P; W, ε, E*) = A/S(P/λ; W/λ, ε, E_ref) with
λ = E*/E_ref.  The contact is therefore solved only on the plane (W_eff = W E_ref/E*, ε): a free E* costs no
solve of its own, only a wider pressure range.

**Nodes.**  Each node is one converged design (:func:`tengsim.design.run_design`, status ok at the design's own
tol) at (W_eff, ε), kept in ``DIR/designs/KEY.nc`` as soon as it is solved (KEY: a hash of the design's table), so a
killed calibration loses at most the design in progress and a rerun takes every solved node back.  A node whose
design is not ok (or fails) is recorded and left out: no model value comes from an unconverged design.  Only the
design's own answer is kept as failed (``KEY.failed.txt``); a failure of the machine (too little memory, the time
budget spent, a solver missing: :class:`tengsim.errors.MachineError`, told by its type) or an interrupted node is
never kept, and the next run solves it again.  KEY covers every file the table names (:func:`node_key`).

**Interpolation: along the curve, not at a fixed pressure.**  A branch's A/S jumps (snap-in on the approach) at a
pressure that moves with W and ε; blending two nodes' A/S at a fixed pressure, one jumped and one not, makes a
curve with a plateau half-way that no design has.  So each node's curve, made monotone in P, is read as pressure
against the level t = A/S + α P/p_max (α = :data:`LEVEL_SLOPE`; strictly increasing; flat beyond 0 and p_max), and
P(t) at fixed levels t is what is interpolated between the nodes by a thin-plate spline in (log W_eff, log ε) (each
axis over its bound range): a jump is a run of t at one pressure, and that pressure moves continuously between the
nodes ("displacement interpolation").  Each node's curve is the states its design's device passes (design.nc's
``state_pressure``, ``state_charged_area_fraction``), not its A/S at the asked pressures: there a snap between two
of them is a ramp one pressure step wide, and a measured point inside that step is read off the ramp, far from
either branch.  A/S at P/λ is then read back off the interpolated curve.  Its error is
measured against designs solved where the fit lands (:func:`tengsim.calibrate.run.calibrate`) and reported beside
the data's noise.
"""
from __future__ import annotations

import functools
import hashlib
import json
import math
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from tengsim.errors import MachineError, SolverUnavailable, TengsimError
from tengsim.status.levels import Status

POINTS_PER_CURVE = 21
"""Pressures of a node's design, 0 to p_max (A/S is linear between them; more make the refinement judge more)."""
LEVEL_SLOPE = 0.25
"""α of the level t = A/S + α P/p_max along which nodes are interpolated (module doc): small, the levels are A/S
itself and a jump moves as one; not zero, so that a flat stretch (full contact) still has one pressure per level."""
LEVELS = np.unique(np.concatenate([np.linspace(0.0, 1.0 + LEVEL_SLOPE, 1001), np.linspace(0.0, 0.3, 301)]))
"""The levels t (dense at small A/S, where a relative noise weighs most)."""


def geometry_key(table: dict) -> str:
    """The design without its material: curves on the same geometry share nodes."""
    rest = {k: v for k, v in table.items() if k not in ("W", "eps", "E_star", "sigma", "name")}
    return json.dumps(rest, sort_keys=True, default=str)


def node_table(table: dict, W: float, eps: float, E_ref: float, p_max: float) -> dict:
    """The design table of a node (SI numbers for the material and pressures)."""
    t = {k: v for k, v in table.items() if k not in ("p_min", "p_max", "p_step", "name", "fit_max", "maps")}
    t.update({"W": float(W), "eps": float(eps), "E_star": float(E_ref), "p_min": 0.0, "p_max": float(p_max),
              "p_step": float(p_max) / (POINTS_PER_CURVE - 1), "maps": False})
    return t


def node_key(table: dict) -> str:
    """The node's identity: a hash of its design table and of the content of every file the table names (a
    topography's heights: a changed file is a new node, never a stale one taken back)."""
    text = json.dumps(table, sort_keys=True, default=str)
    files = input_files(table)
    if files:  # (a table naming no file keeps the key it always had)
        text += json.dumps({f: _digest(f) for f in files}, sort_keys=True)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def _digest(path: str) -> str:
    """SHA-256 of a file's content, computed once per (file, size, modification time)."""
    st = Path(path).stat()
    return _digest_of(str(Path(path).resolve()), st.st_size, st.st_mtime_ns)


@functools.lru_cache(maxsize=64)
def _digest_of(path: str, size: int, mtime_ns: int) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def input_files(table: dict) -> list:
    """The files a design table names (its string values that are existing files: a topography's heights)."""
    out = []
    for v in table.values():
        if isinstance(v, str) and 0 < len(v) < 4096:
            try:
                if Path(v).is_file():
                    out.append(v)
            except (OSError, ValueError):
                continue
    return sorted(out)


@dataclass
class Node:
    u: float  # log W_eff
    v: float  # log eps
    ok: bool
    pressures: np.ndarray | None = None
    area: dict | None = None  # branch -> A/S at pressures
    message: str = ""
    seconds: float = 0.0
    cached: bool = False
    states: dict | None = None  # branch -> (P, A/S) of the states passed (Pa, increasing), where the file has them
    machine: bool = False  # failed for this machine's reason (memory, the time budget): not kept, tried again

    def curve(self, branch: str, p_max: float):
        """(P, A/S) of the branch from 0 to ``p_max`` (Pa): the states passed, A/S held flat before the first and
        after the last, made monotone; the asked pressures (NaN filled) for a file without states."""
        st = (self.states or {}).get(branch)
        if st is None or len(st[0]) < 2:
            P = np.asarray(self.pressures, float)
            return P, np.maximum.accumulate(np.clip(_fill(self.area[branch]), 0.0, 1.0))
        from tengsim.device.areas import passed_curve

        return passed_curve(*st, 0.0, p_max)  # the device reads a design's states the same way

    def area_at(self, branch: str, pressures) -> np.ndarray:
        """The node's own A/S at ``pressures`` (Pa) on ``branch``, off :meth:`curve`."""
        P, A = self.curve(branch, float(np.max(np.r_[self.pressures, pressures])))
        return np.interp(np.asarray(pressures, float), P, A)


def _read(ds):
    """(pressures, {branch: A/S}, {branch: (P, A/S) of the states passed} or None) of a design.nc Dataset."""
    P = np.asarray(ds["pressure"].values, float)
    A = {b: np.asarray(ds["charged_area_fraction"].sel(branch=b).values, float) for b in ("approach", "retraction")}
    if "state_pressure" not in ds:
        return P, A, None
    st = {}
    for b in ("approach", "retraction"):
        sp = np.asarray(ds["state_pressure"].sel(branch=b).values, float)
        sa = np.asarray(ds["state_charged_area_fraction"].sel(branch=b).values, float)
        ok = np.isfinite(sp) & np.isfinite(sa)
        st[b] = (sp[ok], sa[ok])
    return P, A, st


def _load(path: Path):
    from tengsim.io import read_dataset

    ds = read_dataset(path)
    return (*_read(ds), str(ds.attrs.get("status")), float(ds.attrs.get("seconds", 0.0) or 0.0))


def solve_node(table: dict, folder: Path, u: float, v: float, progress=None) -> Node:
    """The node's design, taken back from ``folder`` or solved and kept there (module doc)."""
    from tengsim.design import plan_design, run_design
    from tengsim.io import write_dataset, write_text

    key = node_key(table)
    nc, bad = folder / f"{key}.nc", folder / f"{key}.failed.txt"
    if nc.is_file():
        P, A, st, status, secs = _load(nc)
        return Node(u, v, status == Status.OK, P, A, "" if status == Status.OK else f"status {status}", secs, True, st)
    if bad.is_file():
        return Node(u, v, False, message=bad.read_text(encoding="utf-8").strip(), cached=True)
    folder.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    keep = folder / f"{key}.resolve.nc"
    try:
        res = run_design(plan_design(table), progress=progress, keep=keep)
    except SolverUnavailable:  # not this node's answer, nor any node's: the run stops (one line), nothing kept
        raise
    except (MachineError, MemoryError) as exc:  # the machine's failure, not the design's: never kept as failed
        # (the next run tries again, from the grids kept in KEY.resolve.nc where a budget stopped it)
        return Node(u, v, False, message=machine_text(exc, keep), seconds=time.perf_counter() - t0, machine=True)
    except TengsimError as exc:  # the design's own answer (it cannot be solved as asked): kept
        write_text(bad, str(exc) + "\n")
        keep.unlink(missing_ok=True)
        return Node(u, v, False, message=str(exc), seconds=time.perf_counter() - t0)
    write_dataset(res.dataset, nc)
    (folder / f"{key}.resolve.nc").unlink(missing_ok=True)
    P, A, st = _read(res.dataset)
    ok = res.status == Status.OK
    return Node(u, v, ok, P, A, "" if ok else f"status {res.status}", time.perf_counter() - t0, states=st)


def machine_text(exc, keep: Path) -> str:
    """What stopped a node for this machine's reason, with the advice calibrate can give (it has no --budget:
    the design file's ``budget`` key)."""
    from tengsim.errors import BudgetExceeded
    from tengsim.run.budget import BUDGET_CLOCK
    from tengsim.units import time_text

    again = "not kept as failed: the next run tries it again"
    if isinstance(exc, BudgetExceeded):
        kept = f" from the grids kept in {keep}" if keep.exists() else ""
        return (f"stopped at the design's time budget of {time_text(exc.budget_s)} ({BUDGET_CLOCK}); {again}"
                f"{kept} (or give the design file a larger budget, e.g. budget = \"1800s\")")
    if isinstance(exc, MemoryError):
        return f"out of memory on this machine; {again}"
    return f"{exc}; {again}"


def _fill(y):
    """NaN (a branch that does not reach a pressure) replaced by the nearest finite value along pressure."""
    y = np.array(y, float)
    ok = np.isfinite(y)
    if ok.all() or not ok.any():
        return np.nan_to_num(y)
    idx = np.arange(len(y))
    return np.interp(idx, idx[ok], y[ok])


@dataclass
class Surrogate:
    """A/S(P) of one geometry on the (log W_eff, log ε) plane (module doc).  ``span``: each axis's bound range
    (its scale); ``dims``: the axes that vary (0: W_eff, 1: ε)."""

    pressures: np.ndarray
    nodes: list
    span: tuple
    dims: tuple
    interp: str = "level"  # "pressure": A/S blended at fixed pressures (the jump-blind interpolation, for comparison)
    _rbf: dict = field(default_factory=dict, repr=False)

    def good(self) -> list:
        return [n for n in self.nodes if n.ok]

    def _coords(self, nodes_or_uv) -> np.ndarray:
        uv = np.array([[n.u, n.v] for n in nodes_or_uv]) if isinstance(nodes_or_uv, list) else np.asarray(nodes_or_uv)
        return np.stack([uv[:, d] / self.span[d] for d in self.dims], axis=1) if self.dims else np.zeros((len(uv), 1))

    def _curves(self, nodes, branch):
        """(len(nodes), m) A/S of ``nodes`` on ``branch`` at :attr:`pressures` (NaN filled, monotone in P)."""
        return np.stack([np.maximum.accumulate(np.clip(_fill(n.area[branch]), 0.0, 1.0)) for n in nodes])

    def _build(self, nodes, branch):
        """x (K, len(dims)) -> (K, L): the interpolated rows (P at :data:`LEVELS`, or A/S at the pressures for
        ``interp == "pressure"``)."""
        from scipy.interpolate import RBFInterpolator

        if self.interp == "level":
            pm = float(self.pressures[-1])
            Y = np.concatenate([to_levels(P, A[None, :], p_max=pm) for P, A in (n.curve(branch, pm) for n in nodes)])
        else:
            Y = self._curves(nodes, branch)
        if not self.dims or len(nodes) == 1:
            return lambda x: np.broadcast_to(Y.mean(axis=0), (len(x), Y.shape[1]))
        if len(nodes) > len(self.dims) + 1:
            f = RBFInterpolator(self._coords(nodes), Y, kernel="thin_plate_spline", degree=1)
        else:
            f = RBFInterpolator(self._coords(nodes), Y, kernel="linear", degree=0)  # too few nodes for a spline
        return lambda x: np.concatenate([f(x[k:k + CHUNK]) for k in range(0, len(x), CHUNK)]) if len(x) else \
            np.zeros((0, Y.shape[1]))

    def rbf(self, branch):
        if branch not in self._rbf:
            good = self.good()
            if not good:
                machine = [n for n in self.nodes if n.machine]
                if machine:  # not the design's answer: the advice is to run again, not to change the design
                    raise TengsimError(f"no converged design among the nodes: {len(machine)} of {len(self.nodes)} "
                                       f"were stopped by this machine ({machine[0].message})")
                raise TengsimError("no converged design among the nodes: narrow the bounds or loosen the design's tol")
            self._rbf[branch] = self._build(good, branch)
        return self._rbf[branch]

    def _read(self, rows, x):
        """A/S (K, n) at pressures x (K or 1, n) off interpolated rows (K, L)."""
        if self.interp == "level":
            return from_levels(self.pressures, rows, x)
        return _interp_rows(self.pressures, rows, x)

    def area(self, u, v, lam, pressures, branches) -> np.ndarray:
        """A/S (K, n) at points (u, v, λ) (arrays of K) and the pressures (n, Pa) on their branches."""
        u, v, lam = (np.atleast_1d(np.asarray(x, float)) for x in (u, v, lam))
        uv = np.stack([u, v], axis=1)
        pressures, branches = np.asarray(pressures, float), np.asarray(branches)
        out = np.empty((len(u), len(pressures)))
        for b in np.unique(branches):
            sel = np.flatnonzero(branches == b)
            f, x = self.rbf(str(b)), self._coords(uv)
            for k in range(0, len(u), CHUNK):
                out[k:k + CHUNK, sel] = self._read(f(x[k:k + CHUNK]),
                                                   pressures[sel][None, :] / lam[k:k + CHUNK, None])
        return np.clip(out, 0.0, 1.0)


CHUNK = 2048
"""Query points evaluated at once (a (CHUNK, len(LEVELS)) array)."""


def to_levels(P, A, p_max=None) -> np.ndarray:
    """(K, L): the pressure at each of :data:`LEVELS` of curves A (K, m) (monotone in P, tabulated at P (m,),
    nondecreasing: a jump is two points at one pressure), along t = A + α P/p_max, A held flat beyond 0 and p_max
    (``p_max`` defaults to P's last; module doc)."""
    P = np.asarray(P, float)
    pm, a = float(P[-1] if p_max is None else p_max), LEVEL_SLOPE
    far = (1.0 + 1.0 / a) * pm
    Pe = np.concatenate([[P[0] - far], P, [pm + far]])
    out = np.empty((len(A), len(LEVELS)))
    for k, row in enumerate(np.asarray(A, float)):
        Ae = np.concatenate([[row[0]], row, [row[-1]]])
        out[k] = np.interp(LEVELS, Ae + a * Pe / pm, Pe)
    return out


def from_levels(P, rows, x) -> np.ndarray:
    """A/S (K, n) at pressures x (K or 1, n) off rows (K, L) of pressures at :data:`LEVELS` (made monotone first):
    the level t where the row reaches x, less α x/p_max."""
    pm = float(np.asarray(P, float)[-1])
    rows = np.maximum.accumulate(np.asarray(rows, float), axis=1)
    x = np.broadcast_to(np.asarray(x, float), (rows.shape[0], np.shape(x)[-1]))
    out = np.empty(x.shape)
    L = len(LEVELS)
    for j in range(x.shape[1]):
        xj = x[:, j:j + 1]
        i = np.clip((rows <= xj).sum(axis=1) - 1, 0, L - 2)
        r = np.arange(rows.shape[0])
        p0, p1 = rows[r, i], rows[r, i + 1]
        w = np.clip(np.where(p1 > p0, (x[:, j] - p0) / np.where(p1 > p0, p1 - p0, 1.0), 1.0), 0.0, 1.0)
        t = LEVELS[i] * (1 - w) + LEVELS[i + 1] * w
        out[:, j] = t - LEVEL_SLOPE * x[:, j] / pm
    return out


def _interp_rows(xp, Y, x):
    """Row-wise linear interpolation: Y (K, m) tabulated at xp (m,), evaluated at x (K or 1, n); clamped."""
    x = np.broadcast_to(x, (Y.shape[0], x.shape[1]))
    i = np.clip(np.searchsorted(xp, x) - 1, 0, len(xp) - 2)
    x0, x1 = xp[i], xp[i + 1]
    w = np.clip((x - x0) / (x1 - x0), 0.0, 1.0)
    rows = np.arange(Y.shape[0])[:, None]
    return Y[rows, i] * (1 - w) + Y[rows, i + 1] * w


def grid_points(lo, hi, n) -> np.ndarray:
    return np.array([0.5 * (lo + hi)]) if n <= 1 or hi <= lo else np.linspace(lo, hi, n)


def same(a, b) -> bool:
    return abs(a - b) < 1e-9 * max(1.0, abs(a), abs(b))


def nice_up(x: float) -> float:
    """x rounded up to 1, 2, 2.5 or 5 × a power of ten."""
    e = 10 ** math.floor(math.log10(x))
    for m in (1, 2, 2.5, 5, 10):
        if m * e >= x * (1 - 1e-12):
            return m * e
    return 10 * e
