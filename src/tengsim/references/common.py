"""Closed-form and semi-analytic reference solutions of contact mechanics: the conventions and the
contact modulus.

Plain functions for checking numerical solvers. Units are consistent but
arbitrary (SI recommended): lengths [m], forces [N], moduli and pressures [Pa],
work of adhesion W [J/m^2 = N/m].

Conventions
-----------
* ``E_star`` is the contact modulus, 1/E* = (1-nu1^2)/E1 + (1-nu2^2)/E2
  (use :func:`effective_modulus`).  For a single half-space against a rigid
  body, E* = E/(1-nu^2).
* Indentation ``delta`` > 0 means approach (compression); force ``F`` > 0 is
  compressive; pressure ``p`` > 0 is compressive.
* Maugis-Dugdale quantities use the Maugis (1992) / Johnson & Greenwood (1997)
  scales with K = 4E*/3:  A = a (K/(pi W R^2))^(1/3),  P = F/(pi W R),
  D = delta (K^2/(pi^2 W^2 R))^(1/3),  lambda = 2 sigma0 (R/(pi W K^2))^(1/3).

Sources: K.L. Johnson, *Contact Mechanics* (CUP 1985); Johnson, Kendall &
Roberts, Proc. R. Soc. A 324 (1971) 301; Derjaguin, Muller & Toporov, JCIS 53
(1975) 314; D. Maugis, JCIS 150 (1992) 243; K.L. Johnson & J.A. Greenwood,
JCIS 192 (1997) 326; J.A. Greenwood, Proc. R. Soc. A 453 (1997) 1277;
I.N. Sneddon, Int. J. Eng. Sci. 3 (1965) 47; K.L. Johnson, Int. J. Solids
Struct. 32 (1995) 423; A.E.H. Love, Phil. Trans. A 228 (1929) 377.
"""
from __future__ import annotations

import numpy as np

from tengsim.errors import TengsimError, positive


def nonnegative(name: str, value) -> float:
    """``value`` as a float, checked finite and >= 0 (a TengsimError naming ``name`` otherwise)."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise TengsimError(f"{name} must be a number, got {value!r}") from None
    if not (v >= 0 and v < float("inf")):
        raise TengsimError(f"{name} must be finite and >= 0, got {value!r}")
    return v


def effective_modulus(E1, nu1, E2=np.inf, nu2=0.0) -> float:
    """Contact modulus E* [Pa]: 1/E* = (1-nu1^2)/E1 + (1-nu2^2)/E2.

    E2 = inf (default) is a rigid counter-body. Johnson (1985) Eq. 4.22.
    """
    E1 = positive("E1", E1)
    inv = (1.0 - float(nu1) ** 2) / E1
    if np.isfinite(E2):
        inv += (1.0 - float(nu2) ** 2) / positive("E2", E2)
    if not inv > 0:
        raise TengsimError("Poisson ratios must satisfy |nu| < 1")
    return 1.0 / inv
