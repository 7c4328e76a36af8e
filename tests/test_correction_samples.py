"""Curve fits and training samples from arrays (synthetic curves with a known truth)."""

import numpy as np
import pytest

from twin.correction.curvefit import fit_rise_curve, two_exponential_rise
from twin.correction.samples import (
    RunCurves,
    SampleSet,
    build_samples,
    open_loop_curves,
    sample_times,
)
from twin.correction.toy_plant import ToyPlant


def test_two_exponential_fit_recovers_the_curve():
    t = np.arange(0, 1801, 2.0)
    truth = two_exponential_rise(t, 25.3, 2.0, 90.0, 4.0, 700.0)
    noisy = truth + np.random.default_rng(3).normal(0, 0.05, t.size)
    noisy[100:110] = np.nan  # a dropout
    curve = fit_rise_curve(t, noisy)
    assert curve.rms_residual_C == pytest.approx(0.05, rel=0.15)
    assert np.max(np.abs(curve(t) - truth)) < 0.05
    # the window rise at 200 s (the paper's weak spot) from the fit
    rise = curve(260.0) - curve(200.0)
    assert rise == pytest.approx(truth[130] - truth[100], abs=0.02)


def test_fit_restarts_at_a_speed_change():
    t = np.arange(0, 1201, 4.0)
    first = two_exponential_rise(t, 25.0, 1.0, 60.0, 2.0, 400.0)
    level = two_exponential_rise(600.0, 25.0, 1.0, 60.0, 2.0, 400.0)
    second = two_exponential_rise(t - 600.0, level, 1.5, 50.0, 1.0, 300.0)
    T = np.where(t < 600, first, second)
    speed = np.where(t < 600, 8000.0, 11000.0)
    curve = fit_rise_curve(t, T, speed)
    assert len(curve.pieces) == 2
    assert np.max(np.abs(curve(t) - T)) < 0.01


def test_sample_times_dense_early():
    times = sample_times(1800.0, 60.0, dense_until_s=600.0, dense_step_s=20.0)
    assert times[0] == 0.0 and times[-1] == 1740.0
    assert np.all(np.diff(times[times < 600]) == 20.0)
    assert np.all(np.diff(times[times >= 600]) == 60.0)


def _plant_run(speed, heat_factor, res_factor, seed=0):
    plant = ToyPlant()
    t = np.arange(0, 1801, 2.0)
    H = plant.nominal_heat_W_m3(speed)
    R = plant.nominal_resistance_m2K_W(speed)
    T = plant.simulate(t, speed, 25.0, H * heat_factor, R * res_factor)
    T = T + np.random.default_rng(seed).normal(0, 0.05, T.shape)
    ts = np.arange(0, 1801, 4.0)
    Ts = plant.simulate(ts, speed, 25.0, H, R)
    return open_loop_curves(f"run{speed:.0f}", t, np.full(t.size, speed), np.full(t.size, 25.0),
                            T, ts, Ts, np.r_[H, R])


def test_targets_recover_a_known_truth():
    truth_heat, truth_res = np.array([1.1, 0.9]), np.array([1.3, 0.8])
    curves = _plant_run(9000.0, truth_heat, truth_res)
    s = build_samples(curves)
    nominal = np.asarray(curves.nominal)
    late = s.time_s >= 1200
    # heat: late in the run the total-rise ratio approaches the truth; part of the front
    # ring's rise comes from the motor (housing), which dilutes it slightly
    heat = np.column_stack([s.targets["heat_front"], s.targets["heat_rear"]])[late] / nominal[:2]
    assert heat.mean(axis=0) == pytest.approx(truth_heat, abs=0.05)
    res = np.column_stack([s.targets["resistance_front"],
                           s.targets["resistance_rear"]])[late] / nominal[2:]
    assert res.mean(axis=0) == pytest.approx(truth_res, abs=0.08)
    # an untouched plant gives neutral targets
    neutral = build_samples(_plant_run(9000.0, np.ones(2), np.ones(2)))
    for output, target in neutral.targets.items():
        i = ["heat_front", "heat_rear", "resistance_front", "resistance_rear"].index(output)
        assert np.median(target / nominal[i]) == pytest.approx(1.0, abs=0.03), output


def test_inputs_are_causal_and_shaped():
    curves = _plant_run(7000.0, np.ones(2), np.ones(2))
    s = build_samples(curves)
    assert s.inputs["heat_front"].shape == (len(s), 6)
    row = np.flatnonzero(s.time_s == 300.0)[0]
    x = s.inputs["resistance_rear"][row]
    i = np.flatnonzero(curves.time_s <= 300.0)[-1]
    assert x[0] == 7000.0 and x[1] == 25.0 and x[4] == 300.0
    assert x[2] == pytest.approx(curves.measured_C[i, 2] - curves.measured_C[i, 3])
    both = SampleSet.concatenate([s, s])
    assert len(both) == 2 * len(s)


def test_run_curves_rejects_bad_shapes():
    with pytest.raises(ValueError, match="measured_C"):
        RunCurves("x", np.arange(3.0), np.ones(3), np.ones(3), np.ones((3, 4)), np.arange(3.0),
                  np.ones((3, 5)), np.ones(4), np.ones(4))
    with pytest.raises(ValueError, match="nominal"):
        RunCurves("x", np.arange(3.0), np.ones(3), np.ones(3), np.ones((3, 5)), np.arange(3.0),
                  np.ones((3, 5)), -np.ones(4), np.ones(4))
