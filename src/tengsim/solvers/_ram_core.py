"""The constrained conjugate gradient on the gap of the solver 'ram' (tengsim.solvers.ram): after Rey, Anciaux &
Molinari (Comput. Mech. 60, 2017, 69–81), the total energy of a hard wall with adhesion minimised over the gap.

Unknown: the gap above the wall u >= 0 (ε) on the solve's domain (the cell; for a kernel that is not periodic
the cell embedded in a periodic domain twice its size, :class:`Compliance`).  Energy (W per pixel area):

    F(u) = ½ (u − h)·K⁻¹(u − h) + Σ_cell φ(u),

h the gap at zero pressure, K the compliance, φ the law's energy beyond the wall (its hard-wall limit,
tengsim.laws.cohesive).  Its gradient is g = p − t(u): the pressure p = K⁻¹(u − h) (+ λ, the mean pressure,
where the mean of u is held: a periodic half-space) less the law's traction.  Equilibrium (KKT):

    g = 0 where u > 0 (and off the cell),   g >= 0 where u = 0 (the wall carries p >= t(0)).

One iteration: the free set F (u > 0, or at the wall and pulled off: g < 0), the projected gradient P_F g and
its preconditioned form z = P_F K P_F g (one FFT pair: K turns the unbalanced pressure into the gap it moves;
the mean over F removed where the mean is held), the conjugate direction d = −z + β d_old (β = z·g / z_old·g_old,
restarted where the set changed or a pixel of a law with a jump crossed it), K⁻¹ d (one FFT pair), the step of
the quadratic model −g·d / (d·K⁻¹d + Σ φ'' d²) (where the curvature is not positive, a trust step), u
projected on u >= 0 (the mean restored by scaling), and a backtracking line search on F itself (the energy
change computed pixel by pixel, exact); a clipped step costs one FFT pair more (K⁻¹ u afresh).  So every step
descends F: a cold or warm start settles in a local minimum, a stable state of the non-convex problem.

Converged when the gap residual max |z| <= ``tol`` (ε): the largest gap the unbalanced pressures move, the
KKT conditions' residual in the unit of the hard-wall solver's (complementarity p·u is exact: u = 0 on the
bound set, and the bound set's g >= 0 is enforced).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tengsim import backend
from tengsim.backend import fft as _bf

#: steps after which K⁻¹ u, carried by the recurrence K⁻¹u ← K⁻¹u + τ K⁻¹d, is transformed afresh
RESYNC = 25
#: Armijo's constant of the line search
ARMIJO = 1e-4
#: halvings of a step before the line search gives up (the iteration then restarts along −z)
HALVINGS = 40


class Compliance:
    """K and K⁻¹ of a kernel on the solve's periodic domain: the kernel's own spectrum where it is periodic
    (the mean mode held where it has no compliance, ``pinned``), else the cell's influence coefficients
    (one convolution of a unit pixel at a corner) embedded symmetrically in a periodic domain of twice the
    cell (within the cell the same K; the cell's gaps and pressures are the domain's block ``[:nx, :ny]``)."""

    def __init__(self, kernel, shape):
        self.shape = tuple(shape)
        nx, ny = self.shape
        if bool(getattr(kernel, "periodic", False)) and hasattr(kernel, "spectrum"):
            spec = np.asarray(kernel.spectrum, dtype=complex).real.copy()
            self.domain = self.shape
            self.embedded = False
        else:
            unit = backend.zeros(self.shape)
            unit[0, 0] = 1.0
            c = np.asarray(kernel.apply(unit), dtype=float)
            px, py = backend.fast_len(2 * nx), backend.fast_len(2 * ny)
            ix = np.minimum(np.minimum(np.arange(px), px - np.arange(px)), nx - 1)
            iy = np.minimum(np.minimum(np.arange(py), py - np.arange(py)), ny - 1)
            spec = _bf.rfft2(c[np.ix_(ix, iy)]).real
            self.domain = (px, py)
            self.embedded = True
        self.pinned = bool(spec[0, 0] <= 0.0)
        if self.pinned:
            spec[0, 0] = 0.0
        if (spec.ravel()[1:] <= 0).any() if self.pinned else (spec <= 0).any():
            from tengsim.errors import TengsimError

            raise TengsimError("solver 'ram': the kernel's compliance is not positive on every mode of its periodic "
                               "domain (no energy in the gap); use solver 'pk' or 'fast'")
        self.spec = spec
        self.inv_spec = np.divide(1.0, spec, out=backend.zeros(spec.shape, spec.dtype), where=spec > 0)
        self.count = 0

    def _mul(self, x, mult):
        self.count += 1
        return _bf.irfft2(_bf.rfft2(x.reshape(self.domain)) * mult, self.domain).ravel()

    def apply(self, x):
        """K x (the domain's flat layout)."""
        return self._mul(x, self.spec)

    def inverse(self, x):
        """K⁻¹ x (the mean mode dropped where it is held)."""
        return self._mul(x, self.inv_spec)

    def embed(self, a, fill=0.0):
        """A cell array on the domain, flat (the block [:nx, :ny]; ``fill`` elsewhere)."""
        if not self.embedded:
            return np.ascontiguousarray(a, dtype=float).ravel().copy()
        out = backend.empty(self.domain)
        out[...] = fill
        out[:self.shape[0], :self.shape[1]] = a
        return out.ravel()

    def crop(self, a):
        """The cell's block of a flat domain array, shaped like the cell."""
        a = a.reshape(self.domain)
        return a[:self.shape[0], :self.shape[1]].copy() if self.embedded else a.copy()


@dataclass
class GapResult:
    """What :func:`solve_gap` returns: the gap ``u``, the pressure ``p`` (W/ε, with the mean λ), the mean
    pressure λ, iterations, the gap residual (ε), the largest unbalanced pressure (W/ε), whether it met ``tol``,
    the energy (W per pixel area) and the message."""

    u: np.ndarray
    p: np.ndarray
    lam: float
    iterations: int
    residual: float
    pressure_residual: float
    converged: bool
    energy: float
    message: str


def solve_gap(op: Compliance, h, cell, law, u, tol: float, max_iter: int, monitor=None) -> GapResult:
    """Minimise F (module doc) from the feasible gap ``u`` (overwritten; its mean is h's where the mean is
    held).  ``h``: the gap at zero pressure (flat domain layout); ``cell``: the domain's cell pixels (None: all);
    ``law``: a :class:`tengsim.laws.cohesive.CohesiveLimit`; ``monitor(it, residual)``: progress."""
    n = h.size
    cellm = cell if cell is not None else ~backend.zeros(n, bool)
    outer = ~cellm

    def on_cell(f, v):                     # a law's function on the cell's gaps (0 off the cell)
        return f(v, np) if cell is None else np.where(cellm, f(np.where(cellm, v, 0.0), np), 0.0)

    pinned = op.pinned
    m0 = float(h.mean())
    Kh = op.inverse(h)
    Ku = op.inverse(u)
    d = backend.zeros(n)
    G_old, restart, since = 1.0, True, 0
    trust = 4.0 * float(law.length)
    adhesive = float(law.tension) > 0
    side = law.side(u[cellm], np)
    phi = on_cell(law.energy, u)
    res = pres = math.inf
    lam = 0.0
    msg = ""
    it = 0
    free_old = None
    for it in range(max_iter + 1):
        A = Ku - Kh
        grad = A - on_cell(law.traction, u)
        free = (u > 0.0) | outer
        lam = 0.0
        if pinned:
            lam = -float(grad[free].mean()) if free.any() else 0.0
            grad += lam
        pulled = cellm & ~free & (grad < 0.0)
        if pulled.any():
            free |= pulled
            if pinned:
                dl = -float(grad[free].mean())
                grad += dl
                lam += dl
        pg = grad * free
        z = op.apply(pg)
        z *= free
        if pinned:
            z[free] -= float(z[free].mean())
        res = float(np.abs(z).max())
        pres = float(np.abs(pg).max())
        if monitor is not None:
            monitor(it, res)
        if res <= tol:
            break
        if it == max_iter:
            msg = f"not converged in {max_iter} iterations (gap residual {res:.3g} ε)"
            break
        if free_old is not None and not np.array_equal(free, free_old):
            restart = True
        free_old = free
        G = float(np.dot(pg, z))
        beta = 0.0 if (restart or not G_old > 0) else G / G_old
        G_old = G
        d *= beta
        d *= free
        d -= z
        if pinned and beta:
            d[free] -= float(d[free].mean())
        slope = float(np.dot(grad, d))
        if not slope < 0:
            np.negative(z, out=d)
            slope = float(np.dot(grad, d))
            if not slope < 0:
                msg = f"no descent direction (gap residual {res:.3g} ε)"
                break
        restart = False
        Kd = op.inverse(d)
        curv = float(np.dot(d, Kd)) + float(np.dot(on_cell(law.curvature, u) * d, d))
        dmax = float(np.abs(d).max())
        tau = -slope / curv if curv > 0 else trust / dmax
        if adhesive and tau * dmax > trust:           # a trust step where the energy is not convex
            tau = trust / dmax
        accepted = False
        for _ in range(HALVINGS):
            un = u + tau * d
            neg = cellm & (un < 0.0)
            clipped = bool(neg.any())
            if clipped:
                un[neg] = 0.0
                if pinned:
                    un *= m0 / float(un.mean())
                Kun = op.inverse(un)
            else:
                Kun = Ku + tau * Kd
            du = un - u
            phin = on_cell(law.energy, un)
            dE = float(np.dot(du, A)) + 0.5 * float(np.dot(du, Kun - Ku)) + float((phin - phi).sum())
            if dE <= ARMIJO * float(np.dot(grad, du)) or dE <= 0.0 and tau * dmax < 1e-12:
                accepted = True
                break
            tau *= 0.5
        if not accepted:
            restart = True
            trust *= 0.25
            continue
        if tau * dmax >= 0.9 * trust:
            trust *= 2.0
        u, phi = un, phin
        since += 1
        if clipped or since >= RESYNC:
            Ku = Kun if clipped else op.inverse(u)
            since = 0
            restart = restart or clipped
        else:
            Ku = Kun
        if side is not None:
            s = law.side(u[cellm], np)
            if not np.array_equal(s, side):
                restart = True
            side = s
    E = 0.5 * float(np.dot(u - h, Ku - Kh)) + float(phi.sum())
    p = (Ku - Kh) + lam
    ok = res <= tol
    return GapResult(u, p, lam, it, res, pres, ok, E, "converged" if ok else msg)
