"""The surface displacement of a uniformly loaded rectangle on a half-space (Love 1929; Johnson 1985
Sec. 3.3): the influence coefficients of a pixel.

Units and conventions: :mod:`tengsim.references.common`.
"""
from __future__ import annotations

import numpy as np

from tengsim.errors import positive


# ----------------------------------------------------------------------------
# Uniformly loaded rectangle on a half-space (Love 1929; Johnson 1985 Sec. 3.3)
# ----------------------------------------------------------------------------

def _corner(x, y):
    """Antiderivative of 1/sqrt(x^2+y^2), odd in x and in y: x asinh(y/|x|) + y asinh(x/|y|) (0 on the axes)."""
    ax, ay = np.abs(x), np.abs(y)
    with np.errstate(divide="ignore", invalid="ignore"):
        t1 = np.where(ax > 0, x * np.arcsinh(y / np.where(ax > 0, ax, 1.0)), 0.0)
        t2 = np.where(ay > 0, y * np.arcsinh(x / np.where(ay > 0, ay, 1.0)), 0.0)
    return t1 + t2


def rectangle_displacement(x, y, a, b, p=1.0, E_star=1.0):
    """Normal surface displacement [m] from uniform pressure p [Pa] on [-a,a]x[-b,b] [m].

    u(x,y) = p/(pi E*) [G(x+a,y+b) - G(x+a,y-b) - G(x-a,y+b) + G(x-a,y-b)],
    G(s,t) = s asinh(t/|s|) + t asinh(s/|t|) (the odd-odd antiderivative of
    1/sqrt(s^2+t^2); the form s asinh(t/s) is wrong when the point is inside
    the strip). Centre of a square (a = b): u = (8 p a/(pi E*)) ln(1+sqrt 2)
    ~= 2.244 p a/E*. E* = E/(1-nu^2) for one half-space. Love (1929);
    Johnson (1985) Eq. 3.25.
    """
    a, b = positive("a", a), positive("b", b)
    E_star = positive("E_star", E_star)
    x = np.asarray(x, float)
    y = np.asarray(y, float)
    s = (_corner(x + a, y + b) - _corner(x + a, y - b)
         - _corner(x - a, y + b) + _corner(x - a, y - b))
    return float(p) / (np.pi * E_star) * s
