"""90 % intervals and their coverage.

Deterministic models get split-conformal intervals: the half-width per target is the
⌈(n+1)·0.9⌉-th smallest absolute out-of-fold residual of the time-blocked validation, so
the band reflects errors on blocks the model had not seen, not its training fit.  The
Bayesian network's posterior σ is kept as the shape of its band (see `interval_rule`).
"""

from __future__ import annotations

import numpy as np

LEVEL = 0.90
Z90 = 1.6448536269514722
"""Two-sided 90 % quantile of the standard normal."""


def conformal_half_width(residuals: np.ndarray, level: float = LEVEL) -> np.ndarray:
    """Half-width per column of `residuals` (n, p) (NaN rows ignored per column)."""
    residuals = np.atleast_2d(np.asarray(residuals, dtype=float).T).T
    out = np.empty(residuals.shape[1])
    for j in range(residuals.shape[1]):
        r = np.sort(np.abs(residuals[:, j][np.isfinite(residuals[:, j])]))
        if r.size == 0:
            out[j] = np.nan
            continue
        k = int(np.ceil((r.size + 1) * level)) - 1
        out[j] = r[min(k, r.size - 1)]
    return out


def coverage_pct(measured: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> float:
    """Share (%) of the measured values (finite ones) inside [lo, hi]."""
    ok = np.isfinite(measured)
    if not ok.any():
        return float("nan")
    inside = (measured[ok] >= lo[ok]) & (measured[ok] <= hi[ok])
    return 100.0 * float(np.mean(inside))


def interval_rule(predicted: np.ndarray, std: np.ndarray | None, measured: np.ndarray) -> dict:
    """The 90 % interval rule from out-of-fold predictions (JSON-ready).

    Without a predictive std: split-conformal half-widths (µm).  With one (the Bayesian
    posterior): normalised conformal — the posterior σ is scaled by the factor that makes
    90 % of the out-of-fold |residual|/σ fall inside ±1.645·σ·factor; the factor says how
    far the posterior under-states the error on unseen blocks (autocorrelated residuals
    count as independent samples in the evidence).
    """
    residual = predicted - measured
    if std is None:
        return {"kind": "conformal", "half_width_um": conformal_half_width(residual).tolist()}
    factor = conformal_half_width(residual / std) / Z90
    return {"kind": "scaled_posterior", "factor": np.maximum(factor, 1.0).tolist()}


def apply_interval(rule: dict, predicted: np.ndarray,
                   std: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
    """(lo, hi) of the 90 % interval around `predicted` (n, p)."""
    if rule["kind"] == "conformal":
        half = np.asarray(rule["half_width_um"])[None, :]
    else:
        half = Z90 * np.asarray(rule["factor"])[None, :] * std
    return predicted - half, predicted + half
