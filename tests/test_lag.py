"""The first-order lag τ·y' + y = x (`twin.lag`) against closed-form responses.

Long records of even steps run as a linear filter, short or uneven ones row by row: the
closed forms are checked on each kind of sampling.
"""

from __future__ import annotations

import numpy as np
import pytest

from twin.lag import FILTER_MIN_ROWS, first_order_lag

EVEN_S = np.arange(0.0, 1200.0, 4.0)     # long enough to run as a linear filter
SHORT_S = np.arange(0.0, 64.0, 4.0)      # an estimator window: row by row
UNEVEN_S = np.cumsum(np.r_[0.0, np.tile([1.0, 7.0, 2.5, 4.0, 0.5], 12)])
assert EVEN_S.size >= FILTER_MIN_ROWS > SHORT_S.size
SAMPLINGS = pytest.mark.parametrize("t", [EVEN_S, SHORT_S, UNEVEN_S],
                                    ids=["even", "short", "uneven"])


def ramp_response(t: np.ndarray, tau: float) -> np.ndarray:
    """y of τ·y' + y = t from y(0) = 0 (a unit ramp from rest), 0 before t = 0."""
    s = np.maximum(t, 0.0)
    return s - tau * (1.0 - np.exp(-s / tau))


@SAMPLINGS
def test_linear_form_is_exact_for_a_ramp(t):
    tau, slope = 10.0, 0.1
    y = first_order_lag(slope * t, t, tau)
    np.testing.assert_allclose(y, slope * ramp_response(t, tau), atol=1e-12)
    # columns (and further axes) are independent signals
    x = np.stack([slope * t, -2.0 * slope * t], axis=1)[:, :, None]
    y = first_order_lag(x, t, tau)
    assert y.shape == x.shape
    np.testing.assert_allclose(y[:, 1, 0], -2.0 * slope * ramp_response(t, tau), atol=1e-12)


def test_linear_form_is_exact_for_piecewise_linear_input_sampled_unevenly():
    # x: a ramp up to 60 s, held to 120 s, down at half the rate after (breakpoints on
    # every sampling); by superposition y is a sum of ramp responses at the breakpoints
    tau = 15.0
    breaks, slope_changes = np.array([0.0, 60.0, 120.0]), np.array([0.2, -0.2, -0.1])

    pieces = list(zip(breaks, slope_changes, strict=True))

    def metal(t):
        return sum(dm * np.maximum(t - b, 0.0) for b, dm in pieces)

    def expected(t):
        return sum(dm * ramp_response(t - b, tau) for b, dm in pieces)

    even = np.arange(0.0, 601.0, 2.0)
    uneven = np.unique(np.r_[breaks, np.cumsum(np.tile([0.7, 3.1, 5.3], 30))])
    uneven = uneven[uneven <= 300.0]
    for t in (even, uneven):
        np.testing.assert_allclose(first_order_lag(metal(t), t, tau), expected(t),
                                   atol=1e-12)


@SAMPLINGS
def test_held_form_of_a_step_is_one_minus_exponential(t):
    # each sample is held over the step that ends at it: from 0, the input is 1 over
    # (0, t], so y(t) = 1 − e^(−t/τ) at every sample, whatever the step lengths
    tau = 30.0
    y = first_order_lag(np.where(t > 0, 1.0, 0.0), t, tau, between="held")
    np.testing.assert_allclose(y, 1.0 - np.exp(-t / tau), atol=1e-12)


@SAMPLINGS
def test_linear_form_of_a_step_ramps_over_the_first_step(t):
    # linear between rows, the same samples are a ramp 0 → 1 over the first step h, then
    # 1: y = 1 − (τ/h)(1 − e^(−h/τ)) e^(−(t − h)/τ) from t = h on
    tau = 30.0
    h = t[1]
    y = first_order_lag(np.where(t > 0, 1.0, 0.0), t, tau)
    expected = 1.0 - tau / h * (1.0 - np.exp(-h / tau)) * np.exp(-(t[1:] - h) / tau)
    np.testing.assert_allclose(y[1:], expected, atol=1e-12)


