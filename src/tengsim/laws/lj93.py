"""The paper's Lennard-Jones 9-3 surface law (Derjaguin), Eq. (2)/(8)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tengsim.laws.base import LJ_PEAK_TENSION, Law, check_g_safe
from tengsim.registry import LAWS


# The law's formula, once (Eq. 2/8): Φ = (1/3)g⁻⁸ − (4/3)g⁻², P = −dΦ/dg = (8/3)(g⁻⁹ − g⁻³).  Plain
# arithmetic on arrays of any namespace (NumPy, or jax.numpy inside the JAX solver); the NumPy solver's
# in-place hot path (LJ93.energy_pressure) does the same operations in the same order.
_C_P = 8.0 / 3.0


def powers(g):
    """(g⁻¹, g⁻², g⁻⁸): the powers the formula is built of."""
    inv = 1.0 / g
    i2 = inv * inv
    i8 = i2 * i2
    return inv, i2, i8 * i8


def energy(i8, i2):
    """Φ = (1/3)g⁻⁸ − (4/3)g⁻² (W) from g⁻⁸ and g⁻², or ΣΦ from their sums."""
    return i8 / 3.0 - (4.0 / 3.0) * i2


def pressure(inv, i2, i8):
    """P = (8/3)(g⁻⁹ − g⁻³) (W/ε)."""
    return _C_P * (i8 * inv - i2 * inv)


def slope(inv, i2, i8):
    """dP/dg = (8/3)(3g⁻⁴ − 9g⁻¹⁰) (W/ε²)."""
    return _C_P * (-9.0 * (i8 * inv) + 3.0 * (i2 * inv)) * inv


@dataclass(frozen=True)
class LJ93(Law):
    """The paper's law, Eq. (2)/(8): P = (8/3)[g⁻⁹ − g⁻³], Φ = (1/3)g⁻⁸ − (4/3)g⁻².

    A 9-3 law in pressure (8-2 in energy, Derjaguin): Φ(1) = −1 (the work of adhesion W),
    P(1) = 0, tensile peak P_min = −16/(9√3) ≈ −1.026 at g = 3^{1/6}.  Declared numbers (closed
    forms): dP/dg = (8/3)(3g⁻⁴ − 9g⁻¹⁰) vanishes at g⁶ = 3 (the peak); d²P/dg² = (8/3)(90g⁻¹¹ − 12g⁻⁵)
    vanishes at g⁶ = 15/2, where the softening is steepest, dP/dg = (24/5)(15/2)^{−2/3} ≈ 1.253.
    """

    g_safe: float = 0.6

    def __post_init__(self):
        check_g_safe(self)

    # declared numbers (Law): closed forms
    @property
    def max_tension(self) -> float:
        return LJ_PEAK_TENSION                          # 16/(9√3) = −P(3^{1/6})

    @property
    def g_peak(self) -> float:
        return 3.0 ** (1.0 / 6.0)

    @property
    def g_zero(self) -> float:
        return 1.0

    @property
    def work(self) -> float:
        return 1.0                                      # −Φ(1) = −(1/3 − 4/3)

    @property
    def max_softening(self) -> float:
        return 4.8 * 7.5 ** (-2.0 / 3.0)                # at the inflection g = 7.5^{1/6} ≈ 1.399

    def _raw(self, g, need_dp=True, xp=np):
        inv, i2, i8 = powers(g)
        return energy(i8, i2), pressure(inv, i2, i8), (slope(inv, i2, i8) if need_dp else None)

    def energy_sum_xp(self, g, xp, total):
        """(ΣΦ, P) in the array namespace ``xp``, ΣΦ summed as :meth:`energy_pressure` sums it
        (:func:`energy` of Σg⁻⁸ and Σg⁻², so the JAX solver's energies round as the NumPy solver's do).
        ``total``: the namespace's sum."""
        inv, i2, i8 = powers(g)
        return energy(total(i8), total(i2)), pressure(inv, i2, i8)

    def energy_pressure(self, g, out, work):
        """In place, no temporaries: P bit for bit :func:`pressure`'s, ΣΦ :func:`energy` of the sums as
        :meth:`energy_sum_xp` forms it (tests/test_laws.py checks both); ΣΦ a backend scalar (no host
        sync)."""
        a, b = work
        np.reciprocal(g, out=a)      # g⁻¹
        np.multiply(a, a, out=b)     # g⁻²
        s2 = b.sum()
        np.multiply(b, b, out=out)   # g⁻⁴
        out *= out                   # g⁻⁸
        s8 = out.sum()
        out *= a                     # g⁻⁹
        b *= a                       # g⁻³
        out -= b
        out *= _C_P
        return energy(s8, s2)


LAWS.register("lj93", LJ93, aliases=("lj", "paper", "lj82"), summary="the paper's 9-3 law, Eq. (2)/(8)")
