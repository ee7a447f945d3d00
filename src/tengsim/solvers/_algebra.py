"""The fast solver's algebra, one source for its NumPy loop (tengsim.solvers._lbfgs, _linesearch, _descent) and
its JAX loop (tengsim.solvers._jax_loop): each function takes the array namespace ``xp`` it computes with.

* ``xp`` = ``numpy`` or ``jax.numpy`` for arrays (the L-BFGS memory's small matrices, on the backend or traced);
* ``xp`` = :data:`HOST` for the NumPy loop's host floats (the line search's scalars, the curvature test), whose
  ``where`` is Python's conditional expression: no array made per trial.

The loops differ only in their bookkeeping (a Python loop with ``None`` for "no bracket end yet" and a ring of
active slots in age order; a ``lax.while_loop`` with flags and fixed-shape, masked arrays), never in a formula:
each number is computed here, in the same order of operations for both, so that the two solvers agree step for
step to round-off (tests/test_jax_solver.py, tests/test_algebra.py).  What is not shared and why:
docs/extending.md ("One source for each algorithm").
"""
from __future__ import annotations

from types import SimpleNamespace

from tengsim.solvers._constants import APPROX_SLOPE, CURVATURE_EPS, EPS_E, GROW, SAFEGUARD

HOST = SimpleNamespace(where=lambda c, a, b: a if c else b, minimum=min, maximum=max)
"""The namespace of host floats: the selects and bounds the functions below need, on Python scalars."""


# --- L-BFGS: the compact representation (Byrd, Nocedal & Schnabel 1994, Eq. 3.1-3.2) ---------------------------

def newest_gamma(xp, sy, yy):
    """γ = <s, y>/<y, y> of the newest pair; 1 where <y, y> <= 0 (only an unconfirmed pair, taken back)."""
    return xp.where(yy > 0, sy / xp.where(yy > 0, yy, 1.0), 1.0)


def compact_coefficients(xp, solve_upper, SYa, YYa, pS, pY, gamma):
    """(cS, cY) of H G = γ G + Σ cS_i s_i + Σ cY_i y_i, the pairs in age order (oldest first).

    ``SYa`` = [<s_i, y_j>] and ``YYa`` = [<y_i, y_j>] in age order, ``pS``, ``pY`` = <s_i, G>, <y_i, G>;
    R = the upper triangle of SYa (its diagonal <s_i, y_i> > 0), D = diag(SYa):

        u = R⁻¹ pS,   cS = R⁻ᵀ ((D + γ YᵀY) u − γ pY),   cY = −γ u.

    ``solve_upper(a, b, trans)``: x with U x = b (Uᵀ x = b when ``trans``), U the upper triangle of ``a``."""
    u = solve_upper(SYa, pS, False)
    top = solve_upper(SYa, xp.diag(SYa) * u + gamma * (YYa @ u) - gamma * pY, True)
    return top, -gamma * u


def new_pair_row(gamma, cS, cY, SY, YY, pY):
    """<d, y_j> for every stored y_j, from d = −(γ G + Σ cS_i s_i + Σ cY_i y_i) (G the old gradient, pY its
    <y_j, G>): the new pair's row <s, y_j> = α <d, y_j> of [<s_i, y_j>], with no pass over the rows."""
    return -(gamma * pY + cS @ SY + cY @ YY)


def stores_pair(xp, sy, yy, sks):
    """The curvature test: a pair (s, y) is stored when <s, y> > CURVATURE_EPS |<s, K s>| and <y, y> > 0."""
    return (sy > CURVATURE_EPS * xp.maximum(sks, 1e-300)) & (yy > 0)


# --- the Wolfe line search: its tests and its bracketing ----------------------------------------------------------

def first_step(xp, kmax, first_move):
    """α for a first direction (empty memory): the gap moves by at most ``first_move``, ``kmax`` = max|K d|."""
    return xp.where(kmax > first_move, first_move / xp.where(kmax > 0, kmax, 1.0), 1.0)


def energy_slack(xp, E0, precision):
    """The approximate test's slack on E: EPS_E of the fields' precision ('float64', 'float32') × max(1, |E(0)|)."""
    return EPS_E[precision] * xp.maximum(1.0, abs(E0))


def accepts(e, de, a, E0, E_lo, slope0, eps_E, c1, c2):
    """The trial α = ``a`` (E(α) = ``e`` finite, E'(α) = ``de``) passes the strong Wolfe conditions, or the
    approximate ones of Hager & Zhang (2005), measured from E_lo = min(E(0), the lowest energy so far)."""
    wolfe = (e <= E0 + c1 * a * slope0) & (abs(de) <= -c2 * slope0)
    approx = (e <= E_lo + eps_E) & (c2 * slope0 <= de) & (de <= -APPROX_SLOPE * slope0)
    return wolfe | approx


def overshoots(e, de, a, E0, slope0, eps_E, c1):
    """The trial (finite E) ends the bracket: E rose above the sufficient decrease line, or E' > 0."""
    return (e > E0 + c1 * a * slope0 + eps_E) | (de > 0)


def slope_usable(e, de, E0, eps_E):
    """A bracket end's E' may steer the secant: E(α) not above E(0) (to the slack), or E' > 0."""
    return (e <= E0 + eps_E) | (de > 0)


def next_trial(xp, a, lo, de_lo, hi, de_hi, has_hi, has_de_hi):
    """The next trial step after α = ``a``: GROW α while no upper end ``hi`` is known (``has_hi``), else the
    secant step on E' between lo and hi (bisection when hi's slope is unusable or not above lo's), kept
    SAFEGUARD × the width inside the bracket.  ``hi``, ``de_hi``: any finite numbers where not ``has_*``."""
    width = hi - lo
    sec = has_de_hi & (de_hi > de_lo)
    cand = xp.where(sec, lo - de_lo * width / xp.where(sec, de_hi - de_lo, 1.0), lo + 0.5 * width)
    return xp.where(has_hi, xp.minimum(xp.maximum(cand, lo + SAFEGUARD * width), hi - SAFEGUARD * width), GROW * a)


__all__ = ["HOST", "accepts", "compact_coefficients", "energy_slack", "first_step", "new_pair_row", "newest_gamma",
           "next_trial", "overshoots", "slope_usable", "stores_pair"]
