"""The 90 % band: calibrated across left-out blocks, widened beyond the training range."""

from __future__ import annotations

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from tests.drift_synthetic import synthetic_columns, write_csv
from twin.drift.data import read_drift_data
from twin.drift.extrapolation import OperatingRange, range_excess
from twin.drift.features import FeatureSpec
from twin.drift.intervals import GAIN, apply_interval, conformal_half_width, interval_rule
from twin.drift.model import fit_drift_model
from twin.drift.modelfile import load_drift_model, save_drift_model
from twin.lag import first_order_lag


def test_the_band_is_as_wide_as_the_worst_left_out_block_needs():
    """Rows of a block are autocorrelated: pooled, two well-predicted blocks outvoted a
    third whose band then missed most of it."""
    rng = np.random.default_rng(0)
    blocks = np.repeat([0, 1, 2], 400)
    residual = rng.normal(0.0, np.where(blocks == 2, 5.0, 1.0))[:, None]
    rule = interval_rule(residual, None, np.zeros_like(residual), blocks)
    worst = conformal_half_width(residual[blocks == 2])
    np.testing.assert_array_equal(rule["half_width_um"], worst)
    assert worst[0] > 1.2 * conformal_half_width(residual)[0]     # what pooling gave
    lo, hi = apply_interval(rule, np.zeros((3, 1)), None, np.array([0.0, 0.5, 2.0]))
    np.testing.assert_allclose(hi[:, 0], worst[0] * (1.0 + GAIN * np.array([0.0, 0.5, 2.0])))
    np.testing.assert_allclose(lo, -hi)


def test_the_bayesian_band_keeps_its_floor_and_widens_the_same_way():
    blocks = np.repeat([0, 1], 50)
    std = np.full((100, 1), 2.0)
    rule = interval_rule(np.full((100, 1), 0.1), std, np.zeros((100, 1)), blocks)
    assert rule["kind"] == "scaled_posterior" and rule["factor"] == [1.0]
    lo, hi = apply_interval(rule, np.zeros((2, 1)), std[:2], np.array([0.0, 1.0]))
    np.testing.assert_allclose(hi[:, 0], 1.6448536269514722 * 2.0 * np.array([1.0, 1 + GAIN]))


def test_range_excess_counts_spans_beyond_the_range():
    lo, hi = np.array([0.0, 10.0]), np.array([2.0, 10.0])
    x = np.array([[1.0, 10.0], [3.0, 10.0], [-1.0, 10.0], [1.0, 10.5], [2.5, 12.0]])
    excess, worst = range_excess(x, lo, hi)
    # a column that held one value counts in its own units
    np.testing.assert_allclose(excess, [0.0, 0.5, 0.5, 0.5, 2.0])
    assert worst.tolist()[1:] == [0, 0, 1, 1]


def test_a_speed_between_a_stop_and_the_slowest_run_is_outside_the_range():
    """Fitted on stops and 2500–5000 rpm, 1250 rpm lies inside [0, 5000] but no running
    row of the training was that slow; a stopped row is held against the stopped ones."""
    spec = FeatureSpec(("A_C",), (20.0,), taus_min=(10.0,), groups=("rise", "speed"))
    assert spec.names == ["A_C:rise", "speed_krpm", "speed_krpm2", "speed_krpm:lag10min",
                          "speed_krpm2:lag10min"]

    def row(rise: float, krpm: float, lag: float) -> list[float]:
        return [rise, krpm, krpm**2, lag, lag**2]

    train = np.array([row(0, 0, 0), row(5, 2.5, 0), row(8, 2.5, 2.5), row(9, 0, 2.5),
                      row(4, 0, 0.5), row(9, 5.0, 0), row(20, 5, 5), row(18, 0, 5)])
    rng = OperatingRange.of(spec, train)
    assert rng.features == ("speed_krpm", "speed_krpm2", "speed_krpm:lag10min",
                            "speed_krpm2:lag10min")          # the temperatures are not
    query = np.array([row(50, 2.5, 1.0), row(3, 1.25, 1.25), row(3, 0, 1.25), row(3, 6, 5.0)])
    excess, worst = rng.excess(spec, query)
    # 1250 rpm: (2.5 − 1.25)/2.5 of n; 6000 rpm: (36 − 25)/18.75 of n², more than n's 0.4
    np.testing.assert_allclose(excess, [0.0, 0.5, 0.0, 11.0 / 18.75])
    assert [rng.features[k] for k in worst[[1, 3]]] == ["speed_krpm", "speed_krpm2"]
    doc = json.loads(json.dumps(rng.to_json()))
    assert OperatingRange.from_json(doc) == rng


