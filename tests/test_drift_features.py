"""Drift features and sensor ranking: closed forms and hand-computed values."""

from __future__ import annotations

import numpy as np
import pytest

from twin.drift.features import FeatureSpec, dynamic_features
from twin.drift.ranking import correlation_clusters, grey_relational_grade, rank_sensors


def test_lag_features_are_held_step_responses_tau_major_restarting_per_file():
    # two sensors stepping by 1 and 2 K after the first row, in two files of 15 s samples
    t = np.r_[np.arange(0.0, 3600.0, 15.0), np.arange(0.0, 600.0, 15.0)]
    second = np.arange(t.size) >= 240
    step = np.where((t > 0) | second, 1.0, 0.0)
    spec = FeatureSpec(("a_C", "b_C"), (20.0, 20.0), taus_min=(10.0, 30.0), groups=("lag",))
    X = dynamic_features(spec, t, 20.0 + np.c_[step, 2.0 * step], None,
                         segment_starts=np.array([0, 240]))
    assert spec.names == ["a_C:lag10min", "b_C:lag10min", "a_C:lag30min", "b_C:lag30min"]
    # each sample held over the step that ends at it: 1 − e^(−t/τ) at the samples
    first = ~second
    for col, (gain, tau_s) in enumerate([(1, 600.0), (2, 600.0), (1, 1800.0), (2, 1800.0)]):
        np.testing.assert_allclose(X[first, col], gain * (1 - np.exp(-t[first] / tau_s)),
                                   atol=1e-12)
        np.testing.assert_allclose(X[second, col], gain, atol=1e-12)  # starts settled


def test_features_are_causal():
    rng = np.random.default_rng(3)
    n = 400
    t = np.arange(n) * 15.0
    T = 25 + np.cumsum(rng.normal(0, 0.05, (n, 3)), axis=0)
    speed = np.repeat(rng.choice([0.0, 2000.0, 4000.0], n // 50), 50)
    spec = FeatureSpec(("a_C", "b_C", "c_C"), (25.0, 25.0, 25.0))
    X = dynamic_features(spec, t, T, speed)
    assert X.shape == (n, len(spec.names))
    T2, speed2 = T.copy(), speed.copy()
    T2[250:] += rng.normal(0, 3, (n - 250, 3))
    speed2[250:] = 9000.0
    X2 = dynamic_features(spec, t, T2, speed2)
    np.testing.assert_array_equal(X[:250], X2[:250])
    assert not np.allclose(X[250:], X2[250:])


def test_grey_relational_grade_matches_a_hand_computed_example():
    # mean-normalised: x0 = [.5, 1, 1.5], x1 = [6, 12, 15]/11, x2 = [1, 1, 1]
    # Δ1 = [1, 2, 3]/22, Δ2 = [.5, 0, .5]; min Δ = 0, max Δ = 0.5, ρ = 0.5
    # ξ1 = 0.25/(0.25 + k/22) = 5.5/(5.5 + k);  ξ2 = [1/3, 1, 1/3]
    x0 = np.array([1.0, 2.0, 3.0])
    candidates = np.array([[2.0, 3.0], [4.0, 3.0], [5.0, 3.0]])
    grade = grey_relational_grade(x0, candidates, rho=0.5, normalise="mean")
    expected_1 = np.mean([5.5 / 6.5, 5.5 / 7.5, 5.5 / 8.5])
    np.testing.assert_allclose(grade, [expected_1, 5.0 / 9.0], rtol=1e-12)


def test_grey_relational_grade_range_form_and_identical_series():
    x0 = np.array([0.0, 1.0, 4.0, 9.0])
    grade = grey_relational_grade(x0, np.stack([2 * x0 + 1, x0[::-1]], axis=1),
                                  normalise="range")
    assert grade[0] == pytest.approx(1.0)      # same shape after min–max scaling
    assert grade[1] < 0.7


def test_correlation_clusters_group_collinear_sensors_and_ranking_keeps_the_best():
    rng = np.random.default_rng(0)
    t = np.linspace(0, 1, 500)
    drift = np.sin(3 * t)
    a = 20 + 5 * np.sin(3 * t) + rng.normal(0, 0.01, t.size)
    a_twin = 2 * a + 1 + rng.normal(0, 0.01, t.size)        # collinear with a
    other = 20 + rng.normal(0, 1, t.size)
    T = np.stack([other, a_twin, a], axis=1)
    labels = correlation_clusters(T, min_abs_r=0.99)
    assert labels[1] == labels[2] != labels[0]
    ranking = rank_sensors(["other_C", "a_twin_C", "a_C"], T, {"d_um": drift},
                           min_abs_r=0.99)
    picked = ranking.pick()
    assert len(picked) == 2 and "other_C" in picked
    assert ranking.sensors[0] in ("a_C", "a_twin_C") and ranking.representative[0]
