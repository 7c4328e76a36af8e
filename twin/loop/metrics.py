"""Accuracy metrics of a replay (shared DESIGN.md, "accuracy.json").

Every metric is taken over the solver steps after the first window (the first window
has no correction yet), against the measurement at the same time, skipping samples the
data-quality check excluded (NaN in the measured arrays).

- temperature accuracy (the reference paper's style, °C):
      100 · (1 − mean_i,k |T_twin − T_meas| / max(|T_meas|, T_floor)),  T_floor = 20 °C
- temperature-rise accuracy (stricter):
      100 · (1 − Σ|T_twin − T_meas| / Σ|T_meas − T_meas(0)|)
- deformation accuracy, axial nose drift:
      100 · (1 − Σ|δ_twin − δ_meas| / Σ|δ_meas|)
- band coverage (methods with a 90 % band): share of the valid measured T1..T5 samples and
  drift samples that lie inside the band, %

Why the floor: the paper divides by the measured temperature in °C, a ratio whose zero
is where water freezes, not where the error stops mattering.  Its runs sit at workshop
temperatures (20–40 °C), where the ratio is well defined; near 0 °C it blows up (a
measured 0.0 °C gave −inf) and it depends on the scale's origin (the same run shifted
down 22 K scored 55.8 % instead of 99.5 %).  Dividing by at least `T_FLOOR_C`, a workshop
temperature, keeps the paper's value unchanged wherever every measured temperature is at
or above 20 °C (all bundled runs, the paper's runs) and gives any colder run the error
relative to that temperature: finite for any valid run, and a run shifted to below
20 °C scores as if it sat at 20 °C instead of collapsing towards −∞.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from twin.contract import SENSOR_NAMES

T_FLOOR_C = 20.0
"""Smallest denominator of the temperature accuracy (°C): a workshop temperature."""


def _nan_to_none(value: float) -> float | None:
    return None if value is None or not math.isfinite(value) else float(value)


def accuracy_metrics(
    time_s: np.ndarray,
    T_twin_C: np.ndarray,
    T_meas_C: np.ndarray,
    T_meas0_C: np.ndarray,
    drift_twin_um: np.ndarray,
    drift_meas_um: np.ndarray | None,
    first_window_end_s: float = 60.0,
    band: tuple[np.ndarray, np.ndarray] | None = None,
) -> dict:
    """Metrics of one method on one run.

    time_s (k,), T_twin_C / T_meas_C (k, 5), T_meas0_C (5,) measured at the run start,
    drift_twin_um / drift_meas_um (k,) axial nose drift (None: not measured),
    band (lo, hi), each (k, 6): T1..T5 °C and the axial drift µm (None: no band).
    """
    after = np.asarray(time_s) > first_window_end_s - 1e-9
    tw = np.asarray(T_twin_C, float)[after]
    tm = np.asarray(T_meas_C, float)[after]
    ok = np.isfinite(tm) & np.isfinite(tw)
    err = np.where(ok, np.abs(tw - tm), 0.0)
    n = int(ok.sum())
    if n == 0:
        raise ValueError("no valid temperature samples after the first window")
    scale = np.maximum(np.abs(np.where(ok, tm, T_FLOOR_C)), T_FLOOR_C)
    temp_acc = 100.0 * (1.0 - float(np.sum(err / scale)) / n)
    rise = np.where(ok, np.abs(tm - np.asarray(T_meas0_C, float)[None, :]), 0.0)
    rise_acc = 100.0 * (1.0 - err.sum() / rise.sum()) if rise.sum() > 0 else math.nan
    rmse = {}
    for i, name in enumerate(SENSOR_NAMES):
        col = ok[:, i]
        rmse[name] = _nan_to_none(
            float(np.sqrt(np.mean(err[col, i] ** 2))) if col.any() else math.nan
        )
    out = {
        "temperature_accuracy_pct": float(temp_acc),
        "temperature_rise_accuracy_pct": _nan_to_none(rise_acc),
        "deformation_accuracy_pct": None,
        "rmse_C": rmse,
        "rmse_um": None,
        "max_abs_C": float(err.max()),
        "band_coverage_pct": None,
    }
    if band is not None:
        measured = np.column_stack([
            np.asarray(T_meas_C, float),
            np.full(len(time_s), np.nan) if drift_meas_um is None else drift_meas_um,
        ])
        out["band_coverage_pct"] = band_coverage(measured[after], band[0][after], band[1][after])
    if drift_meas_um is not None:
        dm = np.asarray(drift_meas_um, float)[after]
        dt = np.asarray(drift_twin_um, float)[after]
        okd = np.isfinite(dm) & np.isfinite(dt)
        if okd.any() and np.abs(dm[okd]).sum() > 0:
            e = np.abs(dt[okd] - dm[okd])
            out["deformation_accuracy_pct"] = float(100.0 * (1.0 - e.sum() / np.abs(dm[okd]).sum()))
            out["rmse_um"] = float(np.sqrt(np.mean(e**2)))
    return out


def band_coverage(measured: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> float | None:
    """Share (%) of the finite measured values with a finite band that lie in [lo, hi]."""
    ok = np.isfinite(measured) & np.isfinite(lo) & np.isfinite(hi)
    if not ok.any():
        return None
    inside = (measured >= lo) & (measured <= hi)
    return float(100.0 * np.sum(inside & ok) / np.sum(ok))


LOWER_IS_BETTER = ("rmse_um", "max_abs_C")
"""Error metrics (the worst run has the largest value); every other metric is an accuracy
or a coverage in % (the worst run has the smallest)."""

DISTRIBUTION_METRICS = ("temperature_accuracy_pct", "temperature_rise_accuracy_pct",
                        "deformation_accuracy_pct")
"""The accuracies a batch report shows as a distribution over runs."""


def metric_values(runs: list[dict]) -> dict[str, dict[str, list[float]]]:
    """Per method and scalar metric, the finite values over the runs that have them."""
    methods: dict[str, dict[str, list[float]]] = {}
    for run in runs:
        for method, metrics in run.get("methods", {}).items():
            bucket = methods.setdefault(method, {})
            for key, value in metrics.items():
                if isinstance(value, int | float) and math.isfinite(value):
                    bucket.setdefault(key, []).append(float(value))
    return methods


def _reduce(runs: list[dict], reduce: Callable[[str, list[float]], float]) -> dict:
    return {m: {k: float(reduce(k, v)) for k, v in d.items()}
            for m, d in metric_values(runs).items()}


def mean_metrics(runs: list[dict]) -> dict:
    """Per method, the mean of each scalar metric over the runs that have it."""
    return _reduce(runs, lambda key, v: np.mean(v))


def median_metrics(runs: list[dict]) -> dict:
    """Per method, the median of each scalar metric over the runs that have it."""
    return _reduce(runs, lambda key, v: np.median(v))


def worst_metrics(runs: list[dict]) -> dict:
    """Per method, the worst run's value of each scalar metric (lowest accuracy or
    coverage, largest error)."""
    return _reduce(runs, lambda key, v: max(v) if key in LOWER_IS_BETTER else min(v))


def batch_summary(runs: list[dict], failed: list[dict]) -> dict:
    """summary.json: every run's accuracy.json, the failed runs and the statistics over
    the runs per method (shared DESIGN.md, "Replay output")."""
    return {"runs": runs, "failed": list(failed), "mean": mean_metrics(runs),
            "median": median_metrics(runs), "worst": worst_metrics(runs)}
