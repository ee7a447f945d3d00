"""The constrained CG of the ``pk`` solver compiled with JAX: the active set and the conjugate gradient as one
``lax.while_loop`` (the solver ``pk-jax``, tengsim.solvers.pk).

Step for step the algorithm of :func:`tengsim.solvers._pk_core.constrained_cg` (read its docstring for the
why): the gap u = h + K p on the contact set S = {p > 0}, the conjugate direction on S (the |q| preconditioner's
z = P_S M⁻¹ P_S u where the kernel has one), the exact step along it, the projection p >= 0, the overlapping
pixels out of contact entering (the conjugacy restarted), the load control's correction and rescaling, and the
preconditioner's safeguard (after ``STALL`` iterations without a new lowest residual, on from the best pressure
without it).  What differs is only the bookkeeping JAX needs: ``if`` becomes a select, the safeguard's restart a
branch of the loop's body, Python's early ``break`` a flag.  The kernel is taken through what
:class:`tengsim.registry.FourierKernelLike` declares (spectrum, padded shape, periodic); the convolution and
the preconditioner's product go through the JAX FFT seam (tengsim.solvers._jax_fft).  Fields and scalars are
float64.

The cohesive zones (Maugis–Dugdale, exponential) stay the NumPy solver's outer loop on the host
(:class:`tengsim.solvers.pk.PKSolver`): each zone update calls this compiled contact solve.

One compilation per (grid shape, padded shape, periodic, load control, preconditioned, device), cached in this
module; the gap, the start, the spectrum, the preconditioner's multiplier, tol, max_iter and the load are
traced arguments.  JAX is imported only when this module is (a ``pk-jax`` solver is made).
"""
from __future__ import annotations

import threading

import numpy as np

from tengsim import backend
from tengsim.solvers._pk_core import STALL, CoreResult, Preconditioner
from tengsim.solvers.jax_fast import _jax, _kernel_form, find_device

_CACHE: dict = {}
_LOCK = threading.Lock()


def _build(shape, padded, periodic: bool, load_control: bool, pre: bool):
    """The contact solve as a function of traced arguments (see :class:`JaxConvolution.solve`)."""
    import jax.numpy as jnp
    from jax import lax

    from tengsim.solvers import _jax_fft

    f64 = jnp.float64
    conv_ = _jax_fft.convolution(shape, padded, periodic, jnp.dtype(f64))
    pre_ = _jax_fft.convolution(shape, shape, True, jnp.dtype(f64))   # M⁻¹ x: the periodic product with mult

    def solve(h, p0, Kp0, use_Kp0, spec, mult, diag, tol, max_iter, load):
        conv = lambda x: conv_(x, spec)                                  # noqa: E731

        def precond(x):
            return pre_(x, mult)

        def evaluate(p, Kp):
            """u, S (the direction's set), nS, c, residual at p with K p."""
            u = h + Kp
            S = p > 0
            nS = jnp.sum(S)
            if load_control:
                c = jnp.where(nS > 0, -jnp.sum(jnp.where(S, u, 0.0)) / jnp.maximum(nS, 1), 0.0)
                u = u + c
            else:
                c = f64(0.0)
            res = jnp.maximum(jnp.max(jnp.where(S, jnp.abs(u), -u)), 0.0)
            S = jnp.where(nS == 0, u < 0, S)                              # nothing in contact yet: the overlap
            return u, S, jnp.sum(S), c, res

        p = jnp.maximum(p0, 0.0)
        if load_control:
            m = jnp.mean(p)
            p = jnp.where(m > 0, p * (load / jnp.where(m > 0, m, 1.0)), load)
            Kp = conv(p)
            nc = 1
        else:
            Kp = lax.cond(use_Kp0, lambda: Kp0, lambda: conv(p))
            nc = jnp.where(use_Kp0, 0, 1)
        u, S, nS, c, res = evaluate(p, Kp)
        n = h.size
        zeros = jnp.zeros(n, f64)
        st = dict(p=p, Kp=Kp, u=u, S=S, nS=nS, c=c, res=res, t=zeros, delta=f64(0.0), G_old=f64(1.0),
                  it=jnp.int32(0), nc=jnp.asarray(nc, jnp.int32), broken=jnp.bool_(False), use_pre=jnp.bool_(pre),
                  best=f64(jnp.inf), p_best=p, it_best=jnp.int32(0))

        def cond(s):
            return ~((s["res"] <= tol) | (s["nS"] == 0) | (s["it"] >= max_iter) | s["broken"])

        def restart(s):
            """The safeguard: on from the best pressure, without the preconditioner."""
            p = s["p_best"]
            Kp = conv(p)
            u, S, nS, c, res = evaluate(p, Kp)
            return {**s, "p": p, "Kp": Kp, "u": u, "S": S, "nS": nS, "c": c, "res": res, "t": zeros,
                    "delta": f64(0.0), "G_old": f64(1.0), "use_pre": jnp.bool_(False), "nc": s["nc"] + 1}

        def step(s):
            p, u, S, nS, t = s["p"], s["u"], s["S"], s["nS"], s["t"]
            work = jnp.where(S, u, 0.0)
            if pre:
                z = jnp.where(S, precond(work), 0.0)
                if load_control:
                    z = jnp.where(S, z - jnp.sum(z) / nS, 0.0)
                z = jnp.where(s["use_pre"], z, work)
            else:
                z = work
            G = jnp.dot(work, z)
            t = jnp.where(S, t * (s["delta"] * G / s["G_old"]), 0.0) + z
            r = conv(t)
            if load_control:
                r = r - jnp.sum(jnp.where(S, r, 0.0)) / nS
            rt = jnp.dot(r, t)
            broken = ~(rt > 0)
            tau = jnp.dot(work, t) / jnp.where(broken, 1.0, rt)
            p_new = jnp.maximum(p - tau * t, 0.0)
            left = jnp.where(s["use_pre"], nS - jnp.sum(p_new > 0), 0)
            enter = (u < 0) & (p_new == 0)
            any_in = jnp.any(enter)
            scale = jnp.where(s["use_pre"], tau * diag, tau)
            p_new = jnp.where(enter, p_new - scale * u, p_new)
            delta = jnp.where(any_in | (left > 0), 0.0, 1.0).astype(f64)
            if load_control:
                m = jnp.mean(p_new)
                broken = broken | ~(m > 0)
                p_new = p_new * (load / jnp.where(m > 0, m, 1.0))
            p_new = jnp.where(broken, p, p_new)
            Kp = conv(p_new)
            u2, S2, nS2, c2, res2 = evaluate(p_new, Kp)
            keep = lambda a, b: jnp.where(broken, a, b)                  # noqa: E731
            return {**s, "p": p_new, "Kp": keep(s["Kp"], Kp), "u": keep(u, u2), "S": keep(S, S2),
                    "nS": keep(nS, nS2), "c": keep(s["c"], c2), "res": keep(s["res"], res2), "t": t,
                    "delta": delta, "G_old": G, "it": s["it"] + 1, "nc": s["nc"] + 2, "broken": broken}

        def body(s):
            better = s["res"] < s["best"]
            s = {**s, "best": jnp.where(s["use_pre"] & better, s["res"], s["best"]),
                 "p_best": jnp.where(s["use_pre"] & better, s["p"], s["p_best"]),
                 "it_best": jnp.where(s["use_pre"] & better, s["it"], s["it_best"])}
            stalled = s["use_pre"] & ~better & (s["it"] - s["it_best"] > STALL)
            return lax.cond(stalled, restart, step, s)

        s = lax.while_loop(cond, body, st)
        return {k: s[k] for k in ("p", "Kp", "u", "c", "it", "nc", "res")}

    return solve


