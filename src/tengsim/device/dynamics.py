"""Dynamic TENG model, Eqs. (13)-(24), solved in the dimensionless form of Eq. (24).

State in flight: ybar = y/d0, vbar = dybar/dtbar, Qbar = Q/(S sigma), plus four running energies
(work of the applied force, work of the electrostatic force, heat in R, heat in the damper), all in
units of k_e d0^2. Time tbar = t / sqrt(M/k_e).

Rules the paper leaves open (see docs/device.md):

* Impact (gap reaches 0 with ydot > 0): perfectly inelastic; ydot -> 0, the kinetic energy
  1/2 M ydot^2 is booked as impact loss. The plate then stays at y = d0.
* In contact: the plate does not move (F_e plays no role, as the paper says after Eq. 22); Q relaxes
  through R with V = -Q T/(eps_r eps0 S) (Eq. 22), solved exactly. Release when the force the
  plate would feel at y = d0, P_a S - k_e d0 + F_e, turns negative (the reaction would have to pull).
* Charged area: while in contact A follows A(P); the polymer keeps its charge, so in flight A is
  the largest area reached so far ("max") or the area at release ("release").  An area that carries its own
  history (:class:`tengsim.device.params.AreaCycle`, a viscoelastic contact's cycle) is read at the time, not
  the pressure, and in flight is the largest area of the press just ended (the area it charged; the square
  press's at its release, where the held contact has crept to): no ``area_memory`` rule.
"""
from __future__ import annotations

import math
import sys
import time

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from tengsim.device.field import bar_field
from tengsim.device.params import DeviceParams, SolverOptions
from tengsim.device.result import DeviceResult
from tengsim.errors import finite, positive, require

_NSTATE = 7  # y, v, Q, W_applied, W_electric, E_load, E_damping


class _Core:
    """Dimensionless right-hand side of Eq. (24) for one device and waveform."""

    def __init__(self, p: DeviceParams, waveform):
        self.p = p
        self.wf = waveform
        self.tau = p.time_scale
        self.history = p.area.carries_history  # an area with its own history: read by time, no area_memory
        self.pscale = p.area_m2 / (p.gap_m * p.stiffness_N_per_m)  # Pbar = P_a S/(d0 k_e)
        self.g2 = p.gamma2
        self.g3 = p.gamma3
        self.kappa = p.kappa
        self.two_zeta = 2.0 * p.damping_ratio
        self.mode = p.load_mode
        self.reg = p.eq20_reg
        self.fld = bar_field(p)  # C(x), v(x), u(x) of the field model (parallel: g3 + xb, xb, xb)
        self.cinv0 = float(self.fld.cinv(0.0))  # eps0 S/(d0 C) in contact (parallel: g3)
        self.g1 = 0.0  # area fraction, set per phase
        self.t_lo, self.t_hi = 0.0, math.inf  # inside of the current smooth segment (tbar)

    def pbar(self, tb):
        """Pbar at tbar, clipped into the current segment so a jump is never seen from the wrong side."""
        return self.pscale * self.wf(np.clip(tb, self.t_lo, self.t_hi) * self.tau)

    def force(self, y, q, g1):
        """Fbar_e toward the polymer."""
        fm = self.p.force_model
        if fm == "field":
            if self.p.field == "finite":  # dU/dx at fixed charge, U = kappa/2 (q^2 cinv - 2 q g1 voc + g1^2 usig)
                f, xb = self.fld, 1.0 - y
                return 0.5 * self.kappa * (q * q * f.cinv(xb, 1) - 2.0 * q * g1 * f.voc(xb, 1)
                                           + g1 * g1 * f.usig(xb, 1))
            return 0.5 * self.kappa * (g1 - q) ** 2
        if fm == "eq20":
            return 0.5 * g1 * self.kappa * ((g1 - q) ** 2 - (q * self.g3 / (1.0 - y + self.reg)) ** 2)
        return 0.0 * q

    def vbar(self, y, q, g1):
        """V / (sigma d0/eps0), Eq. (14) (finite field: -q cinv + g1 voc)."""
        if self.p.field == "finite":
            return -q * self.fld.cinv(1.0 - y) + g1 * self.fld.voc(1.0 - y)
        return -q * (self.g3 + 1.0 - y) + g1 * (1.0 - y)

    def rhs(self, tb, s):
        y, v, q = s[0], s[1], s[2]
        g1 = self.g1
        pa = self.pbar(tb)
        fe = self.force(y, q, g1)
        dv = pa - y - self.two_zeta * v + fe
        if self.mode == "finite":
            vb = self.vbar(y, q, g1)
            dq = self.g2 * vb
            de = self.g2 * self.kappa * vb * vb
        elif self.mode == "short" and self.p.field == "finite":  # Q = g1 voc/cinv along the travel
            f, xb = self.fld, 1.0 - y
            ci = f.cinv(xb)
            dq = -g1 * (f.voc(xb, 1) * ci - f.voc(xb) * f.cinv(xb, 1)) / ci ** 2 * v
            de = 0.0
        elif self.mode == "short":
            dq = -g1 * self.g3 * v / (self.g3 + 1.0 - y) ** 2  # Eq. (19)
            de = 0.0
        else:
            dq = 0.0
            de = 0.0
        return np.array([v, dv, dq, pa * v, fe * v, de, self.two_zeta * v * v])

    def impact(self, tb, s):
        return s[0] - 1.0

    impact.terminal = True
    impact.direction = 1.0


