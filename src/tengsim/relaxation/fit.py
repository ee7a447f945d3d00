"""A Prony series fitted to DMA data: storage and loss modulus against frequency.

E'(ω) = E∞ + Σ E_i ω²τ_i²/(1 + ω²τ_i²), E''(ω) = Σ E_i ωτ_i/(1 + ω²τ_i²) are linear in (E∞, E_i): on a
log-spaced τ grid (``per_decade`` times per decade from whole decades, one beyond the data's 1/ω at each end) the
non-negative moduli are the linear least-squares solution (``scipy.optimize.nnls``), each row weighted by
1/|measured| so that E' and E'' count alike.  The fit's error is stated: the RMS and the largest relative
residual of E' and of E''.  Branches fitted to zero are dropped.
"""
from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from tengsim.errors import TengsimError
from tengsim.relaxation.prony import Prony


@dataclass(frozen=True)
class DMAFit:
    """The fitted series and its error: RMS and max relative residual of E' and E'' over the data."""

    prony: Prony
    rms_storage: float
    rms_loss: float
    max_storage: float
    max_loss: float
    points: int

    def summary(self) -> str:
        return (f"Prony fit to {self.points} DMA points, {self.prony.branches} branches: relative error E' "
                f"rms {self.rms_storage:.2%} (max {self.max_storage:.2%}), E'' rms {self.rms_loss:.2%} "
                f"(max {self.max_loss:.2%})")


def fit_dma(f, storage, loss, per_decade: float = 1.0, source: str = "") -> DMAFit:
    """Fit a Prony series to DMA data: ``f`` (Hz), ``storage`` E' and ``loss`` E'' (Pa), arrays of one length."""
    from scipy.optimize import nnls

    f, Es, El = (np.asarray(x, float).ravel() for x in (f, storage, loss))
    if not (f.size == Es.size == El.size) or f.size < 3:
        raise TengsimError(f"DMA data needs >= 3 rows of frequency, storage and loss, got {f.size}")
    if not (np.all(np.isfinite(f)) and np.all(f > 0)):
        raise TengsimError("DMA frequencies must be finite and > 0 Hz")
    if not (np.all(Es > 0) and np.all(El >= 0) and np.all(np.isfinite(El))):
        raise TengsimError("DMA storage moduli must be > 0 and loss moduli >= 0 (Pa)")
    if not per_decade > 0:
        raise TengsimError(f"per_decade must be > 0, got {per_decade!r}")
    w = 2 * np.pi * f
    lo, hi = math.floor(math.log10(1 / w.max())) - 1, math.ceil(math.log10(1 / w.min())) + 1  # whole decades
    n = max(1, int(round((hi - lo) * per_decade)) + 1)
    tau = np.logspace(lo, hi, n)
    wt = w[:, None] * tau[None, :]
    A_s = np.hstack([np.ones((f.size, 1)), wt**2 / (1 + wt**2)])
    A_l = np.hstack([np.zeros((f.size, 1)), wt / (1 + wt**2)])
    scale_l = np.where(El > 0, El, Es)  # a zero loss weighted by the storage
    A = np.vstack([A_s / Es[:, None], A_l / scale_l[:, None]])
    b = np.concatenate([np.ones(f.size), El / scale_l])
    cols = A.max(axis=0)
    x, _ = nnls(A / cols, b)
    x = x / cols
    keep = x[1:] > 1e-12 * max(x.max(), 1e-300)
    if not x[0] > 0:
        raise TengsimError("the DMA fit found no long-time modulus E_inf > 0: extend the data to lower frequencies")
    prony = Prony(float(x[0]), tuple(x[1:][keep]), tuple(tau[keep]), source or "Prony fit to DMA data")
    rs = prony.storage(f) / Es - 1
    rl = np.where(El > 0, (prony.loss(f) - El) / scale_l, 0.0)
    return DMAFit(prony, float(np.sqrt(np.mean(rs**2))), float(np.sqrt(np.mean(rl**2))),
                  float(np.abs(rs).max()), float(np.abs(rl).max()), int(f.size))


def read_dma(path, per_decade: float = 1.0) -> DMAFit:
    """Fit a DMA CSV: columns frequency (Hz), storage and loss modulus (Pa; a header row may name units
    as 'storage_MPa' / 'loss_kPa' / '... (MPa)')."""
    p = Path(path)
    try:
        rows = [r for r in csv.reader(p.read_text().splitlines()) if r and not r[0].lstrip().startswith("#")]
    except OSError as e:
        raise TengsimError(f"cannot read DMA file {str(p)!r}: {e.strerror}") from None
    except (UnicodeDecodeError, csv.Error):
        raise TengsimError(f"DMA file {str(p)!r}: not a text (CSV) file") from None
    factor = 1.0
    if rows and not _is_number(rows[0][0]):
        head = ",".join(rows[0])
        for unit, fac in (("GPa", 1e9), ("MPa", 1e6), ("kPa", 1e3)):
            if unit in head:
                factor = fac
                break
        rows = rows[1:]
    try:
        data = np.array([[float(c) for c in r[:3]] for r in rows], float)
    except ValueError:
        raise TengsimError(f"DMA file {str(p)!r}: every row must be three numbers (frequency, storage, loss)") from None
    if data.ndim != 2 or data.shape[1] != 3:
        raise TengsimError(f"DMA file {str(p)!r}: needs three columns (frequency Hz, storage, loss)")
    return fit_dma(data[:, 0], data[:, 1] * factor, data[:, 2] * factor, per_decade, f"Prony fit to {p.name}")


def _is_number(s: str) -> bool:
    try:
        float(s)
        return True
    except ValueError:
        return False
