"""Fitting a drift model (sensor choice, validation, default method) and predicting with it.

`fit_drift_model` ranks the sensors, picks them (`--sensors auto|K|all|LIST`), runs the
time-blocked validation of the candidate methods (all of them, or the one forced; each
fold picks its sensors on its own training rows), fits the chosen method on every row
with a measured drift, and keeps the interval rule from the out-of-fold residuals and the
operating range of its training rows (a row beyond it gets a wider band and a note).
`DriftModel.predict` is causal: the features of a row use that row and earlier rows of
its file only.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from twin.drift.data import TEMPERATURE_SUFFIX, DriftData, sensor_order
from twin.drift.extrapolation import OperatingRange, fold_excess
from twin.drift.features import FeatureSpec, dynamic_features, reference_temperatures
from twin.drift.folds import block_labels, blocked_folds
from twin.drift.intervals import apply_interval
from twin.drift.methods import METHODS, FitRows, method_named
from twin.drift.ranking import SensorRanking, rank_sensors
from twin.drift.validation import MethodValidation, choose_default, validate_method
from twin.errors import InputError

if TYPE_CHECKING:
    from threadpoolctl import threadpool_limits

Progress = Callable[[str], None] | None


@dataclass(frozen=True)
class DriftModel:
    """A fitted drift model: method, targets, features, parameters, interval rule."""

    method: str
    targets: list[str]
    spec: FeatureSpec
    params: dict[str, np.ndarray]
    interval: dict
    metadata: dict = field(default_factory=dict)
    validation: dict[str, np.ndarray] = field(default_factory=dict)
    """The chosen method's time-blocked validation: `time_s`, `block`, `measured_um`,
    `predicted_um`, `lo_um`, `hi_um` (rows with every target; (n,) or (n, p))."""

    def predict_arrays(self, time_s: np.ndarray, T_C: np.ndarray, speed_rpm: np.ndarray | None,
                       segment_starts: np.ndarray | None = None
                       ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(mean, lo, hi), each (n, p) in µm, for temperatures T_C of `spec.sensors`."""
        return self.predict_with_range(time_s, T_C, speed_rpm, segment_starts)[:3]

    def predict_with_range(self, time_s: np.ndarray, T_C: np.ndarray,
                           speed_rpm: np.ndarray | None,
                           segment_starts: np.ndarray | None = None) -> tuple[
                               np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(mean, lo, hi, excess, furthest): besides the prediction, how far each row lies
        outside the training rows' operating range (0 inside) and the index into
        `operating_range.named` of the feature furthest out."""
        with one_blas_thread():
            X = dynamic_features(self.spec, time_s, T_C, speed_rpm, segment_starts)
            mean, std = METHODS[self.method].predict(self.params, X)
            excess, furthest = np.zeros(len(X)), np.zeros(len(X), dtype=np.int64)
            if self.operating_range is not None:
                excess, furthest = self.operating_range.excess(self.spec, X)
            lo, hi = apply_interval(self.interval, mean, std, excess)
        return mean, lo, hi, excess, furthest

    @property
    def operating_range(self) -> OperatingRange | None:
        """The training rows' operating range (None in a file written before it)."""
        doc = self.interval.get("operating_range")
        return None if doc is None else OperatingRange.from_json(doc)

    def predict(self, data: DriftData) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        return self.predict_data(data)[:3]

    def predict_data(self, data: DriftData) -> tuple[np.ndarray, np.ndarray, np.ndarray,
                                                     np.ndarray, np.ndarray]:
        """`predict_with_range` of the data's rows."""
        columns = [data.sensors.index(s) for s in self.spec.sensors]
        return self.predict_with_range(data.time_s, data.T_C[:, columns], data.speed_rpm,
                                       data.segment_starts)

    def outside_range(self, excess: np.ndarray, furthest: np.ndarray) -> dict | None:
        """What to tell of the rows beyond the training rows' operating range (JSON-ready):
        their count and share, the largest excess (spans of the range), the feature it is
        in and the widening of the band there; None when every row lies inside."""
        rng = self.operating_range
        out = excess > 0
        if rng is None or not out.any():
            return None
        k = int(np.argmax(excess))
        gain = float(self.interval.get("extrapolation_gain", 0.0))
        return {"rows": int(out.sum()), "rows_pct": 100.0 * float(np.mean(out)),
                "max_excess_spans": float(excess[k]), "feature": rng.named[furthest[k]],
                "max_band_factor": 1.0 + gain * float(excess[k])}


def listed_sensors(option: str) -> list[str] | None:
    """The temperature columns a `--sensors` list names (each once), or None for `auto`,
    `all` or a count: only listed columns need be in every data file."""
    text = option.strip()
    if text in ("auto", "all") or text.isdigit():
        return None
    names = list(dict.fromkeys(n.strip() for n in text.split(",") if n.strip()))
    if not names:
        raise InputError("name at least one temperature column", column="--sensors")
    not_temperatures = [n for n in names if not n.endswith(TEMPERATURE_SUFFIX)]
    if not_temperatures:
        # a probe or the speed listed here would be read as a temperature
        raise InputError(f"not temperature columns (names ending in {TEMPERATURE_SUFFIX}): "
                         f"{', '.join(not_temperatures)}", column="--sensors")
    return names


def parse_sensors(option: str, ranking: SensorRanking, available: Sequence[str]) -> list[str]:
    """`auto` (cluster representatives), `all`, a count K (best K representatives) or a list.

    Representatives come best first (the ranking is made on the data's columns in
    `sensor_order`, ties kept in it); `all` and a list in `sensor_order`: either way the
    order of the columns in a file or a list changes nothing."""
    text = option.strip()
    if text == "all":
        return sensor_order(available)
    if text == "auto":
        return ranking.pick()
    if text.isdigit():
        k = int(text)
        if k < 1:
            raise InputError("the sensor count must be at least 1", column="--sensors")
        best = ranking.pick()
        if k > len(best):
            # K counts the clusters' best sensors; fitting on fewer than asked, silently,
            # is not what the user asked for
            raise InputError(
                f"{k} sensors asked for, but the data's {len(available)} temperature columns "
                f"form {len(best)} correlation clusters: give at most {len(best)}, or 'all' "
                "for every column", column="--sensors")
        return best[:k]
    names = listed_sensors(text) or []
    unknown = [n for n in names if n not in available]
    if unknown or not names:
        raise InputError(f"unknown temperature columns {unknown}; the data hold "
                         f"{', '.join(available)}", column="--sensors")
    # a set: listed in another order, the features (and a network's start) were another
    return sensor_order(names)


def sensor_ranking(data: DriftData) -> SensorRanking:
    """Rank the data's temperature sensors for its targets (rows with every target)."""
    rows = measured_rows(data)
    targets = {t: data.targets_um[rows, j] for j, t in enumerate(data.targets)}
    for name, values in targets.items():
        if np.ptp(values) == 0:  # no grade, no correlation, no fit: every grade was NaN
            raise InputError(f"never changes (every sample {values[0]:g} µm): a probe that does "
                             "not move leaves nothing to model", file=", ".join(data.files),
                             column=name)
    return rank_sensors(data.sensors, data.T_C[rows], targets)


def sensors_per_fold(option: str, data: DriftData, rows: np.ndarray,
                     blocks: np.ndarray) -> list[list[str]] | None:
    """The sensors `--sensors auto|K` picks from each validation fold's training rows
    (`blocked_folds` order), or None for `all` or a list, which no drift decides.

    Picked on every row, the left-out block's drift had its say in which sensors predict
    it (its grade and the cluster representatives): a leak of the test targets into the
    validation.  A fold whose sensors form fewer clusters than K asked for takes them all.
    """
    text = option.strip()
    if text != "auto" and not text.isdigit():
        return None
    k = None if text == "auto" else int(text)
    picked = []
    with np.errstate(invalid="ignore", divide="ignore"):  # a probe still in a fold: NaN
        for train, _ in blocked_folds(rows.size, blocks):
            fit_rows = rows[train]
            ranking = rank_sensors(data.sensors, data.T_C[fit_rows],
                                   {t: data.targets_um[fit_rows, j]
                                    for j, t in enumerate(data.targets)})
            picked.append(ranking.pick(k))
    return picked


MIN_MEASURED_ROWS = 20


def measured_rows(data: DriftData, every_file: bool = False) -> np.ndarray:
    """The rows with every target measured: at least `MIN_MEASURED_ROWS` of them, and with
    `every_file` in each file (time-blocked validation holds each file out in turn and
    fits on the others: a one-row file left one row to fit on)."""
    if data.targets_um is None:
        raise InputError("no target column given", column="--target")
    rows = np.flatnonzero(np.all(np.isfinite(data.targets_um), axis=1))
    counts = [(data.files[0], rows.size, "")]
    if every_file and len(data.files) > 1:
        per_file = np.bincount(data.segment_ids()[rows], minlength=len(data.files))
        counts = [(f, int(n), " in every file") for f, n in zip(data.files, per_file,
                                                                  strict=True)]
    for file, count, where in counts:
        if count < MIN_MEASURED_ROWS:
            rows_hold = "1 sample holds" if count == 1 else f"{count} samples hold"
            raise InputError(f"only {rows_hold} every target; need at least "
                             f"{MIN_MEASURED_ROWS}{where}", file=file,
                             column=",".join(data.targets))
    return rows


def _methods_without_speed(names: list[str], method: str | None, data: DriftData,
                           progress: Progress) -> list[str]:
    """The methods of `names` that need no speed, for data without `speed_rpm` in every
    file (it is optional); a forced method that needs it is bad input."""
    def needs_speed(name: str) -> bool:
        return FeatureSpec((), (), groups=METHODS[name].groups).uses_speed

    usable = [n for n in names if not needs_speed(n)]
    if method is not None and not usable:
        without = [n for n in METHODS if not needs_speed(n)]
        raise InputError(f"method {method!r} needs speed_rpm, which not every file holds: "
                         f"give it in every file, or use {' or '.join(without)}",
                         file=", ".join(data.files), column="--method")
    if not usable:
        raise InputError("every candidate method needs speed_rpm, which not every file "
                         "holds", file=", ".join(data.files))
    if progress and usable != names:
        progress(f"no speed_rpm in every file: validating {', '.join(usable)} only")
    return usable


def one_blas_thread() -> threadpool_limits:
    """Run numpy/scipy/scikit-learn linear algebra on one thread.

    Bit-for-bit repeatable results (threaded BLAS reductions may sum in another order)
    and, on a machine whose cores are busy, far faster: threaded OpenBLAS spins waiting
    for a core (a least-squares solve took 20× longer with two threads under load).
    """
    from threadpoolctl import threadpool_limits

    return threadpool_limits(limits=1)


def fit_drift_model(data: DriftData, method: str | None = None, sensors: str = "auto",
                    seed: int = 0, progress: Progress = None,
                    candidates: Sequence[str] | None = None) -> DriftModel:
    """Fit a drift model; `method` None picks the best of `candidates` (default: all)."""
    with one_blas_thread():
        return _fit_drift_model(data, method, sensors, seed, progress, candidates)


def _fit_drift_model(data: DriftData, method: str | None, sensors: str, seed: int,
                     progress: Progress, candidates: Sequence[str] | None) -> DriftModel:
    if method is not None:
        method_named(method)
    ranking = sensor_ranking(data)
    chosen_sensors = parse_sensors(sensors, ranking, data.sensors)
    rows = measured_rows(data, every_file=True)
    Y = data.targets_um[rows]
    blocks = block_labels(data.n_samples, data.segment_ids())[rows]
    names = [method] if method else list(candidates or METHODS)
    if data.speed_rpm is None:
        names = _methods_without_speed(names, method, data, progress)
    features: dict[tuple[tuple[str, ...], tuple[str, ...]], tuple[FeatureSpec, np.ndarray]] = {}

    def features_of(sensor_names: Sequence[str], groups: tuple[str, ...]
                    ) -> tuple[FeatureSpec, np.ndarray]:
        key = (tuple(sensor_names), groups)
        if key not in features:
            cols = [data.sensors.index(s) for s in sensor_names]
            spec = FeatureSpec(key[0], tuple(float(v) for v in reference_temperatures(
                data.T_C[:, cols])), groups=groups)
            features[key] = spec, dynamic_features(spec, data.time_s, data.T_C[:, cols],
                                                   data.speed_rpm, data.segment_starts)[rows]
        return features[key]

    fold_sensors = sensors_per_fold(sensors, data, rows, blocks)
    folds = blocked_folds(rows.size, blocks)
    results: list[MethodValidation] = []
    for name in names:
        groups = METHODS[name].groups
        per_fold = [features_of(s, groups) for s in (fold_sensors or [chosen_sensors]
                                                     * len(folds))]
        fold_X = None if fold_sensors is None else [X for _, X in per_fold]
        excess = fold_excess([spec for spec, _ in per_fold], [X for _, X in per_fold], folds,
                             rows.size)
        results.append(validate_method(name, features_of(chosen_sensors, groups)[1], Y,
                                       data.time_s[rows], blocks, seed, progress, fold_X,
                                       excess))
    best = method or choose_default(results)
    result = next(r for r in results if r.name == best)
    spec, X = features_of(chosen_sensors, METHODS[best].groups)
    if progress:
        progress(f"fitting {best} on all rows")
    params = METHODS[best].fit(FitRows(X, Y, data.time_s[rows], blocks, seed, progress))
    metadata = {
        "training_files": list(data.files), "n_rows": int(rows.size), "seed": seed,
        # what `report` tells in-sample data by, whatever the file is called now
        "training_digests": data.segment_digests(chosen_sensors, spec.uses_speed),
        "sensors_option": sensors, "ranking": ranking.to_json(),
        "validation": {"blocks": int(np.unique(blocks).size), "chosen": best,
                       "sensors_per_block": fold_sensors,
                       "methods": {r.name: r.to_json(data.targets) for r in results}},
        "data_findings": data.findings,
    }
    if data.left_out:
        metadata["sensors_left_out"] = data.left_out
    validation = {"time_s": data.time_s[rows], "block": blocks.astype(float), "measured_um": Y,
                  "predicted_um": result.predicted, "lo_um": result.lo, "hi_um": result.hi}
    interval = {**result.interval, "operating_range": OperatingRange.of(spec, X).to_json()}
    return DriftModel(best, list(data.targets), spec,
                      {k: np.asarray(v, dtype=float) for k, v in params.items()},
                      interval, metadata, validation)
