"""The BP networks: closed-form checks, determinism by seed, the training result."""

import numpy as np
import pytest

from twin.correction.features import OUTPUTS
from twin.correction.network import (
    ANCHORED,
    DEFAULT,
    PAPER,
    r_squared,
    split_by_run,
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


def test_split_by_run_holds_out_whole_runs():
    runs = np.repeat([f"r{i}" for i in range(10)], 7)
    train, test = split_by_run(runs, seed=2)
    assert len(set(runs[test])) == 2 and len(set(runs[train])) == 8
    assert not set(runs[train]) & set(runs[test])
    assert len(train) + len(test) == len(runs)


def _linear_data(n=200):
    rng = np.random.default_rng(0)
    x = np.column_stack([rng.uniform(6000, 13000, n), rng.uniform(23, 27, n),
                         rng.uniform(25, 40, n), rng.uniform(25, 40, n),
                         rng.uniform(0, 1800, n), rng.uniform(1e6, 3e6, n)])
    # a correction factor linear in the inputs: representable exactly by both configs'
    # default (tanh nets approximate it closely)
    factor = 1 + 0.02 * (x[:, 2] - x[:, 3]) + 1e-5 * (x[:, 0] - 9000)
    return x, factor * x[:, 5]


def _train(x, y, train, test, config, **kw):
    anchor = x[:, 5] if config.anchored else None  # the last column stands in for the anchor
    return train_network(x, y, train, test, config=config, anchor=anchor, **kw)


def test_default_network_learns_a_known_function():
    assert DEFAULT is ANCHORED
    x, y = _linear_data()
    train, test = split_indices(len(y), seed=0)
    net, history = _train(x, y, train, test, DEFAULT, hidden=10, epochs=800, seed=0)
    assert r_squared(y[test] / x[test, 5], net.predict(x[test], x[test, 5]) / x[test, 5]) > 0.99
    assert history.train_mse[-1] < history.train_mse[0] / 100


def test_anchored_network_starts_at_its_anchor_and_is_not_capped_by_the_training_range():
    x, y = _linear_data()
    train, test = split_indices(len(y), seed=0)
    # zero-initialised output layer: before any epoch the network is the anchor itself;
    # early stopping keeps no weights that do worse than the anchor on the held-out rows
    # (targets that are noise only: whatever the network learns of them is overfitting)
    noise = x[:, 5] * np.exp(np.random.default_rng(5).normal(0, 0.05, len(y)))
    net, history = _train(x, noise, train, test, DEFAULT, hidden=10, epochs=200, seed=0)
    untrained, _ = _train(x, noise, train, test, DEFAULT, hidden=10, epochs=1, seed=0)
    held_out = np.log(noise[test] / x[test, 5])

    def mse(n):
        return np.mean((np.log(n.predict(x[test], x[test, 5]) / x[test, 5]) - held_out) ** 2)

    assert mse(net) <= np.mean(held_out**2) * (1 + 1e-12)
    assert mse(net) <= mse(untrained) * (1 + 1e-12)
    assert history.train_mse[-1] < history.train_mse[0]  # it did fit the training noise
    assert net.without_correction().predict(x, x[:, 5]) == pytest.approx(x[:, 5], rel=1e-15)
    # the output is a factor on the anchor: anchors 100× beyond anything trained on give
    # values 100× larger, not values squeezed into the training targets' range
    learned, _ = _train(x, y, train, test, DEFAULT, hidden=10, epochs=400, seed=0)
    far = learned.predict(x[:5], 100 * x[:5, 5])
    assert far == pytest.approx(100 * learned.predict(x[:5], x[:5, 5]), rel=1e-12)
    assert far.min() > 10 * y.max()
    with pytest.raises(ValueError, match="anchor"):
        learned.predict(x[:5])


def test_training_is_deterministic_by_seed():
    x, y = _linear_data(80)
    train, test = split_indices(len(y), seed=1)
    a, ha = _train(x, y, train, test, DEFAULT, hidden=10, epochs=100, seed=7)
    b, hb = _train(x, y, train, test, DEFAULT, hidden=10, epochs=100, seed=7)
    c, _ = _train(x, y, train, test, DEFAULT, hidden=10, epochs=100, seed=8)
    assert np.array_equal(a.hidden_weight, b.hidden_weight)
    assert np.array_equal(ha.train_mse, hb.train_mse)
    assert not np.array_equal(a.hidden_weight, c.hidden_weight)


def test_numpy_inference_matches_torch():
    import torch

    x, y = _linear_data(50)
    train, test = split_indices(len(y), seed=0)
    for config in (DEFAULT, PAPER):
        net, _ = _train(x, y, train, test, config, hidden=12, epochs=20, seed=0)
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
    result = train_model(samples, config=PAPER, epochs=300, seed=0)
    table = result.r2_table()
    assert set(table) == {"heat_front", "heat_rear", "resistance_front", "resistance_rear"}
    # held out is a whole run at one speed (the R² of a run never seen, not of its
    # neighbours in time); what the networks learn is checked on the anchored samples below
    assert all(np.isfinite(row["r2_value"]) for row in table.values())
    meta = result.model.metadata
    assert meta["training_runs"] == ["r10000", "r12000", "r6000", "r8000"]
    assert meta["samples"] == len(samples)
    assert len(meta["held_out_runs"]) == 1  # a whole run of the four
    with pytest.raises(ValueError, match="anchor"):
        train_model(samples, epochs=5)  # ratio-rule samples carry no anchor


def anchored_samples(n_runs=6, windows=40):
    """Synthetic anchored samples: the target is the anchor times a known smooth factor of
    two inputs (the level and rise errors), as the window fit would give it."""
    rng = np.random.default_rng(3)
    n = n_runs * windows
    rows = np.column_stack([rng.uniform(3000, 15000, n), rng.normal(0, 0.2, n),
                            rng.normal(0, 1.0, n), rng.normal(0, 0.3, n),
                            np.tile(60.0 * np.arange(windows), n_runs), rng.normal(0, 0.05, n)])
    anchor = rng.uniform(1e6, 3e6, n)
    target = anchor * np.exp(0.1 * rows[:, 2] + 0.3 * rows[:, 3])
    return SampleSet(
        inputs={o: rows for o in OUTPUTS}, targets={o: target for o in OUTPUTS},
        time_s=rows[:, 4], run=np.repeat([f"r{i}" for i in range(n_runs)], windows).astype(object),
        anchored_inputs={o: rows for o in OUTPUTS}, anchors={o: anchor for o in OUTPUTS})


def test_train_model_anchored_learns_the_log_correction_on_held_out_runs():
    result = train_model(anchored_samples(), epochs=400, seed=0)
    assert result.model.anchored and result.model.config_name == "anchored"
    for output, r in result.outputs.items():
        assert r.r2_factor > 0.9, output  # value / anchor on runs never trained on
    meta = result.model.metadata
    assert meta["weight_decay"] > 0 and meta["early_stopping"] is True
    assert len(meta["held_out_runs"]) == 1


def test_windows_without_a_sensor_are_left_out_of_training():
    # a stuck or dropped-out sensor gives NaN inputs for its windows (suite runs with a
    # stuck T2): they must not reach Rprop, whose weights would all turn NaN
    samples = small_samples()
    for output in ("heat_front", "resistance_front"):
        samples.inputs[output][:10, 3] = np.nan
    result = train_model(samples, config=PAPER, epochs=300, seed=0)
    table = result.r2_table()
    assert all(np.isfinite(row["r2_value"]) for row in table.values())
    assert all(np.isfinite(net.hidden_weight).all() for net in result.model.nets.values())
    anchored = anchored_samples()
    anchored.anchored_inputs["heat_front"][:15, 2] = np.nan
    result = train_model(anchored, epochs=200, seed=0)
    assert result.outputs["heat_front"].r2_factor > 0.9