def test_held_ramp_lags_by_less_than_the_linear_ramp():
    # a ramp sampled every h, each sample held over the step that ends at it (the input
    # runs ahead of the ramp): y − x = −m·h·a(1 − aⁱ)/(1 − a), a = e^(−h/τ), tending to
    # −m·h/(e^(h/τ) − 1), less than the −m·τ of the ramp itself (linear between samples)
    tau, h, slope = 20.0, 5.0, 0.3
    t = np.arange(0.0, 400.0, h)
    a = np.exp(-h / tau)
    i = np.arange(t.size)
    held = first_order_lag(slope * t, t, tau, between="held")
    np.testing.assert_allclose(held - slope * t, -slope * h * a * (1 - a**i) / (1 - a),
                               atol=1e-12)
    linear = first_order_lag(slope * t, t, tau)
    np.testing.assert_allclose(linear[-1] - slope * t[-1], -slope * tau, atol=1e-6)
    assert held[-1] > linear[-1]


@SAMPLINGS
@pytest.mark.parametrize("between", ["linear", "held"])
def test_start_value_relaxes_to_a_constant_input(t, between):
    tau = 12.0
    x = np.full((t.size, 2), 30.0)
    y = first_order_lag(x, t, tau, start=np.array([25.0, 31.0]), between=between)
    expected = 30.0 + np.outer(np.exp(-t / tau), [-5.0, 1.0])
    np.testing.assert_allclose(y, expected, atol=1e-12)
    # no start: settled at the first row, a constant stays constant
    np.testing.assert_allclose(first_order_lag(x, t, tau, between=between), x, atol=1e-12)


@SAMPLINGS
def test_several_time_constants_at_once(t):
    taus = np.array([5.0, 0.0, 40.0])
    slopes = np.array([0.1, -0.3])
    y = first_order_lag(np.outer(t, slopes), t, taus, start=np.zeros(2))
    assert y.shape == (t.size, 3, 2)
    for j in (0, 2):
        np.testing.assert_allclose(y[:, j], np.outer(ramp_response(t, taus[j]), slopes),
                                   atol=1e-12)
    np.testing.assert_array_equal(y[:, 1], np.outer(t, slopes))    # τ = 0: the input
    step = first_order_lag(np.where(t > 0, 1.0, 0.0), t, taus, between="held")
    np.testing.assert_allclose(step[:, [0, 2]], 1.0 - np.exp(-t[:, None] / taus[[0, 2]]),
                               atol=1e-12)


@pytest.mark.parametrize("tau", [0.0, -3.0])
def test_no_time_constant_reads_the_input_itself(tau):
    x = np.sin(EVEN_S / 17.0)
    np.testing.assert_array_equal(first_order_lag(x, EVEN_S, tau), x)
    np.testing.assert_array_equal(first_order_lag(x, EVEN_S, tau, start=5.0, between="held"), x)


def test_segments_restart_settled_and_the_start_value_is_the_first_segments():
    # two records, the second starting anew (its times restart too)
    t = np.array([0.0, 10.0, 25.0, 70.0, 0.0, 5.0, 12.0])
    x = np.array([0.0, 2.0, 2.0, 2.0, 5.0, 5.0, 5.0])
    y = first_order_lag(x, t, 30.0, between="held", segment_starts=np.array([4]))
    assert y[0] == 0.0
    np.testing.assert_allclose(y[1:4], 2.0 * (1.0 - np.exp(-t[1:4] / 30.0)), atol=1e-12)
    np.testing.assert_allclose(y[4:], 5.0, atol=1e-12)
    # a ramp in each record, the first from a start value 1 below it
    t = np.r_[EVEN_S, UNEVEN_S]
    x = 0.1 * t
    y = first_order_lag(x, t, 10.0, start=-1.0, segment_starts=[EVEN_S.size])
    np.testing.assert_allclose(y[:EVEN_S.size], 0.1 * ramp_response(EVEN_S, 10.0)
                               - np.exp(-EVEN_S / 10.0), atol=1e-12)
    np.testing.assert_allclose(y[EVEN_S.size:], 0.1 * ramp_response(UNEVEN_S, 10.0),
                               atol=1e-12)


def test_a_repeated_time_does_not_move_the_output():
    t = np.array([0.0, 5.0, 5.0, 10.0])
    x = np.array([0.0, 0.0, 1.0, 1.0])      # a jump at t = 5 s, in no time
    for between in ("linear", "held"):
        y = first_order_lag(x, t, 10.0, between=between)
        np.testing.assert_allclose(y, [0.0, 0.0, 0.0, 1.0 - np.exp(-0.5)], atol=1e-12)


def test_bad_arguments_are_refused():
    with pytest.raises(ValueError, match="rows"):
        first_order_lag(np.zeros(5), np.arange(4.0), 1.0)
    with pytest.raises(ValueError, match="between"):
        first_order_lag(np.zeros(4), np.arange(4.0), 1.0, between="cubic")
