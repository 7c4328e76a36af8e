"""The offline window fit that makes the networks' training targets (twin.loop.windowfit).

The recorded run is made by the spindle model itself with known factors on the nominal
values (heat ×1.15 on both bearings, front contact resistance ×0.7), so the fit has a true
answer to recover.
"""

from __future__ import annotations

import numpy as np
import pytest

from tests.test_replay import make_recorded_run
from twin.correction.samples import fit_samples
from twin.correction.training_data import run_curves
from twin.loop.replay import replay_method
from twin.loop.training import TRAINING_PASSES, simulate_for_training, training_simulator
from twin.loop.windowfit import WindowFit
from twin.runs import read_run

TRUE_FACTORS = np.array([1.15, 1.15, 0.7, 1.0])


@pytest.fixture(scope="module")
def run(tmp_path_factory, spindle_model):
    path = tmp_path_factory.mktemp("fit") / "run.csv"
    return read_run(make_recorded_run(path, spindle_model, minutes=6, heat=1.15,
                                      resistance=0.7))


def test_fit_recovers_the_true_factors(run, spindle_model):
    model = spindle_model
    fit = WindowFit(run, model)
    result = replay_method(run, model, fit, keep_fields=False)
    factors = np.array(fit.fitted) / np.array([list(w.nominal) for w in result.windows])
    # the heats are seen directly by T1/T3: recovered to a fraction of a percent from the
    # second window on (the first starts from the noisy mean of the first samples)
    assert factors[1:, :2] == pytest.approx(np.broadcast_to(TRUE_FACTORS[:2], (5, 2)), rel=0.01)
    # the resistances only through the ring-to-sleeve drops (tenths of a kelvin)
    assert factors[2:, 2:] == pytest.approx(np.broadcast_to(TRUE_FACTORS[2:], (4, 2)), rel=0.05)
    # driven by its own fit, the twin stays on the measurement (noise 0.02 K)
    measured = run.at(result.time_s).T_C
    assert np.sqrt(np.mean((result.T_twin_C[15:] - measured[15:]) ** 2)) < 0.03


def test_training_passes_are_seeded_and_targets_are_the_fit(run, spindle_model):
    passes = simulate_for_training(run, spindle_model)
    assert [d for d, _ in TRAINING_PASSES] == ["anchor", "anchor", "fit"]
    assert len(passes) == len(TRAINING_PASSES)
    exact, driven, fit_driven = passes
    # the first pass runs on the ratio-law anchor, the others scattered off anchor / fit;
    # every pass targets the fit from the state it reached
    assert np.array_equal(exact.used, exact.anchors)
    assert not np.allclose(driven.used, driven.anchors)
    assert not np.allclose(fit_driven.used, fit_driven.fitted)
    again = simulate_for_training(run, spindle_model)
    assert all(np.array_equal(a.fitted, b.fitted) for a, b in zip(passes, again, strict=True))
    samples = [fit_samples(c) for c in run_curves(run, training_simulator("fit", spindle_model))]
    assert len(samples[0]) == 6
    np.testing.assert_array_equal(samples[1].targets["heat_front"], driven.fitted[:, 0])
    # the inputs are what the loop shows the network at each window start
    np.testing.assert_array_equal(samples[0].inputs["heat_front"][:, 4], 60.0 * np.arange(6))
    rows = samples[0].anchored_inputs["heat_front"]
    assert np.isnan(rows[0, 3])  # window 0: no rise to compare yet (the anchor is used)
    np.testing.assert_array_equal(rows[1:, 4], 60.0 * np.arange(1, 6))
    # the sixth input is the other signal of the bearing: a heat network sees the drop
    # error a resistance network sees first, and the reverse (never its own past output)
    drop_rows = samples[0].anchored_inputs["resistance_front"]
    np.testing.assert_array_equal(rows[1:, 5], drop_rows[1:, 2])
    np.testing.assert_array_equal(drop_rows[1:, 5], rows[1:, 2])
    np.testing.assert_array_equal(samples[0].anchors["heat_front"], exact.anchors[:, 0])


