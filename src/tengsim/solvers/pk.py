"""The constrained solver 'pk': Polonsky & Keer's (1999) constrained conjugate gradient on the contact
pressures for a hard wall, and its cohesive extension (Rey, Anciaux & Molinari, Comput. Mech. 2017) for
Maugis–Dugdale and exponential adhesion outside the contact.

Laws.  The solver solves the hard-wall limit of a law with a wall, the wall at g = 1 (h = 0), asking the law
for it (``law.hard_wall()``, a :class:`tengsim.laws.cohesive.CohesiveLimit`; its doc says what 'pk' reads), never
its class:

* no tension (``repulsive``, P = c g^-k, as its limit k → ∞): no pressure for g > 1, any pressure >= 0 at
  g = 1, no overlap g < 1 (a hard wall; the penalty law's own wall is soft on the scale ε, a few ε of
  compression at the loads of a Hertz check);
* a plateau (``md``, :class:`~tengsim.laws.MaugisDugdale`, as its limits wall_stiffness → ∞, smoothing → 0):
  the Dugdale tension σ0 wherever 1 <= g <= 1 + h0 (h0 = W/σ0, so the work of adhesion is the law's W),
  nothing beyond, and at g = 1 any pressure >= −σ0;
* a smooth traction (``exp``, :class:`~tengsim.laws.Exponential`, as its limit wall_stiffness → ∞: the
  attraction −(W/ρ) exp(−(g − 1)/ρ) for g >= 1; a plugin's smooth limit), any pressure >= t(0) at g = 1.

A law without a hard-wall limit (LJ93's smooth repulsion) or whose limit is none of these is refused with one
line naming the solvers that can ('fast', or 'homotopy' where the law is stiff at the pixel scale; 'ram').

Cohesive laws (Rey et al. 2017: the adhesive tractions outside the contact are a load of the
non-adhesive problem).  ``zone='inner'`` (the default of 'pk'; the Maugis–Dugdale ramp under displacement
control): the zone's tensions are set from the gap at every iteration of the contact's constrained solve, the
iterates Anderson-mixed (tengsim.solvers._pk_zone: its doc says how, and what it is converged to); where
that loop stalls (a set update cycling near a jump), the same loop unmixed, then the outer fixed point
below, and the message says so.  ``zone='outer'`` (and the sharp zone, the exponential law, load control: on
the sharp zone, whose pixels trap the contact's edge, the inner loop finds other metastable states): the
pressure is p = p_c + p_a, p_a the law's tension where the gap is within its range (the contact included:
−σ0 there), p_c >= 0 the contact pressure, solved by the constrained CG (tengsim.solvers._pk_core) with the
initial gap g0 − 1 + K p_a; the zone is then updated from the new gap and the contact solve repeated until
the zone no longer changes (the sharp Dugdale zone: a set of pixels), or, for a ramp, the gap moves by less
than ``tol`` and every gap is within ``tol`` of the law's graph (tengsim.solvers._pk_zone.zone_residual);
for a smooth traction (the exponential law) until the gap moves by less than ``tol`` (a damped fixed point; it converges where
the law is softer than a pixel, pixel snap number < 1, and says so when it does not).  The start state's gap
gives the first zone, so a path's warm starts keep its branch (jumps are the walker's).

Cost: two kernel convolutions an iteration of the contact solve and one FFT pair of its preconditioner
(tengsim.solvers._pk_core), one convolution to start it (none when a zone update goes on from the last
solve's K p_c), and one per zone update (K p_a); ``zone='inner'``: one convolution and one FFT pair an
iteration.  ``Equilibrium.n_conv`` counts the kernel's, ``iterations`` the contact solves' (or the inner
loop's) iterations.  The outer Maugis–Dugdale ramp: the sharp zone's solve first (loosely, to
``SHARP_TOL``: it jumps in few updates), then the ramp from it (Anderson-mixed, ``anderson`` differences).
The returned state is q = P = p, w = K p, H = g0 + w − 1 (load control: g0 moved by the approach's
correction, :meth:`PKSolver.solve_load`), H = 0 exactly on the contact (the hard wall's gap there; g0 + w − 1
is within the residual of it, of either sign, and a measure that asks g <= 1, the charged area of a law whose
peak tension starts at the wall, must not see that noise); ``residual`` is the hard-wall residual in ε (the
largest gap over the contact, overlap of the wall, move of the last zone update or distance from the law).
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace
from typing import ClassVar

import numpy as np

from tengsim import backend
from tengsim.errors import TengsimError
from tengsim.registry import SOLVERS
from tengsim.solvers._pk_core import Convolution, constrained_cg, preconditioner
from tengsim.solvers._pk_zone import zone_inner, zone_residual
from tengsim.solvers.mixing import Anderson as _Anderson
from tengsim.solvers.types import SOLVER_TOL, Equilibrium, Problem, State, check_settings

#: the largest pixel snap number of a Maugis–Dugdale ramp (PKSolver._ramp)
RAMP_SNAP = 0.5
#: zone updates of the ramp's polish after the sharp zone's solve (then the sharp state stands)
RAMP_UPDATES = 60
#: zone updates of the ramp from a warm start before the sharp zone is asked (0: always the sharp zone first)
RAMP_WARM = 0
#: the gap residual (ε) of the sharp zone's solve when it is only the ramp's start
SHARP_TOL = 1e-3
#: iterations without a new lowest residual after which the zone in the contact's loop stops, mixed and unmixed
ZONE_STALL = (10, 100)

def _solvable(lim) -> bool:
    """Is ``lim`` (a law's hard-wall limit, or None) one 'pk' solves: the wall alone, a plateau or smooth?"""
    return lim is not None and (not float(lim.tension) > 0 or lim.plateau or lim.smooth)


def limit_of(law, solver: str = "pk"):
    """The hard-wall limit of ``law`` (module doc), or one line naming the solvers that can solve it."""
    lim = law.hard_wall() if hasattr(law, "hard_wall") else None
    if _solvable(lim):
        return lim
    name = type(law).__name__
    if lim is None:
        raise TengsimError(f"solver '{solver}' solves hard walls only (laws repulsive, md, exp); law {name} has a "
                           "smooth repulsion: use solver 'fast' (or 'homotopy' for a law stiff at the pixel scale)")
    raise TengsimError(f"solver '{solver}' solves a hard-wall limit without adhesion, with a Dugdale zone or with a "
                       f"smooth traction; law {name}'s traction jumps: use solver 'ram'")


def supports(law) -> bool:
    """Can 'pk' solve ``law`` (its hard-wall limit)?"""
    return _solvable(law.hard_wall() if hasattr(law, "hard_wall") else None)


def _ramped(lim) -> bool:
    """A plateau whose step has a width (the zone's ramp): solved after the sharp zone's solve, or in the loop."""
    return lim.plateau and lim.smooth


def _traction(lim, u, out):
    """p_a = t(u) at the gaps above the wall u (in contact u <= 0: t(0)), into ``out``."""
    out[...] = lim.traction(u, backend.xp)
    return out


def _energy(lim, u) -> float:
    """ΣΦ over the pixels (W per pixel area) at gaps above the wall u (a plateau's ramp: as its sharp step's,
    O(ramp²))."""
    if not float(lim.tension) > 0:
        return 0.0
    if lim.plateau:
        lim = lim.with_ramp(0.0)
    return float(lim.energy(np.maximum(u, 0.0), backend.xp).sum())


@dataclass(frozen=True)
class Solved:
    """One contact or cohesive solve of :class:`PKSolver`: the pressure ``p``, ``Kp`` = K p, the gap above the
    wall ``u``, the load-control correction ``c`` (ε), the contact solves' iterations, whether it converged, its
    residual (ε), the cohesive-zone updates, its message and the contact mask."""

    p: np.ndarray
    Kp: np.ndarray
    u: np.ndarray
    c: float
    iterations: int
    converged: bool
    residual: float
    zones: int
    message: str
    contact: np.ndarray


@dataclass(frozen=True)
class PKSolver:
    """Polonsky–Keer constrained CG on the contact pressures, with Maugis–Dugdale / exponential cohesive
    zones (module doc).  ``tol``: the gap residual (ε); ``max_iter``: iterations of one contact solve;
    ``max_zone``: zone updates of a cohesive solve; ``monitor(iteration, residual)``: progress."""

    tol: float = SOLVER_TOL
    max_iter: int = 1000
    max_zone: int = 500
    precondition: bool = True
    md_zone: str = "ramp"
    anderson: int = 5
    zone: str = "inner"
    name: str = "pk"
    monitor: object = None
    monitor_every: int = 50
    weighted_block: ClassVar[bool] = False
    splits_over_mpi: ClassVar[bool] = False
    resumes_from_state: ClassVar[bool] = False

    def __post_init__(self):
        check_settings(self, ("max_iter", "max_zone", "monitor_every"))
        if self.md_zone not in ("ramp", "sharp"):
            raise TengsimError(f"md_zone must be 'ramp' or 'sharp', got {self.md_zone!r}")
        if self.zone not in ("inner", "outer"):
            raise TengsimError(f"zone must be 'inner' or 'outer', got {self.zone!r}")

    @staticmethod
    def _convolution(kernel, shape):
        """The convolution the solve calls (the JAX variant's: on its device)."""
        return Convolution(kernel, shape)

    @staticmethod
    def _core(*args, **kw):
        """The contact solve (tengsim.solvers._pk_core.constrained_cg; the JAX variant's: compiled)."""
        return constrained_cg(*args, **kw)

    @staticmethod
    def solves(law) -> bool:
        """Can this solver solve ``law`` (its hard-wall limit; module doc)?"""
        return supports(law)

    def solve(self, problem: Problem, start: State) -> Equilibrium:
        """The equilibrium at the problem's gap g0 (displacement control), from ``start``."""
        return self._solve(problem, start, None)[0]

    def solve_load(self, problem: Problem, mean_pressure: float, start: State | None = None):
        """Load control: the equilibrium whose mean pressure over the cell is ``mean_pressure`` (W/ε).
        Returns (equilibrium, dD): dD (ε) the rigid approach beyond the one in ``problem.g0`` that
        carries the load (the equilibrium's H includes it)."""
        if not math.isfinite(mean_pressure):
            raise TengsimError(f"mean_pressure must be finite, got {mean_pressure!r}")
        if start is None:
            start = State.zero(np.shape(problem.g0))
        eq, c = self._solve(problem, start, float(mean_pressure))
        return eq, -c                                 # the gap's correction c is an approach of −c

    # ---- the solve ---------------------------------------------------------------------------
    @staticmethod
    def _kii(conv, shape) -> float:
        """K_ii, a pixel's own compliance (ε per W/ε), by one convolution of a unit pixel at the cell's middle."""
        unit = backend.zeros(int(np.prod(shape)))
        i = np.ravel_multi_index(tuple(n // 2 for n in shape), shape)
        unit[i] = 1.0
        return float(conv(unit, backend.empty(unit.size))[i])

    @staticmethod
    def _ramp(lim, kii) -> float:
        """The zone's ramp (ε): the law's own step, widened where a pixel would be stiffer than it
        (pixel snap number 1.5 σ0 K_ii / ramp above ``RAMP_SNAP``)."""
        return max(float(lim.ramp), 1.5 * float(lim.tension) * kii / RAMP_SNAP)

    def _solve(self, problem: Problem, start: State, load):
        t0 = time.perf_counter()
        if problem.weights is not None:
            raise TengsimError(f"solver '{self.name}' does not solve weighted (mirror-block) problems; "
                               "use solver 'fast' for a mirror-symmetric cell")
        lim = limit_of(problem.law, self.name)
        shape = np.shape(problem.g0)
        conv = self._convolution(problem.kernel, shape)
        pre = preconditioner(problem.kernel, shape) if self.precondition else None
        if lim.plateau and float(lim.tension) > 0:      # md_zone: the step widened to the pixel, or sharp
            lim = lim.with_ramp(self._ramp(lim, self._kii(conv, shape)) if self.md_zone == "ramp" else 0.0)
        g0 = backend.xp.ascontiguousarray(problem.g0, dtype=float).ravel()
        q0 = backend.xp.asarray(start.q, dtype=float).ravel()
        w0 = backend.xp.asarray(start.w, dtype=float).ravel()
        h0 = g0 - 1.0
        K = problem.kernel
        if load is None and bool(getattr(K, "pinned_mean", getattr(K, "periodic", False))) and not h0.mean() > 0:
            # the mean gap of a periodic half-space is the mean of g0: at or below the wall no state exists
            msg = (f"the mean gap {h0.mean() + 1.0:.6g} ε is at or below the wall (1 ε) on a periodic half-space: "
                   "no state under displacement control; use load control (solve_load)")
            z = backend.zeros(shape)
            return Equilibrium(State(z, z.copy()), np.reshape(h0, shape).copy(), z.copy(), math.inf, False, 0, 0,
                               math.nan, time.perf_counter() - t0, msg), 0.0
        every = self.monitor_every
        mon = None if self.monitor is None else (
            lambda it, res: self.monitor(it, res, math.nan) if it % every == 0 else None)
        if not float(lim.tension) > 0:
            core = self._core(conv, h0, np.maximum(q0, 0.0), self.tol, self.max_iter, load, mon, pre)
            ok, res = core.converged, core.residual
            out = Solved(core.p, core.Kp, core.u, core.c, core.iterations, ok, res, 0,
                         "converged" if ok else f"not converged in {self.max_iter} iterations (residual {res:.3g} ε)",
                         core.p > 0)
        elif _ramped(lim) and self.zone == "inner" and load is None:
            out = self._zone_inner(lim, conv, h0, q0, w0, mon, pre)
        else:
            out = None
            if _ramped(lim) and RAMP_WARM and bool(np.any(q0)):   # warm: the ramp from the start, if quick
                warm = self._cohesive(lim, conv, h0, q0, w0, load, mon, pre, RAMP_WARM)
                out = warm if warm.converged else None
                spent = (warm.iterations, warm.zones) if out is None else (0, 0)
            else:
                spent = (0, 0)
            if out is None:
                out = self._ramp_after_sharp(lim, conv, h0, q0, w0, load, mon, pre)
            out = replace(out, iterations=out.iterations + spent[0], zones=out.zones + spent[1])
        p, w, c = out.p, out.Kp, out.c
        H = (g0 + c) + w - 1.0
        H[out.contact] = 0.0       # on the wall where it presses (the hard wall's u = 0; off by <= tol before)
        E = problem.dA * (0.5 * float(np.dot(p, w)) + _energy(lim, out.u))
        msg = out.message if out.zones == 0 else f"{out.message} ({out.zones} cohesive-zone updates)"
        eq = Equilibrium(State(p.reshape(shape), w.reshape(shape)), H.reshape(shape), p.reshape(shape).copy(),
                         float(out.residual), bool(out.converged), int(out.iterations), int(conv.count), E,
                         time.perf_counter() - t0, msg)
        return eq, float(c)

    def _zone_inner(self, lim, conv, h0, q0, w0, mon, pre) -> Solved:
        """The Maugis–Dugdale zone in the contact's loop (tengsim.solvers._pk_zone), from the start state's gap:
        mixed (``anderson``), then, where that stalls, unmixed from the same start, then the outer fixed point
        (the message says which)."""
        u0 = h0 + w0
        p0 = _traction(lim, np.maximum(u0, 0.0), backend.empty(h0.size))
        pc = np.maximum(q0 - p0, 0.0)
        pc[u0 > self.tol] = 0.0
        p0 += pc
        its, tried = 0, []
        for m, stall in ((self.anderson, ZONE_STALL[0]), (0, ZONE_STALL[1])):
            z = zone_inner(conv, h0, lim, p0.copy(), pc > 0, self.tol, self.max_iter, mon, pre, m, stall)
            its += z.iterations
            if z.converged:
                how = "zone in the contact's loop" + (", unmixed" if tried else "")
                return Solved(z.p, z.Kp, z.u, 0.0, its, True, z.residual, 0, f"converged ({how})", z.contact)
            tried.append(f"{z.iterations} iterations (residual {z.residual:.3g} ε, {z.changes} set changes)")
            if not m:
                break
        out = self._ramp_after_sharp(lim, conv, h0, q0, w0, None, mon, pre)
        why = f"{out.message} (outer fixed point: the zone in the contact's loop did not settle in {' + '.join(tried)})"
        return replace(out, iterations=out.iterations + its, message=why)

    def _ramp_after_sharp(self, lim, conv, h0, q0, w0, load, mon, pre) -> Solved:
        """A cohesive solve; with a ramp (a plateau's step), the sharp zone's solve first (it jumps in few
        updates) as its start, and the sharp state if the ramp does not settle in RAMP_UPDATES updates."""
        if not _ramped(lim):
            return self._cohesive(lim, conv, h0, q0, w0, load, mon, pre, self.max_zone)
        its = zones = 0
        sharp = self._cohesive(lim.with_ramp(0.0), conv, h0, q0, w0, load, mon, pre, self.max_zone,
                               max(self.tol, SHARP_TOL))     # only a start: loosely
        if sharp.converged:
            q0, w0, its, zones = sharp.p, sharp.Kp, sharp.iterations, sharp.zones
        out = self._cohesive(lim, conv, h0, q0, w0, load, mon, pre,
                             RAMP_UPDATES if sharp.converged else self.max_zone)
        its, zones = its + out.iterations, zones + out.zones
        if not out.converged and sharp.converged:  # the ramp's fixed point cycles: the sharp zone's state, to tol
            out = self._cohesive(lim.with_ramp(0.0), conv, h0, sharp.p, sharp.Kp, load, mon, pre, self.max_zone)
            its, zones = its + out.iterations, zones + out.zones
            out = replace(out, message=f"{out.message} (sharp Dugdale zone: the ramp did not settle in "
                                       f"{RAMP_UPDATES} updates)")
        return replace(out, iterations=its, zones=zones)

    def _cohesive(self, lim, conv, h0, q0, w0, load, mon, pre, limit, tol=None) -> Solved:
        """The outer fixed point (module doc): the contact solved with the zone's tractions p_a as a load, the
        zone updated from the new gap, until it no longer changes (a sharp step) or the gap stops moving."""
        tol = self.tol if tol is None else tol
        n = h0.size
        s0 = lim.tension
        sharp = not lim.smooth                        # a zone that is a set of pixels: until it no longer changes
        Ka, pa, pa_new, hh, u_prev, used = (backend.empty(n) for _ in range(6))
        # the first zone from the start state's gap; its contact pressure from its pressure
        _traction(lim, h0 + w0, pa)
        pc = np.maximum(q0 - pa, 0.0)
        pc[(h0 + w0) > tol] = 0.0
        last_move = math.inf
        its, zones, ok, res, c = 0, 0, False, math.inf, 0.0
        core = None
        mix = None if sharp else _Anderson(n, self.anderson)
        for zones in range(1, limit + 1):
            used[:] = pa                              # the zone this contact solve carries
            conv(used, Ka)
            np.add(h0, Ka, out=hh)
            core_load = None if load is None else load - float(pa.mean())
            if core_load is not None and not core_load > 0:
                raise TengsimError(f"load control needs a compressive contact: the mean pressure {load:.6g} W/ε "
                                   f"is below the cohesive zone's tension {float(pa.mean()):.6g} W/ε")
            # the contact solve to a tolerance the zone's last move allows (inexact early updates)
            tol_in = tol if sharp else max(tol, min(1e-2 * last_move, 1e-2))
            core = self._core(conv, hh, pc, tol_in, self.max_iter, core_load, mon, pre,
                                  None if core is None else core.Kp)   # K p_c: the last solve's
            its += core.iterations
            pc, u, c = core.p, core.u, core.c
            if not core.converged:
                res = core.residual
                break
            _traction(lim, u, pa_new)
            pa_new[pc > 0] = -s0
            if sharp:
                moved = int(np.count_nonzero(pa_new != pa))
                res = core.residual
                if moved == 0:
                    ok = True
                    break
                pa[:] = pa_new
            else:
                move = float(np.max(np.abs(u - u_prev))) if zones > 1 else math.inf
                u_prev[:] = u
                res = max(core.residual, move if math.isfinite(move) else 0.0)
                if zones > 1 and move <= tol and tol_in <= tol:
                    if not lim.plateau:
                        ok = True
                        break
                    # two updates can agree on a zone that is not the law's (Anderson's clipped iterates): the
                    # state is judged by its gaps against the law's graph (tengsim.solvers._pk_zone), as the CG's is
                    law = zone_residual(lim, u, pc + used, pc > 0, backend.empty(n))
                    res = max(res, law)
                    if law <= tol:
                        ok = True
                        break
                last_move = move
                mix.step(pa, pa_new)                  # pa <- the next zone (Anderson-mixed fixed point)
                np.clip(pa, -s0, 0.0, out=pa)
        p = pc + used
        # K p = K p_c + K p_a (the last zone's K p_a is in Ka: the core's Kp is K p_c)
        Kp = core.Kp + Ka
        if ok:
            msg = "converged"
        elif core is not None and not core.converged:
            msg = f"contact solve not converged in {self.max_iter} iterations (residual {res:.3g} ε)"
        else:
            msg = f"cohesive zone not settled in {limit} updates (last move {res:.3g} ε)"
        return Solved(p, Kp, u, c, its, ok, res, zones, msg, pc > 0)


@dataclass(frozen=True)
class PKJaxSolver(PKSolver):
    """:class:`PKSolver` with its contact solve (the active set and the CG) compiled with JAX as one loop
    (tengsim.solvers._pk_jax), float64, on ``device`` ('auto': JAX's default, 'cpu' or 'gpu'); the cohesive
    zone's updates stay on the host.  The same states as 'pk' to round-off (tests/test_pk_jax.py)."""

    device: str = "auto"
    zone: str = "outer"
    name: str = "pk-jax"
    compiles: ClassVar[bool] = True

    def __post_init__(self):
        super().__post_init__()
        from tengsim.solvers.jax_fast import DEVICES, find_device

        if self.device not in DEVICES:
            raise TengsimError(f"device must be one of {', '.join(DEVICES)}, got {self.device!r}")
        find_device(self.device)          # the one-line error (no JAX, no GPU) before a run writes anything
        if self.zone != "outer":
            raise TengsimError(f"solver '{self.name}' updates a cohesive zone by the outer fixed point only "
                               f"(zone 'outer'), got zone {self.zone!r}; use solver 'pk' for zone 'inner'")

    def _convolution(self, kernel, shape):
        from tengsim.solvers._pk_jax import JaxConvolution

        return JaxConvolution(kernel, shape, self.device)

    @staticmethod
    def _core(*args, **kw):
        from tengsim.solvers._pk_jax import constrained_cg as jax_cg

        return jax_cg(*args, **kw)


SOLVERS.register("pk", PKSolver, summary="Polonsky–Keer constrained CG: hard wall, Maugis–Dugdale, exponential")
SOLVERS.register("pk-jax", PKJaxSolver, summary="the 'pk' solver's contact solve compiled with JAX (float64)")
