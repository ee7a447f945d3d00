"""Trial of a stiffness-aware preconditioner for the fast solver (issue 6, scaling study).

The fast solver is L-BFGS in the metric of the elastic kernel: its initial inverse Hessian is γK.
The Hessian of the energy in the displacement u is K⁻¹ + diag Φ''(g), so on large cells the long
wavelengths, where K is largest, should be stiffened by the interaction.  This script tries the
mean-field form H0 = γ (K⁻¹ + s̄)⁻¹ (Fourier-diagonal, free to apply) on the scaling study's rough
surface, with s̄ = 0 (the fast solver's own metric, a check that this plain-NumPy L-BFGS counts
like FastSolver), a fixed s̄, or s̄ = the mean of max(Φ'', 0) over the cell at the start.

    OPENBLAS_NUM_THREADS=1 python benchmarks/precond_trial.py --sizes 256 512 --sbar 0 1 mean

Prints, per size and s̄, the L-BFGS iterations to max|r| <= tol on Eq. (9), the energy reached, and
the convergence history (max|r| and E every 20 iterations) with ``--history``.  It is a
measurement script, not part of the package: each iteration spends extra FFTs that FastSolver
assembles from stored images, so only iteration counts are comparable, not times.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
from scipy.optimize import line_search

sys.path.insert(0, str(Path(__file__).resolve().parent))
from scaling import rough_surface  # noqa: E402

from tengsim.laws import LJ93  # noqa: E402


def trial(n, sbar, dx=0.25, mu=0.5, overlap=0.05, memory=10, tol=1e-6, max_iter=4000, history=None):
    """L-BFGS on E(u) = ½ u·K⁻¹u + ΣΦ(g0 + u) (zero-mean u) with H0 = γ(K⁻¹ + s̄)⁻¹."""
    h, _ = rough_surface(n, dx, seed=0)
    U0 = h.max() - h
    g0 = U0 - float(np.quantile(U0, overlap)) + 1.0
    qx = 2 * np.pi * np.fft.fftfreq(n, d=dx)
    qy = 2 * np.pi * np.fft.rfftfreq(n, d=dx)
    k = np.hypot(qx[:, None], qy[None, :])
    kap = mu ** 1.5
    K = np.where(k > 0, 2 * kap / np.where(k > 0, k, 1.0), 0.0)
    Kinv = k / (2 * kap)
    law = LJ93()

    def conv(a, mult):
        return np.fft.irfft2(np.fft.rfft2(a) * mult, s=a.shape)

    def energy_grad(u):
        phi, P = law.evaluate(g0 + u)
        Ku = conv(u, Kinv)
        G = Ku - P
        return 0.5 * float(np.vdot(u, Ku)) + float(phi.sum()), G - G.mean(), P

    u = np.zeros((n, n))
    E, G, P = energy_grad(u)
    s = float(np.maximum(law.stiffness(g0), 0).mean()) if sbar == "mean" else float(sbar)
    M = np.where(k > 0, 1.0 / (Kinv + s + (k == 0)), 0.0)
    S, Y = [], []
    for it in range(max_iter + 1):
        rmax = float(np.abs(u - conv(P, K)).max())
        if history is not None and it % 20 == 0:
            history.append((it, rmax, E))
        if rmax <= tol or it == max_iter:
            return dict(n=n, sbar=s, iterations=it, residual=rmax, energy=E, converged=rmax <= tol)
        z, alphas = G.copy(), []
        for si, yi in zip(reversed(S), reversed(Y)):
            a = float(np.vdot(si, z)) / float(np.vdot(yi, si))
            alphas.append(a)
            z -= a * yi
        gamma = float(np.vdot(S[-1], Y[-1]) / np.vdot(Y[-1], conv(Y[-1], M))) if S else 1.0
        z = gamma * conv(z, M)
        for (si, yi), a in zip(zip(S, Y), reversed(alphas)):
            z += (a - float(np.vdot(yi, z)) / float(np.vdot(yi, si))) * si
        d = -z
        alpha = None
        if S:
            alpha = line_search(lambda x: energy_grad(x.reshape(n, n))[0],
                                lambda x: energy_grad(x.reshape(n, n))[1].ravel(),
                                u.ravel(), d.ravel(), G.ravel(), E, c1=1e-4, c2=0.9, amax=1e3)[0]
        if alpha is None:  # first step, or no Wolfe point: backtrack from a step of <= 0.25 ε
            alpha = min(1.0, 0.25 / float(np.abs(d).max()))
            slope = float(np.vdot(G, d))
            while energy_grad(u + alpha * d)[0] > E + 1e-4 * alpha * slope and alpha > 1e-12:
                alpha *= 0.5
        un = u + alpha * d
        En, Gn, Pn = energy_grad(un)
        si, yi = un - u, Gn - G
        if float(np.vdot(si, yi)) > 1e-14:
            S.append(si)
            Y.append(yi)
            if len(S) > memory:
                S.pop(0)
                Y.pop(0)
        u, E, G, P = un, En, Gn, Pn


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[256, 512])
    ap.add_argument("--sbar", nargs="+", default=["0", "1", "mean"], help="numbers or 'mean'")
    ap.add_argument("--history", action="store_true", help="print max|r| and E every 20 iterations")
    a = ap.parse_args(argv)
    print("| n | s̄ | iterations | max\\|r\\| | energy | seconds |\n|---|---|---|---|---|---|")
    for n in a.sizes:
        for sb in a.sbar:
            hist = [] if a.history else None
            t0 = time.perf_counter()
            r = trial(n, sb if sb == "mean" else float(sb), history=hist)
            print(f"| {n} | {sb} ({r['sbar']:.3g}) | {r['iterations']}{'' if r['converged'] else ' (not converged)'} "
                  f"| {r['residual']:.1e} | {r['energy']:.10g} | {time.perf_counter() - t0:.1f} |", flush=True)
            for it, rm, e in hist or ():
                print(f"    {it}: max|r| {rm:.2e}, E {e:.12g}")


if __name__ == "__main__":
    main()
