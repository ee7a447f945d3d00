"""The fast solver's loop, traced by JAX: one ``lax.while_loop`` over L-BFGS iterations (tengsim.solvers.jax_fast).

Step for step the algorithm of :class:`tengsim.solvers.FastSolver` (read its docstrings for the why):
compact-form L-BFGS in the K metric with memory m, the rows s, y stored beside their images K s, K y
(tengsim.solvers._lbfgs: the products <s_i, G>, <y_i, G> carried by recurrence, refreshed on re-anchoring),
the direction's image K d assembled from the rows (no convolution), the Wolfe line search with its
safeguarded secant steps, element-wise only (tengsim.solvers._linesearch), re-anchoring w = K q every
``resync`` iterations, the periodic gauge (the mean of q held fixed), stop at max|r| <= tol.

What differs is only the bookkeeping JAX needs: arrays of fixed shape.  The memory's m slots are all
present; a slot is active when its index is below the count k (as in the NumPy ring, the active slots
are always 0 … k − 1), its age orders the pairs, and inactive slots are masked out of the small
triangular solves (identity rows, zero right-hand sides), so they contribute exact zeros.  Python's
``None`` (no bracket end yet, no best point) becomes a flag.  Scalars (energies, slopes, inner products, the
rows' products B @ v: :func:`row_products`) are accumulated in float64 even when the fields are float32 (the
convert fused into the reduction: no extra pass over memory); the law stays in the fields' precision.  Choices
the NumPy solver makes with ``if`` (a restart to steepest descent, the law's own sum or the safe extension's)
are selects on the device where both sides are cheap, so that an iteration waits for the host less often.

Everything here is built by :func:`build` for one static configuration (grid, kernel kind, law class,
dtype, memory, resync); every number that varies between equilibria (g0, the start, the kernel's
spectrum, the law's parameters, tol, max_iter) is a traced argument.
"""
from __future__ import annotations

import jax.numpy as jnp
from jax import lax
from jax.scipy.linalg import solve_triangular

from tengsim.laws.safe import SafeLaw
from tengsim.solvers import _algebra, _jax_fft
from tengsim.solvers._constants import C1, C2, FIRST_MOVE, MAX_EVAL

F64 = jnp.float64


def law_twin(cls, fields, values):
    """An instance of the law class ``cls`` whose dataclass fields hold traced values (no __post_init__:
    the law was validated when the user made it)."""
    t = object.__new__(cls)
    for k, v in zip(fields, values):
        object.__setattr__(t, k, v)
    return t


def row_products(M, v):
    """M @ v (the L-BFGS rows' products with a field) accumulated in float64.  float64 fields: the plain matmul.
    float32 fields: each row's sum in float64, the converts fused into one reduction over M (no float64 copy of
    M).  A float32 matmul accumulates the n products in float32, with an error growing with n; the products of
    L-BFGS rows with a near-converged gradient cancel, so their relative error is larger still, and the directions
    built from them stopped float32 solves short of their tolerance on large grids (docs/benchmarks.md, "GPU")."""
    if M.dtype == F64:
        return jnp.matmul(M, v)
    return jnp.sum(M.astype(F64) * v.astype(F64)[None, :], axis=1)


def solve_upper(a, b, trans):
    """x with U x = b (Uᵀ x = b when ``trans``), U the upper triangle of the small square array ``a``."""
    return solve_triangular(jnp.triu(a), b, lower=False, trans=int(bool(trans)))


