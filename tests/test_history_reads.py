"""A window's reads of the measured history by bisection (`rows_between`) and by blocks
from one end (`first_finite`, `last_at_or_before`) give what the whole-history boolean
masks they replace gave, rows and values, on ascending times with repeats and gaps."""

from __future__ import annotations

import numpy as np
import pytest

from twin.correction.features import (
    BoundaryValues,
    WindowFeatures,
    bin_mean,
    first_finite,
    last_at_or_before,
    rows_between,
    window_line_fit,
    window_observed,
)
from twin.correction.rerun import speed_change_s


def _history(seed: int, n: int = 3000) -> tuple[np.ndarray, np.ndarray]:
    """Ascending times (1 Hz with jitter, repeated stamps and a logger gap) and five
    columns with NaN spells, one column NaN up to late in the run, one all NaN."""
    rng = np.random.default_rng(seed)
    t = np.cumsum(rng.choice([0.0, 0.7, 1.0, 1.3], size=n, p=[0.05, 0.2, 0.6, 0.15]))
    t[n // 2:] += 400.0  # a gap
    v = 20.0 + rng.normal(size=(n, 5))
    v[rng.random((n, 5)) < 0.3] = np.nan
    v[: n - 50, 3] = np.nan  # valid only in the last 50 rows
    v[:, 4] = np.nan
    return t, v


def _naive_last(t: np.ndarray, v: np.ndarray, t_s: float) -> np.ndarray:
    out = np.full(v.shape[1], np.nan)
    for j in range(v.shape[1]):
        idx = np.flatnonzero((t <= t_s + 1e-9) & np.isfinite(v[:, j]))
        if idx.size:
            out[j] = v[idx[-1], j]
    return out


def _naive_first(v: np.ndarray) -> np.ndarray:
    out = np.full(v.shape[1], np.nan)
    for j in range(v.shape[1]):
        idx = np.flatnonzero(np.isfinite(v[:, j]))
        if idx.size:
            out[j] = v[idx[0], j]
    return out


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_rows_between_are_the_masks_rows(seed: int) -> None:
    t, _ = _history(seed)
    rng = np.random.default_rng(seed + 10)
    # bounds on sample times exactly (ties), between them, before and after the run
    bounds = np.r_[t[rng.integers(0, t.size, 40)], rng.uniform(-10, t[-1] + 10, 40), -np.inf]
    for lo in bounds:
        for hi in (lo + 20.0, lo + 60.0, t[-1], np.inf, lo):
            mask = (t > lo) & (t <= hi)
            assert np.array_equal(np.arange(t.size)[rows_between(t, lo, hi)],
                                  np.flatnonzero(mask))
            strict = (t > lo) & (t < hi)
            assert np.array_equal(np.arange(t.size)[rows_between(t, lo, hi, with_upto=False)],
                                  np.flatnonzero(strict))


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_first_and_last_finite_are_the_whole_history_scans(seed: int) -> None:
    t, v = _history(seed)
    assert np.array_equal(first_finite(v), _naive_first(v), equal_nan=True)
    for cut in (0, 1, 63, 64, 65, 200, v.shape[0]):  # block edges of the search
        assert np.array_equal(first_finite(v[:cut]), _naive_first(v[:cut]), equal_nan=True)
    for t_s in np.r_[t[::97], t[0] - 1.0, t[-1] + 1.0, t[-1]]:
        assert np.array_equal(last_at_or_before(t, v, t_s), _naive_last(t, v, t_s),
                              equal_nan=True)
    assert np.isnan(first_finite(v)[4]) and np.isnan(last_at_or_before(t, v, t[-1])[4])
    assert first_finite(v)[3] == v[np.flatnonzero(np.isfinite(v[:, 3]))[0], 3]


def test_window_reads_on_a_suffix_of_history_match_the_masks() -> None:
    """bin_mean, window_observed and window_line_fit, read on a whole 3000-row history,
    give bit for bit what the same functions give on the window's rows alone (what the
    masks selected), so the bisection changes no value."""
    t, v = _history(3)
    for end in (600.0, 1200.0, float(t[1800]), float(t[-1])):
        window = (t > end - 60.0 - 1e-9) & (t <= end + 1e-9)
        tw, vw = t[window], v[window]
        for lo in (end - 60.0, end - 40.0, end - 20.0):
            whole = bin_mean(t, v, lo, lo + 20.0)
            alone = bin_mean(tw, vw, lo, lo + 20.0)
            assert np.array_equal(whole[0], alone[0], equal_nan=True)
            assert np.array_equal(whole[1], alone[1])
        assert np.array_equal(window_observed(t, v, end), window_observed(tw, vw, end))
        for a, b in zip(window_line_fit(t, v, end), window_line_fit(tw, vw, end), strict=True):
            assert np.array_equal(a, b, equal_nan=True)


def test_speed_change_is_found_by_bisection() -> None:
    """The first recorded speed in the window just ended that differs from the forecast,
    not the sample on the window's end (the next window's speed)."""
    t = np.arange(0.0, 180.5, 1.0)
    T = np.full((t.size, 5), 30.0)
    nominal = BoundaryValues(1e6, 1e6, 1e-4, 1e-4)

    def change(speed: np.ndarray) -> float | None:
        f = WindowFeatures(3, 180.0, 9000.0, 20.0, t, T, t[:1], T[:1], nominal, nominal,
                           measured_speed_rpm=speed)
        return speed_change_s(f, 9000.0)

    assert change(np.where(t > 150.0, 12000.0, 9000.0)) == 151.0
    assert change(np.where(t >= 180.0, 12000.0, 9000.0)) is None  # on the window's end
    assert change(np.where(t <= 120.0, 12000.0, 9000.0)) is None  # before the window
    assert change(np.where(t == 121.0, 0.0, 9000.0)) == 121.0  # its first sample


def _dead_ring_features(sim_gap: bool) -> WindowFeatures:
    """Window 240 of a 4-h history at 1 Hz: the front ring (T1) dead throughout, its sleeve
    (T2) valid from 900 s on; the twin's history 4 s apart, with a gap (NaN) at the
    sleeve's first valid sample where `sim_gap`."""
    rng = np.random.default_rng(5)
    t = np.arange(0.0, 14400.5, 1.0)
    T = 30.0 + 8.0 * (1 - np.exp(-t / 3000.0))[:, None] + rng.normal(0, 0.05, (t.size, 5))
    T[:, 0] = np.nan
    T[t < 900.0, 1] = np.nan
    sim_t = np.arange(0.0, 14400.5, 4.0)
    sim = 30.0 + 7.5 * (1 - np.exp(-sim_t / 2800.0))[:, None] + np.array([3, 1, 2.5, 1, 0])
    if sim_gap:
        sim[225, 0] = np.nan  # 900 s
    nominal = BoundaryValues(1e6, 1e6, 1e-4, 1e-4)
    return WindowFeatures(240, 14400.0, 9000.0, 25.0, t, T, sim_t, sim, nominal, nominal,
                          previous_factors=(1.1, 1.0, 1.0, 1.0))


def _whole_stand_in(f: WindowFeatures) -> WindowFeatures:
    """The stand-in over the whole history, as until 2026-11-27."""
    measured = f.measured_C.copy()
    now = f.simulated_now()
    ring_rise = now[0] - f.ambient_C
    divisor = max(now[1] - f.ambient_C, 0.5 * ring_rise)
    twin_ring, twin_sleeve = (np.interp(f.measured_time_s, f.simulated_time_s,
                                        f.simulated_C[:, c]) for c in (0, 1))
    measured[:, 0] = twin_ring + ring_rise / divisor * (measured[:, 1] - twin_sleeve)
    return WindowFeatures(**{**f.__dict__, "measured_C": measured})


@pytest.mark.parametrize("sim_gap", [False, True])
def test_a_dead_ring_stand_in_reads_as_the_whole_columns(sim_gap: bool) -> None:
    """Written over the window just ended and at the sleeve's first valid sample only, the
    stand-in gives the ratio law (bpnn's anchor) every value the whole column gave: the
    initial value, the last one, the window's line; with a gap in the twin's history there,
    the whole column is written."""
    from twin.correction.methods import ANCHOR_LAW, ratio_anchor

    f = _dead_ring_features(sim_gap)
    assert f.dead_rings() == ("front",)
    read, whole = f.with_dead_rings_read_through_sleeves(), _whole_stand_in(f)
    assert np.isnan(read.measured_C[1000:13000, 0]).all() != sim_gap
    for name in ("measured_initial", "measured_now"):
        assert np.array_equal(getattr(read, name)(), getattr(whole, name)(), equal_nan=True)
    for a, b in zip(window_line_fit(read.measured_time_s, read.measured_C, 14400.0),
                    window_line_fit(whole.measured_time_s, whole.measured_C, 14400.0),
                    strict=True):
        assert np.array_equal(a, b, equal_nan=True)
    assert ANCHOR_LAW.correct(read).values == ANCHOR_LAW.correct(whole).values
    # the anchor itself moved the front heat: the stand-in was read, not held
    assert ratio_anchor(f, np.array([1.1, 1.0, 1.0, 1.0]))[0] != pytest.approx(1.1e6)
