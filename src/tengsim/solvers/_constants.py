"""The fast solver's constants, one source for the NumPy solver (tengsim.solvers._linesearch, _lbfgs,
_descent) and the JAX loop (tengsim.solvers._jax_loop): changing one here changes both solvers alike."""
from __future__ import annotations

C1 = 1e-4
"""Wolfe's sufficient-decrease constant: E(α) <= E(0) + C1 α E'(0)."""
C2 = 0.9
"""Wolfe's curvature constant: |E'(α)| <= −C2 E'(0); also the approximate test's lower slope bound C2 E'(0)."""
APPROX_SLOPE = 0.8
"""The approximate Wolfe test's upper slope bound (Hager & Zhang 2005): E'(α) <= −APPROX_SLOPE E'(0)."""
EPS_E = {"float64": 1e-11, "float32": 1e-6}
"""The approximate test's energy slack relative to max(1, |E(0)|), per field precision (float32 rounds E at ~1e-7)."""
MAX_EVAL = 40
"""Trial steps of one line search before it fails."""
FIRST_MOVE = 0.25
"""A first direction (empty memory) moves the gap by at most this (ε)."""
GROW = 2.0
"""Before a bracket is found the trial step is multiplied by this."""
SAFEGUARD = 0.1
"""A secant (or bisection) step stays this fraction of the bracket's width inside it."""
CURVATURE_EPS = 1e-14
"""A pair (s, y) is stored only when s·y > CURVATURE_EPS · |s·K s| (and y·y > 0)."""

__all__ = ["APPROX_SLOPE", "C1", "C2", "CURVATURE_EPS", "EPS_E", "FIRST_MOVE", "GROW", "MAX_EVAL", "SAFEGUARD"]
