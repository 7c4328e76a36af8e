"""Accuracy of a drift prediction per target (DESIGN.md: metrics.json; REFERENCE §5)."""

from __future__ import annotations

import numpy as np

from twin.correction.network import r_squared
from twin.drift.intervals import coverage_pct


def target_metrics(measured_um: np.ndarray, predicted_um: np.ndarray, lo_um: np.ndarray,
                   hi_um: np.ndarray) -> dict[str, float | int]:
    """rmse_um, mae_um, max_abs_um, r2, coverage_90_pct over rows with a measurement."""
    ok = np.isfinite(measured_um)
    if not ok.any():
        nan = float("nan")
        return {"n": 0, "rmse_um": nan, "mae_um": nan, "max_abs_um": nan, "r2": nan,
                "coverage_90_pct": nan}
    err = predicted_um[ok] - measured_um[ok]
    return {"n": int(ok.sum()), "rmse_um": float(np.sqrt(np.mean(err**2))),
            "mae_um": float(np.mean(np.abs(err))), "max_abs_um": float(np.max(np.abs(err))),
            "r2": r_squared(measured_um[ok], predicted_um[ok]),
            "coverage_90_pct": coverage_pct(measured_um[ok], lo_um[ok], hi_um[ok])}
