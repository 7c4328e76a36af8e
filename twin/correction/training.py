"""Train the four networks on a sample set and measure them on the held-out 20 %."""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from twin.correction.features import HIDDEN_SIZES, OUTPUTS, kind_of
from twin.correction.modelfile import CorrectionModel
from twin.correction.network import (
    DEFAULT,
    GOAL_MSE,
    LEARNING_RATE,
    MAX_EPOCHS,
    TEST_FRACTION,
    NetConfig,
    TrainingHistory,
    r_squared,
    split_by_run,
    split_indices,
    train_network,
)
from twin.correction.samples import SampleSet
from twin.errors import InputError
from twin.wording import counted


@dataclass(frozen=True)
class OutputResult:
    """How one network trained: loss curves and held-out targets vs predictions."""

    history: TrainingHistory
    test_target: np.ndarray
    test_predicted: np.ndarray
    test_nominal: np.ndarray
    """The reference each held-out value is compared with: the nominal value (paper
    configuration) or the anchor, the ratio-law value (anchored configuration)."""
    r2_value: float
    """R² of the corrected value on the held-out samples (the paper's figure)."""
    r2_factor: float
    """R² of value / reference: the part the nominal value (or the anchor) does not explain."""


@dataclass(frozen=True)
class TrainingResult:
    model: CorrectionModel
    outputs: dict[str, OutputResult]
    seconds: float

    def r2_table(self) -> dict[str, dict[str, float]]:
        return {o: {"r2_value": _json_float(r.r2_value), "r2_factor": _json_float(r.r2_factor),
                    "epochs": r.history.epochs}
                for o, r in self.outputs.items()}


def train_model(
    samples: SampleSet,
    *,
    config: NetConfig = DEFAULT,
    epochs: int = MAX_EPOCHS,
    seed: int = 0,
    metadata: dict[str, Any] | None = None,
) -> TrainingResult:
    """Train the four networks with one shared 80/20 split drawn from `seed`: whole runs are
    held out (`split_by_run`) when the samples come from two runs or more."""
    if len(samples) < 5:
        raise InputError(f"too few training samples ({counted(len(samples), 'window')}); "
                         "need at least 5: give more or longer runs")
    if config.anchored and samples.anchors is None:
        raise ValueError("the anchored networks need samples with the ratio-law anchor "
                         "(window-fit targets, `--targets fit`)")
    start = time.perf_counter()
    if len(set(samples.run)) >= 2:
        split = split_by_run(samples.run, seed, TEST_FRACTION)
    else:
        split = split_indices(len(samples), seed, TEST_FRACTION)
    nets, results = {}, {}
    for i, output in enumerate(OUTPUTS):
        y = samples.targets[output]
        if config.anchored:
            x, reference = samples.anchored_inputs[output], samples.anchors[output]
        else:
            x = samples.inputs[output]
            reference = x[:, 5]
        # a stopped bearing (nominal heat 0) has no heat factor to learn, and a window whose
        # sensor the quality check excluded (stuck, dropout) has no input: both left out
        usable = ((reference > 0) & np.isfinite(x).all(axis=1) & np.isfinite(y)
                  & np.isfinite(reference) & (y > 0))
        train, test = (rows[usable[rows]] for rows in split)
        if len(train) < 2:
            # the runs' data, not the code, falls short: bad input (exit 2), said so
            raise InputError(f"too few usable windows (bearing running, sensors valid) to "
                             f"train {output} on ({len(train)} in the training split of "
                             f"{len(set(samples.run))} run(s)): give more or longer runs")
        anchor = reference if config.anchored else None
        net, history = train_network(
            x, y, train, test, config=config, hidden=HIDDEN_SIZES[kind_of(output)],
            epochs=epochs, seed=seed + i, anchor=anchor,
        )
        nominal = reference[test]
        predicted = net.predict(x[test], nominal if config.anchored else None)
        r2_factor = r_squared(y[test] / nominal, predicted / nominal)
        nets[output] = net
        results[output] = OutputResult(
            history=history,
            test_target=y[test],
            test_predicted=predicted,
            test_nominal=nominal,
            r2_value=r_squared(y[test], predicted),
            r2_factor=r2_factor,
        )
    seconds = time.perf_counter() - start
    meta = dict(metadata or {})
    meta.update(
        seed=seed,
        epochs_max=epochs,
        weight_decay=config.weight_decay,
        early_stopping=config.early_stopping,
        held_out_runs=sorted({str(r) for r in samples.run[split[1]]}),
        learning_rate=LEARNING_RATE,
        goal_mse=GOAL_MSE,
        test_fraction=TEST_FRACTION,
        samples=len(samples),
        training_runs=sorted({str(r) for r in samples.run}),
        r2=({o: {"value": _json_float(r.r2_value), "factor": _json_float(r.r2_factor)}
             for o, r in results.items()}),
    )
    return TrainingResult(CorrectionModel(nets, meta), results, seconds)


def _json_float(x: float) -> float | None:
    return float(x) if np.isfinite(x) else None