def build(shape, padded, periodic, pinned, law_cls, law_fields, dtype, memory, resync, mesh=None):
    """The solve as a function of traced arguments (see :func:`solve`'s signature), for jax.jit; ``mesh``: the
    devices the grid's rows are split over (tengsim.solvers._jax_fft), None for one device."""
    nx, ny = shape
    m = int(memory)
    dt = jnp.dtype(dtype)
    conv = _jax_fft.convolution(shape, padded, periodic, dt, mesh)
    if mesh is None:
        def rows_split(a):
            return a
    else:
        rows_sharding = _jax_fft.field_sharding(mesh, 2, 1)

        def rows_split(a):  # the memory's rows split along the points like every field
            return lax.with_sharding_constraint(a, rows_sharding)

    def dot(a, b):  # a·b accumulated in float64 (one fused pass, no float64 copy of a float32 field)
        return jnp.sum(a.astype(F64) * b.astype(F64))

    def rows(M, v):  # M @ v over the stored rows, accumulated in float64 (:func:`row_products`)
        return row_products(M, v)

    def total(a):
        return jnp.sum(a, dtype=F64)

    def solve(g0, q, w, spec, law_values, tol, max_iter, dA, nw):
        raw = law_twin(law_cls, law_fields, [jnp.asarray(v, dt) for v in law_values])  # no float64 promotion
        law = SafeLaw(raw)  # the safe extension below g_safe, as the NumPy solver evaluates it

        fast_sum = getattr(raw, "energy_sum_xp", None)

        def law_phis(g):
            """(ΣΦ, P(g)): the law's own sum where it has one (LJ93, summed as the NumPy solver sums it)
            and no gap is below g_safe, else Σ of evaluate_xp's Φ."""
            def plain(g):
                phi, P = law.evaluate_xp(g, jnp)
                return total(phi), P.astype(dt)

            if fast_sum is None:
                return plain(g)

            def own(g):
                phis, P = fast_sum(g, jnp, total)
                return phis, P.astype(dt)

            # both sums in the same pass over g, one selected: no conditional (a host synchronisation per
            # line-search trial on a GPU) for a choice made on the device
            low = jnp.min(g) < law.g_safe
            (p1, P1), (p2, P2) = plain(g), own(g)
            return jnp.where(low, p1, p2), jnp.where(low, P1, P2)

        def law_sweep(g):
            phis, P = law_phis(g)
            return phis, total(P), P.astype(dt)

        def coefficients(c):
            """(γ, cS, cY) of the compact form over the m slots (zeros on inactive ones)."""
            k = c["k"]
            idx = jnp.arange(m)
            act = idx < k
            age = jnp.where(act, c["age"], jnp.iinfo(jnp.int32).max)
            perm = jnp.argsort(age)
            act_p = act[perm]                                   # the first k entries are the active ones
            new = perm[jnp.maximum(k - 1, 0)]
            gamma = _algebra.newest_gamma(jnp, c["SY"][new, new], c["YY"][new, new])
            both = act_p[:, None] & act_p[None, :]
            SYa = jnp.where(both, c["SY"][perm][:, perm], jnp.eye(m, dtype=F64))
            YYa = jnp.where(both, c["YY"][perm][:, perm], 0.0)
            pS = jnp.where(act_p, c["pS"][perm], 0.0)
            pY = jnp.where(act_p, c["pY"][perm], 0.0)
            top, cy = _algebra.compact_coefficients(jnp, solve_upper, SYa, YYa, pS, pY, gamma)
            cS = jnp.zeros(m, F64).at[perm].set(jnp.where(act_p, top, 0.0))
            cY = jnp.zeros(m, F64).at[perm].set(jnp.where(act_p, cy, 0.0))
            gamma = jnp.where(k > 0, gamma, 1.0)
            return gamma, cS, cY

        def direction(c, gamma, cS, cY):
            coef = jnp.stack([cS, cY], axis=1).ravel().astype(dt)   # rows 2j, 2j + 1: s_j, y_j
            gd = jnp.asarray(-gamma, dt)
            d = c["G"] * gd - coef @ c["B"]
            Kd = c["r"] * gd - coef @ c["KB"]
            return d, Kd, dot(d, c["w"]), dot(d, Kd), dot(d, c["r"]), total(d)

        def evaluate(a, g, P, Kd, qw, dw, dKd, slope):
            gt = Kd * a.astype(dt) + g
            phis, Pt = law_phis(gt)
            Pt = Pt.astype(dt)
            dpk = dot(Pt.astype(F64) - P.astype(F64), Kd)  # the pressure change exact in float64 (small steps)
            e = dA * (0.5 * qw + a * dw + 0.5 * a * a * dKd + phis)
            de = slope + dA * (a * dKd - dpk)
            return e, de, phis, total(Pt), gt, Pt

        def line_search(alpha0, g, P, Kd, qw, dw, dKd, E0, slope0, E_ref):
            eps_E = _algebra.energy_slack(jnp, E0, dt.name)
            E_lo = jnp.minimum(E0, E_ref)
            ev = (g, P, Kd, qw, dw, dKd, slope0)
            z = jnp.zeros((), F64)
            no = jnp.zeros((), bool)
            s0 = dict(i=jnp.int32(0), alpha=alpha0, lo=z, de_lo=slope0, hi=z, has_hi=no, de_hi=z, has_de_hi=no,
                      best_de=z, best_a=z, has_best=no, done=no, a_acc=z, e=z, phis=z, sp=z, gt=g, Pt=P)

            def cond(s):
                return (s["i"] < MAX_EVAL) & ~s["done"]

            def body(s):
                a = s["alpha"]
                e, de, phis, sp, gt, Pt = evaluate(a, *ev)
                fin = jnp.isfinite(e)
                acc = fin & _algebra.accepts(e, de, a, E0, E_lo, slope0, eps_E, C1, C2)
                better = fin & (e <= E_lo + eps_E) & (~s["has_best"] | (jnp.abs(de) < s["best_de"]))
                to_hi = ~fin | _algebra.overshoots(e, de, a, E0, slope0, eps_E, C1)
                hi = jnp.where(to_hi, a, s["hi"])
                has_hi = s["has_hi"] | to_hi
                dh_ok = fin & _algebra.slope_usable(e, de, E0, eps_E)
                de_hi = jnp.where(to_hi, de, s["de_hi"])
                has_de_hi = jnp.where(to_hi, dh_ok, s["has_de_hi"])
                lo = jnp.where(to_hi, s["lo"], a)
                de_lo = jnp.where(to_hi, s["de_lo"], de)
                nxt = _algebra.next_trial(jnp, a, lo, de_lo, hi, de_hi, has_hi, has_de_hi)
                return dict(i=s["i"] + 1, alpha=nxt, lo=lo, de_lo=de_lo, hi=hi, has_hi=has_hi, de_hi=de_hi,
                            has_de_hi=has_de_hi, best_de=jnp.where(better, jnp.abs(de), s["best_de"]),
                            best_a=jnp.where(better, a, s["best_a"]), has_best=s["has_best"] | better,
                            done=acc, a_acc=a, e=e, phis=phis, sp=sp, gt=gt, Pt=Pt)

            s = lax.while_loop(cond, body, s0)

            def from_best(s):
                e, _, phis, sp, gt, Pt = evaluate(s["best_a"], *ev)
                return dict(s, done=True, a_acc=s["best_a"], e=e, phis=phis, sp=sp, gt=gt, Pt=Pt)

            s = lax.cond(~s["done"] & s["has_best"], from_best, lambda s: s, s)
            return s["done"], s["a_acc"], s["phis"], s["sp"], s["gt"], s["Pt"]

        def step(c):
            gamma, cS, cY = coefficients(c)
            d, Kd, dw, dKd, dr, sum_d = direction(c, gamma, cS, cY)

            # not a descent direction: restart from steepest descent in the K metric, d = −G, K d = −r (what
            # the memory's direction is with no pairs), selected element-wise: no conditional
            ok = dr < 0
            zm = jnp.zeros(m, F64)
            d = jnp.where(ok, d, -c["G"])
            Kd = jnp.where(ok, Kd, -c["r"])
            dw, dKd, dr, sum_d = (jnp.where(ok, dw, dot(d, c["w"])), jnp.where(ok, dKd, dot(d, Kd)),
                                  jnp.where(ok, dr, dot(d, c["r"])), jnp.where(ok, sum_d, total(d)))
            k, gamma = jnp.where(ok, c["k"], jnp.int32(0)), jnp.where(ok, gamma, 1.0)
            cS, cY = jnp.where(ok, cS, zm), jnp.where(ok, cY, zm)
            c = dict(c, k=k)
            E_best = jnp.minimum(c["E_best"], c["E"])
            kmax = jnp.max(jnp.abs(Kd)).astype(F64)
            first = _algebra.first_step(jnp, kmax, FIRST_MOVE)
            alpha0 = jnp.where(k == 0, first, 1.0)
            slope = dA * dr
            found, alpha, phis_t, sp_t, gt, Pt = line_search(alpha0, c["g"], c["P"], Kd, c["qw"], dw, dKd,
                                                              c["E"], slope, E_best)
            ray = (d, Kd, dw, dKd, sum_d, gamma, cS, cY, E_best)
            # a failed search takes the step α = 0 (the state unchanged, the loop then stops with status 4):
            # no conditional around the step, which would make XLA keep a second copy of the carried arrays
            alpha = jnp.where(found, alpha, 0.0)
            phis_t, sp_t = jnp.where(found, phis_t, c["phis"]), jnp.where(found, sp_t, c["sum_p"])
            gt, Pt = jnp.where(found, gt, c["g"]), jnp.where(found, Pt, c["P"])
            out = advance(c, alpha, phis_t, sp_t, gt, Pt, ray)
            return dict(out, status=jnp.where(found, out["status"], jnp.int32(4)),
                        it=jnp.where(found, out["it"], c["it"]))

        def advance(c, alpha, phis_t, sp_t, gt, Pt, ray):
            d, Kd, dw, dKd, sum_d, gamma, cS, cY, E_best = ray
            a = alpha.astype(dt)
            resync = (c["it"] + 1) % resync_every == 0

            def plain(_):
                qw = c["qw"] + alpha * (2.0 * dw + alpha * dKd)
                return (c["q"] + d * a, c["w"] + Kd * a, gt, Pt, phis_t, sp_t, qw, E_best, jnp.int32(0),
                        jnp.zeros_like(c["w"]))

            def reanchor(_):
                q = c["q"] + d * a
                w = conv(q, spec)
                corr = (w - c["w"]) + Kd * (-a)
                g = g0 + w
                phis, sp, P = law_sweep(g)
                return q, w, g, P, phis, sp, dot(q, w), jnp.asarray(jnp.inf, F64), jnp.int32(1), corr

            q, w, g, P, phis, sum_p, qw, E_best, extra, corr = lax.cond(resync, reanchor, plain, None)
            E = dA * (0.5 * qw + phis)
            mean_q = c["mean_q"] + alpha * sum_d / nw
            mu = (mean_q - sum_p / nw) if pinned else jnp.zeros((), F64)
            rn = w - conv(P, spec)
            ky = (rn - c["r"]) - corr
            Gn = (q - P) - mu.astype(dt)
            y = Gn - c["G"]
            dky, yky, drn, yrn = dot(d, ky), dot(y, ky), dot(d, rn), dot(y, rn)
            rmax = jnp.max(jnp.abs(rn)).astype(F64)
            x = dA * rows(c["B"], ky)
            # the memory's update (KMetricLBFGS.update)
            sy, yy = dA * alpha * dky, dA * yky
            sks = dA * alpha * alpha * jnp.abs(dKd)
            store = _algebra.stores_pair(jnp, sy, yy, sks)
            k = c["k"]
            idx = jnp.arange(m)
            act = idx < k
            xs, xy = x[0::2], x[1::2]
            dy = _algebra.new_pair_row(gamma, cS, cY, c["SY"], c["YY"], c["pY"])
            pS = jnp.where(act, c["pS"] + xs, c["pS"])
            pY = jnp.where(act, c["pY"] + xy, c["pY"])
            oldest = jnp.argmin(jnp.where(act, c["age"], jnp.iinfo(jnp.int32).max))
            slot = jnp.where(k < m, k, oldest)
            SY, YY = c["SY"], c["YY"]
            SYn = SY.at[:, slot].set(jnp.where(act, xs, SY[:, slot]))
            SYn = SYn.at[slot, :].set(jnp.where(act, alpha * dy, SYn[slot, :]))
            YYn = YY.at[:, slot].set(jnp.where(act, xy, YY[:, slot]))
            YYn = YYn.at[slot, :].set(jnp.where(act, xy, YYn[slot, :]))
            SYn = SYn.at[slot, slot].set(sy)
            YYn = YYn.at[slot, slot].set(yy)
            pSn = pS.at[slot].set(alpha * (dA * drn))
            pYn = pY.at[slot].set(dA * yrn)

            # a conditional: the rows written in place (a select instead made XLA keep a copy of the rows)
            def write(_):
                B = c["B"].at[2 * slot].set(d * a).at[2 * slot + 1].set(y)
                KB = c["KB"].at[2 * slot].set(Kd * a).at[2 * slot + 1].set(ky)
                return B, KB

            B, KB = lax.cond(store, write, lambda _: (c["B"], c["KB"]), None)
            k2 = jnp.where(store, jnp.minimum(k + 1, m), k)
            age = jnp.where(store, c["age"].at[slot].set(c["count"]), c["age"])
            SY = jnp.where(store, SYn, SY)
            YY = jnp.where(store, YYn, YY)
            pS = jnp.where(store, pSn, pS)
            pY = jnp.where(store, pYn, pY)

            def refresh(_):
                p = dA * rows(B, rn)
                a2 = idx < k2
                return jnp.where(a2, p[0::2], pS), jnp.where(a2, p[1::2], pY)

            pS, pY = lax.cond(resync, refresh, lambda _: (pS, pY), None)
            return dict(c, q=q, w=w, g=g, P=P, r=rn, G=Gn, B=B, KB=KB, SY=SY, YY=YY, pS=pS, pY=pY, age=age,
                        k=k2, count=c["count"] + store.astype(jnp.int32), phis=phis, sum_p=sum_p, qw=qw, E=E,
                        E_best=E_best, mean_q=mean_q, rmax=rmax, it=c["it"] + 1, n_conv=c["n_conv"] + 1 + extra)

        # the start: g, P, ΣΦ, r (one convolution), G, E
        g = g0 + w
        phis, sum_p, P = law_sweep(g)
        r = w - conv(P, spec)
        mean_q = total(q) / nw
        G = q - P
        if pinned:
            G = G - (mean_q - sum_p / nw).astype(dt)
        qw = dot(q, w)
        E = dA * (0.5 * qw + phis)
        n = g0.shape[0]
        c0 = dict(q=q, w=w, g=g, P=P, r=r, G=G, B=rows_split(jnp.zeros((2 * m, n), dt)),
                  KB=rows_split(jnp.zeros((2 * m, n), dt)),
                  SY=jnp.zeros((m, m), F64), YY=jnp.zeros((m, m), F64), pS=jnp.zeros(m, F64),
                  pY=jnp.zeros(m, F64), age=jnp.zeros(m, jnp.int32), k=jnp.int32(0), count=jnp.int32(0),
                  phis=phis, sum_p=sum_p, qw=qw, E=E, E_best=E, mean_q=mean_q,
                  rmax=jnp.max(jnp.abs(r)).astype(F64), it=jnp.int32(0), n_conv=jnp.int32(1),
                  status=jnp.int32(0))

        def cond(c):
            return (c["status"] == 0) & jnp.isfinite(c["rmax"]) & (c["rmax"] > tol) & (c["it"] < max_iter)

        c = lax.while_loop(cond, step, c0)
        return dict(q=c["q"], w=c["w"], P=c["P"], r=c["r"], E=c["E"], rmax=c["rmax"], it=c["it"],
                    n_conv=c["n_conv"], status=c["status"], converged=c["rmax"] <= tol)

    resync_every = int(resync)
    return solve


__all__ = ["build", "law_twin", "row_products"]