def test_anchor_chain_of_the_fit_is_the_ratio_law_with_a_network_of_zero(run, spindle_model):
    # driven by its anchor, the window fit's twin runs exactly as the loop runs `bpnn` with
    # networks that output 0 and no re-run (the fit does not re-run): the anchored design
    # reproduces the ratio law (the anchor's, `ANCHOR_LAW`)
    from twin.correction.methods import ANCHOR_LAW, BpnnCorrection
    from twin.correction.modelfile import CorrectionModel
    from twin.correction.network import ANCHORED, TrainedNet

    nets = {o: TrainedNet(ANCHORED, np.ones((10 if o.startswith("heat") else 12, 6)),
                          np.zeros(10 if o.startswith("heat") else 12),
                          np.zeros((1, 10 if o.startswith("heat") else 12)), np.zeros(1),
                          np.zeros(6), np.ones(6), np.zeros(1), np.ones(1))
            for o in ("heat_front", "heat_rear", "resistance_front", "resistance_rear")}
    zero = BpnnCorrection(CorrectionModel(nets), rerun_missed_speed=False)
    bpnn = replay_method(run, spindle_model, zero, keep_fields=False)
    ratio = replay_method(run, spindle_model, ANCHOR_LAW, keep_fields=False)
    fit = WindowFit(run, spindle_model, drive="anchor")
    replay_method(run, spindle_model, fit, keep_fields=False)
    used = np.array([list(w.correction.values) for w in bpnn.windows])
    np.testing.assert_allclose(used, [list(w.correction.values) for w in ratio.windows],
                               rtol=1e-12)
    np.testing.assert_allclose(used, np.array(fit.anchors), rtol=1e-12)
    np.testing.assert_allclose(bpnn.T_twin_C, ratio.T_twin_C, rtol=1e-12)
    # with its re-run (the default) and the loads following the rings, a run at one speed
    # has nothing to re-run: the same chain
    def chain(**options):
        replay = replay_method(run, spindle_model, BpnnCorrection(CorrectionModel(nets),
                                                                  **options), keep_fields=False)
        return np.array([list(w.correction.values) for w in replay.windows])

    np.testing.assert_array_equal(chain(), used)
    # held for each window, window 0 (the cold start's loads for 60 s) is re-run before
    # window 1's correction: from then on the chain differs, window 0 itself does not
    held, rerun = chain(loads_follow_rings=False, rerun_missed_speed=False), \
        chain(loads_follow_rings=False)
    np.testing.assert_array_equal(rerun[0], held[0])
    assert np.abs(rerun[1] / held[1] - 1).max() > 1e-3


def test_fit_needs_the_twin_state(run, spindle_model):
    from twin.correction.features import BoundaryValues, WindowFeatures

    nominal = BoundaryValues(1.0, 1.0, 1.0, 1.0)
    f = WindowFeatures(0, 0.0, 9000.0, 25.0, np.zeros(1), np.zeros((1, 5)), np.zeros(1),
                       np.zeros((1, 5)), nominal, nominal)
    with pytest.raises(ValueError, match="twin's state"):
        WindowFit(run, spindle_model).correct(f)


def test_fit_stays_within_four_times_nominal(tmp_path, spindle_model):
    # a run whose bearings are far hotter than any plausible heat explains (heat ×8): the
    # Gauss–Newton steps would run the log factors off (to inf on a suite run with
    # dropouts); the fit keeps every value within ×/÷ 4 of nominal
    path = tmp_path / "hot.csv"
    hot = read_run(make_recorded_run(path, spindle_model, minutes=3, heat=8.0, resistance=1.0))
    fit = WindowFit(hot, spindle_model)
    result = replay_method(hot, spindle_model, fit, keep_fields=False)
    factors = np.array(fit.fitted) / np.array([list(w.nominal) for w in result.windows])
    assert np.all(np.isfinite(factors))
    assert np.all(factors <= 4.0 * (1 + 1e-9)) and np.all(factors >= 0.25 * (1 - 1e-9))
    assert factors[1:, :2].max() == pytest.approx(4.0)
