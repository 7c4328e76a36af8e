"""A stop (speed 0) is an ordinary part of a run (issue 12): the corrections give a stopped
bearing no heat and carry their factor through the stop; replay, quality and training
accept runs with stops."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest
from typer.testing import CliRunner

from twin.cli import app
from twin.correction import BoundaryValues, OpenLoop, RatioCorrection, WindowFeatures
from twin.correction.methods import BpnnCorrection
from twin.correction.network import ANCHORED, PAPER
from twin.correction.samples import RunCurves, fit_samples
from twin.correction.training import train_model

NOMINAL_RUNNING = BoundaryValues(2.0e6, 4.0e5, 2.0e-4, 3.0e-4)
NOMINAL_STOPPED = BoundaryValues(0.0, 0.0, 2.1e-4, 3.1e-4)


class _ConstantNet:
    """A stand-in model of the paper's kind: every network answers nominal × 1.2."""

    anchored = False

    def predict(self, output, x, anchor=None):  # noqa: ANN001, ANN201
        return np.asarray(x)[:, 5] * 1.2


class _ConstantCorrection:
    """A stand-in anchored model: every network answers anchor × 1.2."""

    anchored = True

    def predict(self, output, x, anchor=None):  # noqa: ANN001, ANN201
        return np.asarray(anchor) * 1.2


def _features(window, nominal, previous, previous_nominal=None, factors=None):  # noqa: ANN001, ANN202
    t = np.arange(0.0, 60.0 * window + 1e-9, 2.0)
    T = 25.0 + 0.01 * t[:, None] * np.array([1.0, 0.8, 1.2, 1.0, 0.3])
    return WindowFeatures(window, 60.0 * window, 0.0 if nominal[0] == 0 else 9000.0, 25.0,
                          t, T, t, T + 0.2, nominal, previous,
                          previous_nominal=previous_nominal, previous_factors=factors)


@pytest.mark.parametrize("method", [OpenLoop(), RatioCorrection(), BpnnCorrection(_ConstantNet()),
                                    BpnnCorrection(_ConstantCorrection())])
def test_a_stopped_bearing_gets_no_heat_and_nothing_divides_by_zero(method):
    previous = BoundaryValues(*(np.array(NOMINAL_RUNNING) * 1.1))
    with np.errstate(divide="raise", invalid="raise"):
        stopped = method.correct(_features(5, NOMINAL_STOPPED, previous, NOMINAL_RUNNING,
                                           factors=(1.1, 1.1, 1.1, 1.1)))
        assert stopped.H_front_W_m3 == 0.0 and stopped.H_rear_W_m3 == 0.0
        assert stopped.R_front_m2K_W > 0 and stopped.R_rear_m2K_W > 0
        assert np.all(np.isfinite(stopped.C_H + stopped.C_C))
        # the window after: still stopped, the previous heat is 0
        again = method.correct(_features(6, NOMINAL_STOPPED, stopped.values, NOMINAL_STOPPED,
                                         factors=(1.1, 1.1, 1.1, 1.1)))
        assert again.H_front_W_m3 == 0.0 and again.C_H == (1.0, 1.0)
        # restart: the factor from before the stop comes back (open loop: the nominal)
        restart = method.correct(_features(7, NOMINAL_RUNNING, again.values, NOMINAL_STOPPED,
                                           factors=(1.1, 1.1, 1.1, 1.1)))
        assert restart.H_front_W_m3 > 0 and np.all(np.isfinite(restart.C_H))


def test_ratio_resumes_the_factor_it_had_before_the_stop():
    # the twin matches the measurement: every ratio neutral, the factor carries over
    t = np.arange(0.0, 420.0 + 1e-9, 2.0)
    T = 25.0 + 0.01 * t[:, None] * np.array([1.0, 0.8, 1.2, 1.0, 0.3])
    f = WindowFeatures(7, 420.0, 9000.0, 25.0, t, T, t, T, NOMINAL_RUNNING,
                       BoundaryValues(0.0, 0.0, 2.2e-4, 3.3e-4), previous_nominal=NOMINAL_STOPPED,
                       previous_factors=(1.3, 0.8, 1.0, 1.0))
    c = RatioCorrection().correct(f)
    assert np.array(c.values[:2]) / np.array(NOMINAL_RUNNING[:2]) == pytest.approx([1.3, 0.8])


