"""The BP networks: closed-form checks, determinism by seed, the training result."""

import numpy as np
import pytest

from twin.correction.network import (
    DEFAULT,
    PAPER,
    r_squared,
    split_indices,
    train_network,
)
from twin.correction.samples import SampleSet, build_samples, open_loop_curves
from twin.correction.toy_plant import ToyPlant
from twin.correction.training import train_model


def test_r_squared_hand_worked():
    # SS_tot = 2 (mean 2), SS_res = 0.25 + 0 + 0.25 → R² = 1 − 0.5/2 = 0.75
    assert r_squared([1, 2, 3], [1.5, 2, 2.5]) == pytest.approx(0.75)
    assert np.isnan(r_squared([1, 1], [1, 2]))


def test_split_is_80_20_and_seeded():
    train, test = split_indices(100, seed=3)
    assert len(test) == 20 and len(train) == 80
    assert not set(train) & set(test)
    assert np.array_equal(split_indices(100, seed=3)[1], test)
    assert not np.array_equal(split_indices(100, seed=4)[1], test)


def _linear_data(n=200):
    rng = np.random.default_rng(0)
    x = np.column_stack([rng.uniform(6000, 13000, n), rng.uniform(23, 27, n),
                         rng.uniform(25, 40, n), rng.uniform(25, 40, n),
                         rng.uniform(0, 1800, n), rng.uniform(1e6, 3e6, n)])
    # a correction factor linear in the inputs: representable exactly by both configs'
    # default (tanh nets approximate it closely)
    factor = 1 + 0.02 * (x[:, 2] - x[:, 3]) + 1e-5 * (x[:, 0] - 9000)
    return x, factor * x[:, 5]


def test_default_network_learns_a_known_function():
    x, y = _linear_data()
    train, test = split_indices(len(y), seed=0)
    net, history = train_network(x, y, train, test, config=DEFAULT, hidden=10, epochs=800,
                                 seed=0)
    assert r_squared(y[test] / x[test, 5], net.predict(x[test]) / x[test, 5]) > 0.99
    assert history.train_mse[-1] < history.train_mse[0] / 100


def test_training_is_deterministic_by_seed():
    x, y = _linear_data(80)
    train, test = split_indices(len(y), seed=1)
    a, ha = train_network(x, y, train, test, config=DEFAULT, hidden=10, epochs=100, seed=7)
    b, hb = train_network(x, y, train, test, config=DEFAULT, hidden=10, epochs=100, seed=7)
    c, _ = train_network(x, y, train, test, config=DEFAULT, hidden=10, epochs=100, seed=8)
    assert np.array_equal(a.hidden_weight, b.hidden_weight)
    assert np.array_equal(ha.train_mse, hb.train_mse)
    assert not np.array_equal(a.hidden_weight, c.hidden_weight)


def test_numpy_inference_matches_torch():
    import torch

    x, y = _linear_data(50)
    train, test = split_indices(len(y), seed=0)
    for config in (DEFAULT, PAPER):
        net, _ = train_network(x, y, train, test, config=config, hidden=12, epochs=20, seed=0)
        hidden = torch.nn.Linear(6, 12, dtype=torch.float64)
        out = torch.nn.Linear(12, 1, dtype=torch.float64)
        with torch.no_grad():
            hidden.weight[:] = torch.from_numpy(net.hidden_weight)
            hidden.bias[:] = torch.from_numpy(net.hidden_bias)
            out.weight[:] = torch.from_numpy(net.output_weight)
            out.bias[:] = torch.from_numpy(net.output_bias)
            h = hidden(torch.from_numpy(net.scale_inputs(x)))
            h = torch.tanh(h) if config.hidden_activation == "tanh" else h
            o = out(h)[:, 0]
            o = torch.sigmoid(o) if config.output_activation == "logistic" else o
        assert net.forward_scaled(net.scale_inputs(x)) == pytest.approx(o.numpy(), rel=1e-12)


def test_paper_scaling_is_the_logistic_of_x_over_1e6():
    x, y = _linear_data(20)
    net, _ = train_network(x, y, np.arange(16), np.arange(16, 20), config=PAPER, hidden=10,
                           epochs=2, seed=0)
    assert net.scale_inputs(x)[0, 5] == pytest.approx(1 / (1 + np.exp(-x[0, 5] / 1e6)))
    assert net.unscale_targets(net.scale_targets(y[:3])) == pytest.approx(y[:3], rel=1e-9)


def small_samples():
    plant = ToyPlant()
    sets = []
    for i, speed in enumerate((6000.0, 8000.0, 10000.0, 12000.0)):
        t = np.arange(0, 1201, 4.0)
        H, R = plant.nominal_heat_W_m3(speed), plant.nominal_resistance_m2K_W(speed)
        factor = 1 + 0.1 * (speed - 9000) / 3000
        T = plant.simulate(t, speed, 25.0 + i * 0.3, H * factor, R * [1.2, 0.9])
        T = T + np.random.default_rng(i).normal(0, 0.05, T.shape)
        Ts = plant.simulate(t, speed, 25.0 + i * 0.3, H, R)
        sets.append(build_samples(open_loop_curves(
            f"r{speed:.0f}", t, np.full(t.size, speed), np.full(t.size, 25.0 + i * 0.3), T,
            t, Ts, np.r_[H, R])))
    return SampleSet.concatenate(sets)


def test_train_model_reports_r2_and_metadata():
    samples = small_samples()
    result = train_model(samples, epochs=300, seed=0)
    table = result.r2_table()
    assert set(table) == {"heat_front", "heat_rear", "resistance_front", "resistance_rear"}
    assert table["heat_front"]["r2_value"] > 0.95
    meta = result.model.metadata
    assert meta["training_runs"] == ["r10000", "r12000", "r6000", "r8000"]
    assert meta["samples"] == len(samples)


def test_windows_without_a_sensor_are_left_out_of_training():
    # a stuck or dropped-out sensor gives NaN inputs for its windows (suite runs with a
    # stuck T2): they must not reach Rprop, whose weights would all turn NaN
    samples = small_samples()
    for output in ("heat_front", "resistance_front"):
        samples.inputs[output][:10, 3] = np.nan
    result = train_model(samples, epochs=300, seed=0)
    table = result.r2_table()
    assert all(np.isfinite(row["r2_value"]) for row in table.values())
    assert table["heat_front"]["r2_value"] > 0.95