def test_a_stop_hotter_than_every_fitted_stop_is_outside_the_range():
    """A stop holds no input but its heat, and the speed lags fall back inside their range
    long before it is gone: a stopped row hotter than every stopped training row counts,
    in spans of the feature's range over every training row; a colder one does not (the
    room was colder), nor a running row's temperatures (the speed's answer, held against
    the speed)."""
    spec = FeatureSpec(("A_C",), (20.0,), taus_min=(10.0,), groups=("rise", "speed"))

    def row(rise: float, krpm: float, lag: float) -> list[float]:
        return [rise, krpm, krpm**2, lag, lag**2]

    train = np.array([row(0, 0, 0), row(5, 2.5, 0), row(9, 0, 2.5), row(20, 5, 5),
                      row(18, 0, 5)])
    rng = OperatingRange.of(spec, train)
    assert rng.state_features == ("A_C:rise",)
    assert (rng.stopped_state_lo, rng.stopped_state_hi) == ((0.0,), (18.0,))
    assert rng.state_span == (20.0,)
    query = np.array([row(27, 0, 1.0), row(-9, 0, 1.0), row(40, 5, 5), row(27, 0, 6.0),
                      row(18, 0, 6.0)])
    excess, worst = rng.excess(spec, query)
    # 9 K above the hottest stop: 9/20 of the rise's span over every training row; 6 of a
    # lag in 0–5: n² (36 − 25)/25
    np.testing.assert_allclose(excess, [0.45, 0.0, 0.0, 0.45, 11.0 / 25.0])
    assert [rng.named[k] for k in worst[[0, 3, 4]]] == ["A_C:rise", "A_C:rise",
                                                        "speed_krpm2:lag10min"]
    doc = json.loads(json.dumps(rng.to_json()))
    assert OperatingRange.from_json(doc) == rng
    # a file written before the state was kept: its stops held against the speed alone
    older = OperatingRange.from_json({k: v for k, v in doc.items() if "state" not in k})
    np.testing.assert_allclose(older.excess(spec, query)[0], [0.0, 0.0, 0.0, 11.0 / 25.0,
                                                              11.0 / 25.0])
    # one written with the state but not the unit to count it in: the same
    unitless = OperatingRange.from_json({k: v for k, v in doc.items() if k != "state_span"})
    np.testing.assert_allclose(unitless.excess(spec, query)[0], older.excess(spec, query)[0])


def test_a_warm_stop_after_a_cold_rest_counts_in_the_fitted_range_not_the_rests_noise():
    """Stand data often stop only at their start, cold: the rest's temperatures span the
    sensors' noise (0.0002–0.03 K on the real step tests), and a warm stop later counted
    thousands of such spans (the real data's first 4.1 h and the stop after them: 8938,
    a band ×17878, 2.25 m wide).  Counted in the feature's span over every training row,
    the range the model was fitted over, it is a fraction of that (×4.5 there, where the
    speed lags alone widen the band ×4.1 as the spindle stops)."""
    spec = FeatureSpec(("A_C",), (20.0,), taus_min=(10.0,), groups=("rise", "speed"))

    def row(rise: float, krpm: float, lag: float) -> list[float]:
        return [rise, krpm, krpm**2, lag, lag**2]

    train = np.array([row(0.0, 0, 0), row(0.01, 0, 0), row(-0.005, 0, 0), row(3, 2.5, 1),
                      row(8, 2.5, 2.5), row(10, 2.5, 2.5)])
    rng = OperatingRange.of(spec, train)
    assert (rng.stopped_state_lo, rng.stopped_state_hi) == ((-0.005,), (0.01,))
    excess, worst = rng.excess(spec, np.array([row(9, 0, 0), row(12, 0, 0.5)]))
    # 8.99 and 11.99 K above the rest, in spans of 10.005 K (the lag's 0.5 krpm less)
    np.testing.assert_allclose(excess, [8.99 / 10.005, 11.99 / 10.005])
    assert [rng.named[k] for k in worst] == ["A_C:rise", "A_C:rise"]