def test_features_reject_negative_heat_and_zero_resistance():
    with pytest.raises(ValueError, match="heats must be ≥ 0"):
        _features(2, BoundaryValues(-1.0, 0.0, 2e-4, 3e-4), NOMINAL_RUNNING)
    with pytest.raises(ValueError, match="resistances positive"):
        _features(2, BoundaryValues(1.0, 0.0, 0.0, 3e-4), NOMINAL_RUNNING)


def test_training_leaves_stopped_heat_samples_out():
    rng = np.random.default_rng(0)
    windows = 40
    stopped = (np.arange(windows) % 4) == 3
    nominal = np.tile(np.array(NOMINAL_RUNNING), (windows, 1))
    nominal[stopped, :2] = 0.0
    fitted = nominal * rng.uniform(0.9, 1.3, nominal.shape)
    t = np.arange(0.0, 60.0 * windows + 1e-9, 10.0)
    T = 25.0 + rng.normal(0.0, 0.1, (t.size, 5))
    anchors = nominal * rng.uniform(0.9, 1.3, nominal.shape)  # 0 at a stop, as nominal
    rows = rng.normal(size=(windows, 4, 6))
    curves = RunCurves("stops", t, np.where(stopped[np.minimum(t // 60, windows - 1)
                                                   .astype(int)], 0.0, 9000.0),
                       np.full(t.size, 25.0), T, t, T, nominal, nominal, fitted=fitted,
                       anchors=anchors, anchored_inputs=rows)
    samples = fit_samples(curves)
    assert np.all(samples.targets["heat_front"][stopped] == 0.0)
    for config in (ANCHORED, PAPER):
        with np.errstate(divide="raise", invalid="raise"):
            result = train_model(samples, config=config, epochs=5)
        for output in ("heat_front", "heat_rear"):
            assert np.all(result.outputs[output].test_nominal > 0)
        assert len(result.outputs["resistance_front"].test_nominal) > len(
            result.outputs["heat_front"].test_nominal)


def invoke(*args: str):  # noqa: ANN201
    return CliRunner().invoke(app, list(args), catch_exceptions=False)


@pytest.fixture(scope="module")
def stop_run(tmp_path_factory):
    d = tmp_path_factory.mktemp("stop")
    profile = d / "stop.profile.csv"
    profile.write_text("time_s,speed_rpm\n0,9000\n240,0\n420,12000\n")
    run = d / "stop.csv"
    result = invoke("synth", "--profile", str(profile), "--minutes", "9", "--ambient", "24",
                    "--seed", "3", "--rate", "0.5", "--out", str(run), "--quiet")
    assert result.exit_code == 0, result.output
    return run


def test_replay_and_quality_handle_a_stop(stop_run, tmp_path):
    out = tmp_path / "replay"
    result = invoke("replay", str(stop_run), "--out", str(out), "--methods",
                    "open_loop,ratio,bpnn", "--snapshots", "none", "--quiet")
    assert result.exit_code == 0, result.output
    run_dir = out / "stop"
    with open(run_dir / "corrections.csv", newline="") as fh:
        rows = list(csv.DictReader(r for r in fh if not r.startswith("#")))
    assert {r["method"] for r in rows} == {"open_loop", "ratio", "bpnn"}
    for r in rows:
        window = int(r["window"])
        stopped = 4 <= window < 7
        heats = float(r["H_front"]), float(r["H_rear"])
        assert (heats == (0.0, 0.0)) if stopped else min(heats) > 0, r
        assert float(r["R_front"]) > 0
    accuracy = json.loads((run_dir / "accuracy.json").read_text())
    for method in ("open_loop", "ratio", "bpnn"):
        m = accuracy["methods"][method]
        assert np.isfinite(m["temperature_accuracy_pct"]) and m["temperature_accuracy_pct"] > 90
    quality = json.loads((run_dir / "quality.json").read_text())
    assert not [f for f in quality.get("findings", []) if f.get("column") == "speed_rpm"]


@pytest.mark.slow
def test_training_on_a_run_with_a_stop(stop_run, tmp_path):
    out = tmp_path / "m.safetensors"
    # a second run of the same profile (one file twice, or a copy, is refused)
    again = tmp_path / "stop_again.csv"
    made = invoke("synth", "--profile", str(stop_run.with_name("stop.profile.csv")),
                  "--minutes", "9", "--ambient", "24", "--seed", "4", "--rate", "0.5",
                  "--out", str(again), "--quiet")
    assert made.exit_code == 0, made.output
    result = invoke("train", str(stop_run), str(again), "--out", str(out), "--epochs", "20",
                    "--quiet")
    assert result.exit_code == 0, result.output
    assert out.exists()