class JaxConvolution:
    """K x of a Fourier kernel on a JAX device, called from the host like :class:`tengsim.solvers._pk_core.Convolution`
    (its ``count``); :meth:`solve` is the compiled contact solve on the same kernel."""

    def __init__(self, kernel, shape, device="cpu"):
        jax = _jax()
        import jax.numpy as jnp

        from tengsim.solvers import _jax_fft

        periodic, padded, spec, _ = _kernel_form(kernel)
        self.shape, self.padded, self.periodic = tuple(shape), padded, periodic
        self.dev = find_device(device)
        self.spec = jax.device_put(np.asarray(spec), self.dev)
        key = ("conv", self.shape, padded, periodic, str(self.dev))
        with _LOCK:
            self._conv = _CACHE.get(key)
        if self._conv is None:                        # compiled once per grid and device, as the solve
            self._conv = jax.jit(_jax_fft.convolution(self.shape, padded, periodic, jnp.dtype("float64")))
            with _LOCK:
                _CACHE[key] = self._conv
        self.count = 0

    def __call__(self, x, out):
        import jax

        self.count += 1
        out[:] = np.asarray(jax.device_get(self._conv(jax.device_put(np.asarray(x, dtype=float), self.dev), self.spec)))
        return out

    def solve(self, h, p, tol, max_iter, load, precond: Preconditioner | None, Kp0):
        jax = _jax()
        key = (self.shape, self.padded, self.periodic, load is not None, precond is not None, str(self.dev))
        with _LOCK:
            fn = _CACHE.get(key)
        if fn is None:
            fn = jax.jit(_build(self.shape, self.padded, self.periodic, load is not None, precond is not None))
            with _LOCK:
                _CACHE[key] = fn
        put = lambda a: jax.device_put(np.ascontiguousarray(a, dtype=float), self.dev)  # noqa: E731
        n = h.size
        mult = precond.mult if precond is not None else backend.zeros((1, 1))
        diag = precond.diag if precond is not None else 0.0
        out = jax.device_get(fn(put(h), put(p), put(Kp0 if Kp0 is not None else backend.zeros(n)), Kp0 is not None,
                                self.spec, jax.device_put(np.asarray(mult), self.dev), float(diag), float(tol),
                                int(max_iter), float(0.0 if load is None else load)))
        self.count += int(out["nc"])
        return out


def constrained_cg(conv: JaxConvolution, h, p, tol: float, max_iter: int, load: float | None = None,
                   monitor=None, precond=None, Kp0=None) -> CoreResult:
    """:func:`tengsim.solvers._pk_core.constrained_cg` as one compiled loop on ``conv``'s device (same
    arguments; ``monitor`` is called once, with the last iteration)."""
    n0 = conv.count
    out = conv.solve(h, p, tol, max_iter, load, precond, None if load is not None else Kp0)
    res, it = float(out["res"]), int(out["it"])
    if monitor is not None:
        monitor(it, res)
    arr = lambda k: np.array(out[k], dtype=float)                         # noqa: E731
    return CoreResult(arr("p"), arr("Kp"), arr("u"), float(out["c"]), it, conv.count - n0, res, bool(res <= tol))


def clear_cache() -> None:
    """Forget every compiled contact solve."""
    with _LOCK:
        _CACHE.clear()


__all__ = ["JaxConvolution", "clear_cache", "constrained_cg"]