@pytest.fixture(scope="module")
def fitted(tmp_path_factory):
    folder = tmp_path_factory.mktemp("drift_band")
    data = folder / "machine.csv"
    write_csv(data, synthetic_columns(hours=3.0))                  # 3000 and 6000 rpm
    model = fit_drift_model(read_drift_data([data], targets=["drift_um"]),
                            method="ridge_dynamic", sensors="all", seed=0)
    path = save_drift_model(model, folder / "model.safetensors")
    faster = synthetic_columns(hours=3.0)
    faster["speed_rpm"] = 1.5 * faster["speed_rpm"]                # 4500 and 9000 rpm
    write_csv(folder / "faster.csv", faster)
    return folder, data, path


def test_rows_beyond_the_fitted_speeds_get_a_wider_band_and_a_note(fitted):
    from twin.cli import app

    folder, data, path = fitted
    model = load_drift_model(path)
    w = model.interval["half_width_um"][0]
    same = read_drift_data([data], targets=["drift_um"])
    mean, lo, hi, excess, _ = model.predict_data(same)
    assert not excess.any() and model.outside_range(excess, _) is None
    np.testing.assert_allclose(hi - mean, w)                      # the fitted range: w
    faster = read_drift_data([folder / "faster.csv"], targets=["drift_um"])
    mean, lo, hi, excess, furthest = model.predict_data(faster)
    at_9000 = faster.speed_rpm == 9000
    # n² 81 beyond its running range 9–36 by 45/27 of the span (its lags later further)
    assert np.all(excess[at_9000] >= 45.0 / 27.0 - 1e-12)
    np.testing.assert_allclose((hi - mean)[:, 0], w * (1.0 + GAIN * excess))
    outside = model.outside_range(excess, furthest)
    assert outside["rows"] == int(np.sum(excess > 0)) >= int(at_9000.sum())
    assert outside["max_band_factor"] == pytest.approx(1.0 + GAIN * excess.max())
    result = CliRunner().invoke(app, ["drift", "predict", str(path), str(folder / "faster.csv"),
                                      "--out", str(folder / "pred.csv")])
    assert result.exit_code == 0, result.output
    assert (f"note: {outside['rows']} rows ({outside['rows_pct']:.1f} %) outside the operating "
            f"range the model was fitted on (furthest: {outside['max_excess_spans']:.2f} of its "
            f"span beyond, in {outside['feature']}): the model extrapolates there; the 90 % "
            f"interval is widened for it, up to ×{outside['max_band_factor']:.2f}"
            in result.output), result.output
    result = CliRunner().invoke(app, ["drift", "predict", str(path), str(data),
                                      "--out", str(folder / "same.csv")])
    assert result.exit_code == 0 and "outside the operating range" not in result.output
    result = CliRunner().invoke(app, ["drift", "report", str(path), str(folder / "faster.csv"),
                                      "--out", str(folder / "report")])
    assert result.exit_code == 0, result.output
    metrics = json.loads((folder / "report" / "metrics.json").read_text())
    assert metrics["outside_range"]["rows"] == outside["rows"]
    assert "Outside the fitted range:" in (folder / "report" / "report.html").read_text()


def test_a_model_file_without_the_range_keeps_its_band(fitted):
    """A file written before the band widened has no operating range: it loads, and its
    band is the width it was fitted with everywhere."""
    folder, _, path = fitted
    model = load_drift_model(path)
    older = type(model)(model.method, model.targets, model.spec, model.params,
                        {k: v for k, v in model.interval.items()
                         if k not in ("operating_range", "extrapolation_gain")},
                        model.metadata, model.validation)
    older_path = save_drift_model(older, folder / "older.safetensors")
    faster = read_drift_data([folder / "faster.csv"], targets=["drift_um"])
    mean, lo, hi, excess, furthest = load_drift_model(older_path).predict_data(faster)
    assert not excess.any()
    np.testing.assert_allclose(hi - mean, model.interval["half_width_um"][0])


