"""90 % intervals and their coverage.

The band is calibrated on the out-of-fold residuals of the time-blocked validation, so it
reflects errors on blocks the model had not seen, not its training fit:

    half-width(x) = w · s(x) · (1 + GAIN · e(x))

- s(x) is 1 for the deterministic methods (split conformal: w in µm) and the posterior σ
  for the Bayesian network (normalised conformal: w = 1.645 · factor).
- w is calibrated *across* blocks, not over their pooled rows: each left-out block's own
  conformal quantile of |residual| / s, the largest of them taken.  A block's 15-s rows
  are strongly autocorrelated, so the exchangeable unit is the block; a pooled quantile
  let two well-predicted blocks outvote a badly predicted one (on the real step tests the
  band covered every sample of two tests and 8 % of a probe in a third).  With K blocks,
  a new block like them is covered to 90 % with probability K/(K+1) at least, no more.
- e(x) is how far the row's operating point lies outside the range the model was fitted
  on (a stopped row's thermal state too: hotter than every fitted stop), in spans of that
  range (`twin.drift.extrapolation`; 0 inside).  An error linear in
  the inputs and within ±w over the range is within ±w·(1 + 2e) at e spans beyond it:
  GAIN = 2 is that bound, not a figure fitted to the data.  w is not divided by the
  left-out blocks' own widening first: it would shrink by the blocks that extrapolated,
  and the rows that interpolate (e = 0) would keep the narrower band (on the real data
  ridge_dynamic's 3750-rpm test, covered 96 % before, fell to 39 %).  So the band is
  conservative where a left-out block's error came from extrapolating.
"""

from __future__ import annotations

import numpy as np

LEVEL = 0.90
Z90 = 1.6448536269514722
"""Two-sided 90 % quantile of the standard normal."""
GAIN = 2.0
"""Growth of the band per span of the training range a row lies beyond it (see above)."""


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


def interval_rule(predicted: np.ndarray, std: np.ndarray | None, measured: np.ndarray,
                  blocks: np.ndarray, gain: float = GAIN) -> dict:
    """The 90 % interval rule from out-of-fold predictions (JSON-ready; see the module).

    `blocks` labels the rows' validation blocks.  Without a predictive std: w in µm
    (`half_width_um`).  With one (the Bayesian posterior): the posterior σ's `factor`, at
    least 1; it says how far the posterior under-states the error on unseen blocks
    (autocorrelated residuals count as independent samples in the evidence).
    """
    score = (predicted - measured) / (1.0 if std is None else std)
    w = np.max([conformal_half_width(score[blocks == b]) for b in np.unique(blocks)], axis=0)
    widths = ({"half_width_um": w.tolist()} if std is None
              else {"factor": np.maximum(w / Z90, 1.0).tolist()})
    return {"kind": "conformal" if std is None else "scaled_posterior", **widths,
            "extrapolation_gain": gain}


def apply_interval(rule: dict, predicted: np.ndarray, std: np.ndarray | None,
                   excess: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(lo, hi) of the 90 % interval around `predicted` (n, p); `excess` (n,) the rows' e
    (a rule without `extrapolation_gain`, from a file written before it, takes none)."""
    if rule["kind"] == "conformal":
        half = np.asarray(rule["half_width_um"])[None, :]
    else:
        half = Z90 * np.asarray(rule["factor"])[None, :] * std
    if excess is not None:
        gain = float(rule.get("extrapolation_gain", 0.0))
        half = half * (1.0 + gain * np.asarray(excess, dtype=float))[:, None]
    return predicted - half, predicted + half
