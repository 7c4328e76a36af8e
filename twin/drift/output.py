"""Drift outputs: PRED.csv (DESIGN.md) and metrics.json, written atomically."""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np

from twin.drift.data import DriftData
from twin.drift.metrics import target_metrics
from twin.drift.model import DriftModel
from twin.io.atomic import write_csv, write_json


def prediction_columns(targets: list[str]) -> list[str]:
    """`time_s`, then `<target>`, `<target>_lo`, `<target>_hi` per target."""
    return ["time_s"] + [f"{t}{s}" for t in targets for s in ("", "_lo", "_hi")]


def write_predictions(path: str | os.PathLike[str], model: DriftModel, data: DriftData,
                      mean: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> Path:
    """PRED.csv: time and, per target, the prediction and its 90 % interval (µm).

    The time is written to 15 digits, as read: at the CSV's 6 a logger's Unix time
    (1.7e9 s) read the same on every row, and a run's 15-s samples merged after 11 days.
    """
    table = np.stack([a[:, j] for j in range(len(model.targets)) for a in (mean, lo, hi)],
                     axis=1)
    rows = ([f"{t:.15g}", *values] for t, values in zip(data.time_s.tolist(), table.tolist(),
                                                        strict=True))
    return write_csv(path, prediction_columns(model.targets), rows)


def _finite_or_none(value: object) -> object:
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {k: _finite_or_none(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_finite_or_none(v) for v in value]
    return value


def _finite_mean(values: list[float]) -> float:
    """Mean of the finite values, NaN (null in the JSON) for none: R² of a probe that reads
    flat is undefined, and nanmean of nothing warned."""
    finite = np.asarray(values, dtype=float)
    finite = finite[np.isfinite(finite)]
    return float(finite.mean()) if finite.size else float("nan")


def fitted_share_pct(model: DriftModel, data: DriftData) -> float | None:
    """Share (%) of the data's rows in files the model was fitted on (the same time,
    temperatures, speed and drifts, `DriftData.segment_digests`), None for a model that
    does not record its data's digests: `report` on the fitting data gave 0.3 µm RMSE on
    the real step tests beside a validation of 3 µm, and only a sentence starting 'if'
    told which is which."""
    known = model.metadata.get("training_digests")
    if not isinstance(known, list):
        return None
    digests = data.segment_digests(model.spec.sensors, model.spec.uses_speed)
    fitted = np.isin(data.segment_ids(), [k for k, d in enumerate(digests) if d in known])
    return 100.0 * float(np.mean(fitted))


def drift_metrics(model: DriftModel, data: DriftData, mean: np.ndarray, lo: np.ndarray,
                  hi: np.ndarray, outside_range: dict | None = None) -> dict:
    """metrics.json: per target rmse_um, mae_um, max_abs_um, r2, coverage_90_pct; the rows
    beyond the model's operating range (`DriftModel.outside_range`, null for none)."""
    if data.targets_um is None:
        raise ValueError("the data hold no targets")
    per_target = {t: target_metrics(data.targets_um[:, j], mean[:, j], lo[:, j], hi[:, j])
                  for j, t in enumerate(model.targets)}
    keys = ("rmse_um", "mae_um", "max_abs_um", "r2", "coverage_90_pct")
    mean_of = {k: _finite_mean([m[k] for m in per_target.values()]) for k in keys}
    validation = model.metadata.get("validation", {})
    return _finite_or_none({
        "method": model.method, "files": list(data.files), "n_rows": data.n_samples,
        "sensors": list(model.spec.sensors), "targets": per_target, "mean": mean_of,
        "fitted_rows_pct": fitted_share_pct(model, data),
        "interval": model.interval, "outside_range": outside_range,
        "data_findings": data.findings,
        "validation": validation})


def write_metrics(path: str | os.PathLike[str], metrics: dict) -> Path:
    return write_json(path, metrics)
