"""The time-stepping drive: each step one elastic equilibrium of the existing kind (any law, kernel, film and
solver) at the material's instantaneous modulus, with the history's displacement offset added to the gap
(:mod:`tengsim.visco.memory`, docs/viscoelastic.md).

* displacement control (``History.kind == 'approach'``): one equilibrium per step at D(t);
* load control ('pressure'): the D of each step is the root of p̄(D) = p̄(t) (the solver's own ``solve_load``
  where it has one, else a bracketed regula falsi on D, each trial a warm-started equilibrium with the
  same memory); the memory advances once, with the root.

A step whose gap changes by more than ``jump_h`` beyond the rigid shift (the walker's jump test) is bisected
in time down to ``dt_min``: a snap-in or a pull-off is located in time to that resolution and marked.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tengsim.analysis import apex_index, summarize
from tengsim.continuation.walker import jumped, persist
from tengsim.errors import TengsimError
from tengsim.relaxation import Prony
from tengsim.solvers import Problem, State
from tengsim.visco.history import History
from tengsim.visco.memory import MaxwellMemory, StepOperator
from tengsim.visco.result import COLUMNS, TimeResult

MAX_ROOT = 60  # regula-falsi steps of one load-controlled step


@dataclass(frozen=True)
class DriveEnd:
    """Where a run ended: the material's ``memory``, the solver's last ``state`` (a warm start), the kernel's
    coupling ratio E_ref/E_eff of its last step and the approach ``D`` (ε): what a run that goes on from it needs."""

    memory: MaxwellMemory
    state: State | None
    ratio: float
    D: float


class TimeDrive:
    """Runs ``history`` on the gap ``U0`` (ε) with ``law``, ``solver`` and the kernels ``make_kernel(coupling)``
    around the reference coupling ``coupling`` (the static run's κ, at the modulus ``E_ref``, Pa; default E∞).

    ``steps``: a time-step control (``times(t0, t1)``, :mod:`tengsim.visco.history`).  ``dt_min`` (s): the
    time resolution of a located jump (default: a 64th of the first step).  ``maps_at``: times (s) whose
    (P, H) maps are kept (the step nearest each)."""

    def __init__(self, U0, law, make_kernel, coupling: float, solver, material: Prony, E_ref: float | None = None,
                 jump_h: float = 0.3, dt_min: float | None = None, d_step: float = 0.5, p_tol: float = 1e-6,
                 maps_at=()):
        self.U0, self.law, self.make_kernel, self.solver, self.material = U0, law, make_kernel, solver, material
        self.coupling = float(coupling)
        self.E_ref = float(material.E_inf if E_ref is None else E_ref)
        if not self.E_ref > 0:
            raise TengsimError(f"E_ref must be > 0, got {E_ref!r} Pa")
        self.jump_h, self.dt_min, self.d_step, self.p_tol = jump_h, dt_min, float(d_step), float(p_tol)
        self.maps_at = tuple(float(t) for t in maps_at)
        self._kernels: dict = {}
        self.grid = None
        self.apex = apex_index(U0)

    # ---- pieces -------------------------------------------------------------------------------------------
    def kernel(self, ratio: float):
        """The kernel at the coupling κ_ref · E_ref/E_eff (built once per distinct step modulus)."""
        key = round(ratio, 12)
        if key not in self._kernels:
            self._kernels[key] = self.make_kernel(self.coupling * ratio)
            self.grid = self._kernels[key].grid
        return self._kernels[key]

    def _solve(self, g0, kernel, start):
        problem = Problem(g0, self.law, kernel)
        eq = self.solver.solve(problem, start)
        if not eq.converged:
            eq = persist(self.solver, problem, eq)
        return eq

    def _start(self, state: State | None, ratio_from: float, ratio_to: float) -> State:
        if state is None:
            return State.zero(self.U0.shape)
        return State(state.q.copy(), state.w * (ratio_to / ratio_from))  # K ∝ κ: w = K q rescaled

    @staticmethod
    def mean_pressure(eq) -> float:
        """The mean of P over the cell (W/ε): the load-controlled quantity."""
        return float(np.mean(eq.P))

    # ---- one step -------------------------------------------------------------------------------------------
    def step(self, mem, state, ratio_prev, D_prev, dt, kind, target):
        """(mem, state, ratio, D, eq, n_conv): one step of length dt (s) to the control ``target``."""
        op = StepOperator(self.material, self.E_ref, dt)
        kern = self.kernel(op.ratio)
        u_h = op.offset(mem)
        base = self.U0 + 1.0 + u_h
        start = self._start(state, ratio_prev, op.ratio)
        if kind == "approach":
            D = float(target)
            eq = self._solve(base - D, kern, start)
            spent = int(eq.n_conv)
        else:
            D, eq, spent = self._load(base, kern, start, D_prev, float(target))
        w_tot = eq.state.w + u_h
        return op.update(mem, w_tot), eq.state, op.ratio, D, eq, spent, op.E_eff

    def _load(self, base, kern, start, D0, target):
        """(D, eq, convolutions): the equilibrium whose mean pressure is ``target``, near D0."""
        if hasattr(self.solver, "solve_load"):
            eq, dD = self.solver.solve_load(Problem(base - D0, self.law, kern), target, start)
            return D0 + float(dD), eq, int(eq.n_conv)
        spent = 0
        tol = self.p_tol * max(abs(target), 1e-3)

        def f(D, st):
            nonlocal spent
            eq = self._solve(base - D, kern, st)
            spent += int(eq.n_conv)
            return self.mean_pressure(eq) - target, eq

        fa, eqa = f(D0, start)
        if abs(fa) <= tol:
            return D0, eqa, spent
        s = 1.0 if fa < 0 else -1.0
        h = self.d_step
        Da, Db = D0, D0 + s * h
        fb, eqb = f(Db, eqa.state)
        while fa * fb > 0:  # march, then widen, until the load is bracketed
            Da, fa, eqa = Db, fb, eqb
            h *= 2
            Db = Da + s * h
            fb, eqb = f(Db, eqa.state)
            if s < 0 and abs(fb + target) <= tol:  # pulled out of reach: separated, no state carries the load
                return Db, eqb, spent
            if h > 1e6:
                raise TengsimError(f"load control: no approach carries the mean pressure {target:g} W/ε")
        side = 0
        for _ in range(MAX_ROOT):  # Illinois regula falsi
            Dc = (Da * fb - Db * fa) / (fb - fa)
            near = eqa if abs(Dc - Da) < abs(Dc - Db) else eqb
            fc, eqc = f(Dc, near.state)
            if abs(fc) <= tol:
                return Dc, eqc, spent
            if fc * fb < 0:
                Da, fa, eqa = Db, fb, eqb
                side = 0
            else:
                fa = fa / 2 if side == -1 else fa
                side = -1
            Db, fb, eqb = Dc, fc, eqc
        return Db, eqb, spent

    # ---- the run ----------------------------------------------------------------------------------------------
    def run(self, history: History, steps, start_D: float | None = None) -> TimeResult:
        """The run of ``history`` with the step control ``steps``; the surface at rest before the first time."""
        return self.run_from(history, steps, start_D=start_D)[0]

    def run_from(self, history: History, steps, start: DriveEnd | None = None,
                 start_D: float | None = None) -> tuple:
        """(TimeResult, DriveEnd): the run of ``history`` from ``start`` (the :class:`DriveEnd` of an earlier run:
        its memory, warm start and approach; None: the surface at rest), and where it ended.  The first point is
        the instantaneous step from the start's memory to the control at the history's first time (from a
        memory that run ended with at that control, the same state again)."""
        kind = history.kind
        if start is None:
            mem = MaxwellMemory.rest(self.U0.shape, self.material.branches)
            state, ratio = None, 1.0
            D = float(history.value[0]) if kind == "approach" else (float(start_D) if start_D is not None
                                                                     else float(self.U0.min()) - 2.0)
        else:
            mem, state, ratio = start.memory, start.state, start.ratio
            D = float(history.value[0]) if kind == "approach" else float(start.D)
        rows, maps = [], {}
        t0 = float(history.t[0])
        # the first point: the surface at rest meets the control at t0 (an instantaneous step)
        mem, state, ratio, D, eq, n, E_eff = self.step(mem, state, ratio, D, 0.0, kind, history.value[0])
        rows.append(self._row(t0, D, eq, n, E_eff, False))
        self._keep(maps, t0, eq)
        dt_min = self.dt_min
        for k in range(len(history.t) - 1):
            ta, tb = float(history.t[k]), float(history.t[k + 1])
            if tb == ta:
                times = [tb]
            else:
                times = list(steps.times(ta, tb))
                if dt_min is None:
                    dt_min = (times[0] - ta) / 64
            t_prev = ta
            va, vb = float(history.value[k]), float(history.value[k + 1])
            for tb_ in times:  # the control linear on this segment (a jump at its end belongs to the next one)
                value_at = ((lambda s, vb=vb: vb) if tb == ta else
                            (lambda s, ta=ta, tb=tb, va=va, vb=vb: va + (s - ta) / (tb - ta) * (vb - va)))
                out = self._advance(mem, state, ratio, D, eq, t_prev, float(tb_), kind, value_at,
                                    dt_min or 0.0, rows, maps)
                mem, state, ratio, D, eq = out
                t_prev = float(tb_)
        t = np.array([r[0] for r in rows])
        cols = {name: np.array([r[1][name] for r in rows]) for name in COLUMNS}
        params = {**self.material.params(), **history.params(), **getattr(steps, "params", dict)(),
                  "E_ref_Pa": self.E_ref, "coupling_ref": self.coupling, "jump_h": self.jump_h,
                  "dt_min_s": dt_min or 0.0, "solver": getattr(self.solver, "name", ""),
                  **getattr(self.law, "params", dict)()}
        res = TimeResult(t, cols, np.array([r[2] for r in rows]), np.array([r[3] for r in rows]), params, maps)
        return res, DriveEnd(mem, state, ratio, D)

    def _advance(self, mem, state, ratio, D, eq, ta, tb, kind, value_at, dt_min, rows, maps, depth=0):
        """The step ta → tb, bisected at a jump down to dt_min; rows appended; returns the new (mem, state, ratio, D, eq)."""
        out = self.step(mem, state, ratio, D, tb - ta, kind, value_at(tb))
        mem_b, state_b, ratio_b, D_b, eq_b, n, E_eff = out
        jump = jumped(eq, eq_b, D_b - D, self.jump_h)
        if jump and (tb - ta) > 2 * dt_min and depth < 30:
            tm = 0.5 * (ta + tb)
            mid = self._advance(mem, state, ratio, D, eq, ta, tm, kind, value_at, dt_min, rows, maps, depth + 1)
            return self._advance(*mid, tm, tb, kind, value_at, dt_min, rows, maps, depth + 1)
        rows.append(self._row(tb, D_b, eq_b, n, E_eff, jump))
        self._keep(maps, tb, eq_b)
        return mem_b, state_b, ratio_b, D_b, eq_b

    def _row(self, t, D, eq, n, E_eff, jump):
        s = summarize(eq.P, eq.H, self.grid, self.apex, self.law, bool(getattr(self._any_kernel(), "periodic", False)))
        vals = {"D": D, "F": s.F, "mean_pressure": self.mean_pressure(eq),
                "area_fraction": s.charged_fraction, "area_repulsive": s.area_repulsive,
                "contact_length": s.contact_length, "min_gap": s.min_gap, "E_eff": E_eff,
                "residual": eq.residual, "n_conv": n}
        return (t, vals, bool(jump), bool(eq.converged))

    def _any_kernel(self):
        return next(iter(self._kernels.values()))

    def _keep(self, maps, t, eq):
        for tm in self.maps_at:
            best = maps.get(tm)
            if best is None or abs(t - tm) < abs(best[0] - tm):
                maps[tm] = (t, eq.P.copy(), eq.H.copy())