def _area_fraction(core: _Core, tb):
    """A/S demanded by the pressure at tbar (in contact), per ``area_pressure``; an area that carries its own
    history: its value at that time."""
    p = core.p
    if core.history:
        return p.area.at_time(np.asarray(tb) * core.tau)
    pa = core.pbar(np.asarray(tb)) / core.pscale
    if p.area_pressure == "contact":
        pa = np.maximum(pa - p.stiffness_N_per_m * p.gap_m / p.area_m2, 0.0)
    return p.area(pa)


def simulate(params: DeviceParams, waveform, t_end: float, *, dt_out: float | None = None,
             options: SolverOptions | None = None, progress: bool = False,
             q0_C: float | None = None, area0: float | None = None) -> DeviceResult:
    """Integrate Eqs. (13)-(22) from rest (y = 0) over [0, t_end] s; returns a :class:`DeviceResult`.

    Output rows: a uniform grid of step ``dt_out`` (default 2e-5 s) plus the instant just before
    each impact, so that impact peaks are not missed. ``q0_C`` overrides ``params.initial_charge``;
    ``area0`` the charged-area fraction A/S held at the start (default ``params.area.initial_fraction``:
    with ``area_memory = 'max'`` a run that goes on from another's end starts from the area it reached).
    """
    require(isinstance(params, DeviceParams), f"params must be DeviceParams, got {type(params).__name__}")
    t_end = positive("t_end", t_end)
    dt_out = positive("dt_out", 2e-5 if dt_out is None else dt_out)
    require(t_end / dt_out <= 5e6, f"t_end / dt_out = {t_end / dt_out:.3g} output rows is too many")
    opts = options or SolverOptions()
    core = _Core(params, waveform)
    tau = core.tau
    tb_end = t_end / tau
    n_grid = int(math.floor(t_end / dt_out + 1e-9)) + 1
    grid = np.arange(n_grid) * dt_out / tau
    bps = np.asarray(waveform.breakpoints(0.0, t_end), dtype=float) / tau
    edges = np.concatenate([[0.0], bps[(bps > 0) & (bps < tb_end)], [tb_end]])

    g1 = params.area.initial_fraction if area0 is None else finite("area0", area0)
    require(0.0 <= g1 <= 1.0, f"area0 must be a fraction A/S in [0, 1], got {g1!r}")
    s = np.zeros(_NSTATE)
    if params.initial_charge == "rest" or params.load_mode == "short":
        s[2] = g1 * float(core.fld.voc(1.0)) / float(core.fld.cinv(1.0))  # Q_SC at the rest gap: V = 0
    if q0_C is not None and params.load_mode != "short":
        s[2] = finite("q0_C", q0_C) / params.charge_scale
    contact = released = False
    e_impact = 0.0
    rows_t, rows_s, rows_c, rows_g, rows_ei = [], [], [], [], []
    impacts, releases = [], []
    nfev = 0
    wall0 = time.perf_counter()
    eps_t = 1e-12 * max(tb_end, 1.0)
    last_report = wall0

    def emit(tbs, states, is_contact, g1s, ei):
        rows_t.append(np.atleast_1d(tbs))
        rows_s.append(np.array(np.atleast_2d(states), dtype=float))  # copy: s is reused
        rows_c.append(np.full(np.size(tbs), is_contact))
        rows_g.append(np.broadcast_to(g1s, np.shape(np.atleast_1d(tbs))).astype(float))
        rows_ei.append(np.full(np.size(tbs), ei))

    def grid_in(a, b):
        i0, i1 = np.searchsorted(grid, [a, b], side="left")
        return grid[i0:i1]

    for a, b in zip(edges[:-1], edges[1:]):
        core.t_lo, core.t_hi = a + 1e-9 * (b - a), b - 1e-9 * (b - a)
        switches = 0
        while a < b - eps_t:
            switches += 1
            require(switches < 10000, f"contact chatter near t = {a * tau:.6g} s (over 10000 switches)")
            net = core.pbar(a) - 1.0 + core.force(1.0, s[2], g1)  # net pull toward the polymer at y = d0
            if not contact and not released and s[0] >= 1.0 - 1e-12 and (s[1] > 0 or net > 0):
                if s[1] > 0:  # impact at a segment boundary
                    e_impact += 0.5 * s[1] ** 2
                    impacts.append(a * tau)
                contact, s[0], s[1] = True, 1.0, 0.0
            if contact:
                if net < 0:  # the reaction would have to pull: release now
                    contact, released = False, True
                    releases.append(a * tau)
                    continue
                lam = 0.0 if core.mode == "open" else (math.inf if core.mode == "short" else core.g2 * core.cinv0)
                q_in = _contact_charge(s[2], lam, a)

                def pull(x):
                    return core.pbar(x) - 1.0 + core.force(1.0, q_in(x), g1)

                t_rel = b
                tt = np.linspace(a, b, 65)
                neg = np.nonzero(pull(tt) < 0)[0]
                if neg.size:
                    j = neg[0]
                    t_rel = brentq(pull, tt[j - 1], tt[j], xtol=1e-14)
                tg = grid_in(a, t_rel)
                q0, e0 = s[2], s[5]
                decay = np.exp(-lam * (tg - a)) if lam < math.inf else np.zeros_like(tg)
                st = np.tile(s, (tg.size, 1))
                st[:, 2] = q0 * decay
                if core.mode == "finite":
                    st[:, 5] = e0 + 0.5 * core.kappa * core.cinv0 * q0 ** 2 * (1 - decay ** 2)
                if tg.size:
                    demand = _area_fraction(core, tg)
                    gs = (np.maximum.accumulate(np.maximum(demand, g1)) if params.area_memory == "max"
                          and not core.history else demand)
                    emit(tg, st, True, gs, e_impact)
                dec = math.exp(-lam * (t_rel - a)) if lam < math.inf else 0.0
                if core.mode == "finite":
                    s[5] = e0 + 0.5 * core.kappa * core.cinv0 * q0 ** 2 * (1 - dec ** 2)
                s[2] = q0 * dec
                g1 = _contact_area(core, g1, a, t_rel)
                if t_rel < b - eps_t:
                    contact, released = False, True
                    releases.append(t_rel * tau)
                a = t_rel
                continue
            # flight
            released = False
            core.g1 = g1
            tg = grid_in(a, b)
            sol = solve_ivp(core.rhs, (a, b), s, method=opts.method, t_eval=np.append(tg, b),
                            events=core.impact, rtol=opts.rtol, atol=opts.atol, max_step=opts.max_step / tau)
            require(sol.status >= 0, f"integrator failed at t = {a * tau:.6g} s: {sol.message}")
            nfev += sol.nfev
            # an event before the first output time leaves sol.t and sol.y as empty lists (scipy)
            ts = np.asarray(sol.t, dtype=float)
            ys = np.asarray(sol.y, dtype=float).reshape(len(s), ts.size)
            keep = ts < b - eps_t
            emit(ts[keep], ys.T[keep], False, g1, e_impact)
            if sol.status == 1 and sol.t_events[0].size:
                te = float(sol.t_events[0][0])
                se = sol.y_events[0][0].copy()
                if not np.any(keep) or te > ts[keep][-1] + eps_t:
                    emit(te, se, False, g1, e_impact)  # pre-impact row keeps the peak
                e_impact += 0.5 * max(se[1], 0.0) ** 2
                impacts.append(te * tau)
                s = se
                s[0], s[1] = 1.0, 0.0
                contact = True
                a = te
            else:
                s = ys[:, -1].copy()
                a = b
            if progress and time.perf_counter() - last_report > 1.0:
                last_report = time.perf_counter()
                print(f"tengsim device: t = {a * tau:.4g} / {t_end:.4g} s", file=sys.stderr, flush=True)
    # final grid point at t_end
    if grid[-1] >= tb_end - eps_t and (not rows_t or rows_t[-1].size == 0 or rows_t[-1][-1] < grid[-1] - eps_t):
        emit(grid[-1], s, contact, g1, e_impact)
    if progress:
        print(f"tengsim device: done, {len(impacts)} impacts, {time.perf_counter() - wall0:.2f} s",
              file=sys.stderr, flush=True)
    tb = np.concatenate(rows_t)
    st = np.concatenate(rows_s)
    order = np.argsort(tb, kind="stable")
    return DeviceResult.from_core(
        params=params, waveform=waveform, options=opts, tbar=tb[order], state=st[order],
        contact=np.concatenate(rows_c)[order], area_fraction=np.concatenate(rows_g)[order],
        impact_energy=np.concatenate(rows_ei)[order], impacts=np.array(impacts), releases=np.array(releases),
        nfev=nfev, wall_s=time.perf_counter() - wall0)


def _contact_charge(q0: float, lam: float, a: float):
    """Qbar(tbar) in contact: exact decay through R with V = -Q T/(eps_r eps0 S) (Eq. 22)."""
    if lam == math.inf:
        return lambda x: 0.0 * np.asarray(x)
    return lambda x: q0 * np.exp(-lam * (np.asarray(x) - a))


def _contact_area(core: _Core, g1: float, a: float, b: float) -> float:
    """Charged-area fraction after a contact interval [a, b] (tbar), per ``area_memory`` (an area that carries
    its own history: the largest A/S of that press, :meth:`tengsim.device.params.AreaCycle.largest`)."""
    if core.history:
        return float(core.p.area.largest(a * core.tau, b * core.tau))
    tt = np.linspace(a, b, 33) if b > a else np.array([a])
    demand = _area_fraction(core, tt)
    if core.p.area_memory == "release":
        return float(demand[-1])
    return float(max(g1, demand.max()))