def test_a_model_file_without_the_stopped_state_keeps_its_band(fitted):
    """A spindle heating half as much again at the same speeds: its stops are hotter than
    every fitted stop, and a model holds them outside its range, with a wider band (its
    running rows, at speeds it was fitted on, keep theirs).  A file written before stopped
    rows were held against their thermal state loads, and holds them inside, as it did."""
    folder, data, path = fitted
    model = load_drift_model(path)
    assert set(model.operating_range.state_features) == {
        f"{s}:{kind}" for s in ("A_C", "B_C", "C_C")
        for kind in ["rise"] + [f"lag{tau:g}min" for tau in model.spec.taus_min]}
    columns = synthetic_columns(hours=3.0)
    for sensor in ("A_C", "B_C"):
        columns[sensor] = 20.0 + 1.5 * (columns[sensor] - 20.0)
    write_csv(folder / "hotter.csv", columns)
    hotter = read_drift_data([folder / "hotter.csv"], targets=["drift_um"])
    mean, lo, hi, excess, furthest = model.predict_data(hotter)
    stopped = hotter.speed_rpm == 0
    assert not excess[~stopped].any()
    assert np.mean(excess[stopped] > 0) > 0.5
    named = model.operating_range.named
    assert {named[k] for k in furthest[excess > 0]} <= set(model.operating_range.state_features)
    w = model.interval["half_width_um"][0]
    np.testing.assert_allclose((hi - mean)[:, 0], w * (1.0 + GAIN * excess))
    # written before the state was kept, or with the state but not the span it is counted
    # in (between the two changes): the stops held against the speed alone
    for name, dropped in (("older_state", lambda k: "state" in k),
                          ("unitless_state", lambda k: k == "state_span")):
        doc = {k: v for k, v in model.interval["operating_range"].items() if not dropped(k)}
        older = type(model)(model.method, model.targets, model.spec, model.params,
                            {**model.interval, "operating_range": doc},
                            model.metadata, model.validation)
        older_path = save_drift_model(older, folder / f"{name}.safetensors")
        mean, lo, hi, excess, _ = load_drift_model(older_path).predict_data(hotter)
        assert not excess.any(), name
        np.testing.assert_allclose(hi - mean, w)


def test_a_stop_after_a_run_that_only_rested_cold_keeps_a_band_like_the_speeds(tmp_path):
    """Fitted on 2 min of cold rest and 2 h at 3000 rpm, a model asked about the 2-h stop
    after them: the stop lies outside throughout (the heat stays), and the band is never
    wider than the speed lags make it where the spindle stops (held against the rest's
    noise, the stop counted 58453 spans of the 90-min lag, a band ×116907)."""
    t = np.arange(0.0, 120.0 + 4 * 3600.0, 15.0)
    speed = np.where((t >= 120.0) & (t < 120.0 + 2 * 3600.0), 3000.0, 0.0)
    heat = (speed / 1000.0) ** 1.5
    noise = np.random.default_rng(0).normal(0.0, 0.01, (2, t.size))
    a = 20.0 + first_order_lag(heat, t, 900.0, between="held")
    b = 20.0 + 0.5 * first_order_lag(heat, t, 2400.0, between="held")
    columns = {"time_s": t, "speed_rpm": speed, "A_C": a + noise[0], "B_C": b + noise[1],
               "drift_um": 3.0 * (a - 20.0) + 1.5 * (b - 20.0)}
    fitted_rows = t < 120.0 + 2 * 3600.0
    write_csv(tmp_path / "fit.csv", {k: v[fitted_rows] for k, v in columns.items()})
    write_csv(tmp_path / "all.csv", columns)
    model = fit_drift_model(read_drift_data([tmp_path / "fit.csv"], targets=["drift_um"]),
                            method="ridge_dynamic", sensors="all", seed=0)
    rng = model.operating_range
    assert sum(speed[fitted_rows] == 0) == 8 and max(np.ptp([rng.stopped_state_lo,
                                                             rng.stopped_state_hi], 0)) < 0.1
    data = read_drift_data([tmp_path / "all.csv"], targets=["drift_um"])
    mean, lo, hi, excess, furthest = model.predict_data(data)
    stop = ~fitted_rows
    assert np.all(excess[stop] > 0)
    at_stop = excess[np.argmax(stop)]                 # the speed lags: 3000 rpm, n² 9 krpm²
    assert at_stop == pytest.approx(9.0, rel=0.05) and excess.max() <= at_stop
    assert model.outside_range(excess, furthest)["max_band_factor"] < 20.0

