"""A generalized Maxwell solid as a frozen value: E(t) = E∞ + Σ_i E_i exp(−t/τ_i) (Pa, s).

The series is the relaxation modulus of the material's plane-strain modulus E*(t) up to one constant factor
(ν constant): only ratios E(t)/E_ref enter the contact, whose coupling is κ ∝ 1/E* (:mod:`tengsim.units`).
The exact update over a time step (:meth:`Prony.step_factors`) is the one :mod:`tengsim.visco.memory` uses.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tengsim.errors import TengsimError


@dataclass(frozen=True)
class Prony:
    """E(t) = E_inf + Σ E[i] exp(−t/tau[i]); moduli in Pa, times in s; no branch: an elastic solid."""

    E_inf: float
    E: tuple = ()
    tau: tuple = ()
    source: str = ""

    def __post_init__(self):
        E, tau = tuple(float(x) for x in self.E), tuple(float(x) for x in self.tau)
        object.__setattr__(self, "E", E)
        object.__setattr__(self, "tau", tau)
        if not (math.isfinite(self.E_inf) and self.E_inf > 0):
            raise TengsimError(f"relaxation E_inf must be a modulus > 0, got {_modulus(self.E_inf)}")
        if len(E) != len(tau):
            raise TengsimError(f"relaxation: {len(E)} branch moduli but {len(tau)} relaxation times")
        for i, (e, t) in enumerate(zip(E, tau)):
            if not (math.isfinite(e) and e >= 0):
                raise TengsimError(f"relaxation branch {i + 1}: E must be >= 0, got {_modulus(e)}")
            if not (math.isfinite(t) and t > 0):
                raise TengsimError(f"relaxation branch {i + 1}: tau must be > 0, got {t:g} s")

    @property
    def E0(self) -> float:
        """The instantaneous (glassy) modulus E∞ + Σ E_i (Pa)."""
        return self.E_inf + sum(self.E)

    @property
    def branches(self) -> int:
        return len(self.E)

    def relaxation(self, t):
        """E(t) (Pa) for t >= 0 (s)."""
        t = np.asarray(t, float)
        out = np.full(t.shape, self.E_inf)
        for e, tau in zip(self.E, self.tau):
            out = out + e * np.exp(-t / tau)
        return out

    def storage(self, f):
        """Storage modulus E'(f) (Pa) at frequency f (Hz)."""
        w = 2 * np.pi * np.asarray(f, float)
        out = np.full(w.shape, self.E_inf)
        for e, tau in zip(self.E, self.tau):
            x = (w * tau) ** 2
            out = out + e * x / (1 + x)
        return out

    def loss(self, f):
        """Loss modulus E''(f) (Pa) at frequency f (Hz)."""
        w = 2 * np.pi * np.asarray(f, float)
        out = np.zeros(w.shape)
        for e, tau in zip(self.E, self.tau):
            out = out + e * w * tau / (1 + (w * tau) ** 2)
        return out

    def step_factors(self, dt: float):
        """(a, γ) per branch over a step dt >= 0 (s): a_i = exp(−dt/τ_i), γ_i = (τ_i/dt)(1 − a_i) (1 at dt = 0),
        the exact integration of dq/dt + q/τ = E du/dt with u linear over the step."""
        if not dt >= 0:
            raise TengsimError(f"time step must be >= 0, got {dt!r} s")
        tau = np.asarray(self.tau, float)
        x = dt / tau
        a = np.exp(-x)
        gamma = np.where(x > 1e-8, -np.expm1(-x) / np.where(x > 0, x, 1.0), 1.0 - x / 2)
        return a, gamma

    def effective(self, dt: float) -> float:
        """The instantaneous modulus of a step dt: E∞ + Σ E_i γ_i (Pa): E0 at dt = 0, → E∞ for dt ≫ τ_i."""
        _, gamma = self.step_factors(dt)
        return float(self.E_inf + np.dot(np.asarray(self.E, float), gamma))

    def scaled(self, factor: float) -> "Prony":
        """The series times ``factor`` (e.g. E → E* = E/(1 − ν²))."""
        return Prony(self.E_inf * factor, tuple(e * factor for e in self.E), self.tau, self.source)

    def params(self) -> dict:
        return {"relaxation_E_inf_Pa": self.E_inf, "relaxation_E_Pa": list(self.E),
                "relaxation_tau_s": list(self.tau), "relaxation_E0_Pa": self.E0,
                **({"relaxation_source": self.source} if self.source else {})}


def sls(E_inf: float, E1: float, tau: float) -> Prony:
    """The standard linear solid (one Maxwell branch beside a spring)."""
    return Prony(E_inf, (E1,), (tau,), "standard linear solid")


def sls_creep(t, E_inf: float, E1: float, tau: float):
    """Creep compliance J(t) (1/Pa) of the standard linear solid E(t) = E∞ + E1 e^{−t/τ}, in closed form:
    J(t) = 1/E∞ − (1/E∞ − 1/E0) exp(−t/τ_c), E0 = E∞ + E1, retardation time τ_c = τ E0/E∞."""
    E0 = E_inf + E1
    tc = tau * E0 / E_inf
    return 1 / E_inf - (1 / E_inf - 1 / E0) * np.exp(-np.asarray(t, float) / tc)


def sylgard184() -> Prony:
    """Representative Sylgard 184 (10:1, cured ~ 65–100 °C), Young's modulus at room temperature.

    Not a fit to one published table: E∞ = 1.5 MPa lies in the 1–3 MPa spread that Varner & Cohen (2024,
    arXiv:2404.16960) compile for 10:1 cures; four decades of branches (10 ms – 10 s) give a loss tangent of
    0.02–0.06 and a storage modulus rising ~ 20 % from 0.01 to 100 Hz, the size DMA studies of Sylgard 184
    at room temperature report (e.g. Kunzemann et al. 2024, arXiv:2402.07555, a Prony series from DMTA master
    curves: use its table, or fit your own DMA data with ``tengsim.relaxation.fit_dma``, for numbers)."""
    return Prony(1.5e6, (0.12e6, 0.08e6, 0.06e6, 0.05e6), (0.01, 0.1, 1.0, 10.0),
                 "representative Sylgard 184 (tengsim.relaxation.sylgard184; see its doc)")


def _modulus(pa: float) -> str:
    """A modulus in the user's units for a message (e.g. '-1 MPa'); a value that is no number as it is."""
    from tengsim.units import pressure_text

    return pressure_text(pa) if math.isfinite(pa) else repr(pa)
