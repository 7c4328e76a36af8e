"""The BP networks: one hidden layer, trained with Rprop in torch, evaluated in numpy.

Two configurations (REFERENCE.md §1; issues 6 and 13):

- `PAPER`: the paper's choices — linear ("purelin") hidden layer, logistic ("logsig")
  output, every input and the target squashed by a logistic of X/10^6 (their Eq. 8), the
  target being the corrected value itself, on the paper's six inputs (INPUT_NAMES).  Its
  output is bounded by the range of its training targets.
- `ANCHORED` (the default): the network learns a *log-correction on the ratio-law value*
  (the anchor, `twin.correction.methods.ratio_anchor`): value = anchor · exp(output).  tanh
  hidden layer, inputs standardised (z-scores of the training samples), linear output; the
  target log(value/anchor) is only divided by its RMS (no offset), so an output of 0 is the
  ratio law exactly.  Nothing caps the value at the training range: the anchor moves with
  the measurement, the network only corrects it.  Its inputs (ANCHORED_INPUT_NAMES) carry
  what the ratio law does not use (rates, speed change).  A weight decay and early stopping
  on the held-out runs shrink it towards the ratio law where the data say nothing.

Both keep the paper's topology (6-10-1 heat, 6-12-1 resistance) and its training: full
batch, `torch.optim.Rprop` with learning rate 0.05, up to 5000 epochs, stop when the
training MSE (in scaled units) reaches 1e-6, float64 throughout (the logistic of X/10^6
leaves differences of 1e-9 and less between samples).  The anchored networks keep the
weights of the epoch with the lowest held-out MSE.  Deterministic for a seed:
torch.manual_seed, deterministic algorithms and one thread while training (restored
afterwards).
"""

from __future__ import annotations

import contextlib
import dataclasses
from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

LEARNING_RATE = 0.05
MAX_EPOCHS = 5000
GOAL_MSE = 1e-6
TEST_FRACTION = 0.2
PAPER_SCALE = 1e6
"""n = 6 of the paper's Eq. 8: inputs and targets enter as logistic(X / 10^6)."""


@dataclass(frozen=True)
class NetConfig:
    name: str
    hidden_activation: str  # "tanh" | "linear"
    output_activation: str  # "linear" | "logistic"
    scaling: str  # "standard" | "logistic"
    target: str  # "value" | "log_anchor"
    weight_decay: float = 0.0
    """L2 penalty on the weights (not the biases), added to the scaled MSE."""
    early_stopping: bool = False
    """Keep the weights of the epoch with the lowest held-out MSE."""

    @property
    def anchored(self) -> bool:
        """True if the network corrects an anchor value (needs it to predict)."""
        return self.target == "log_anchor"


PAPER = NetConfig("paper", "linear", "logistic", "logistic", "value")
ANCHORED_WEIGHT_DECAY = 1e-3
ANCHORED = NetConfig("anchored", "tanh", "linear", "standard", "log_anchor",
                     weight_decay=ANCHORED_WEIGHT_DECAY, early_stopping=True)
DEFAULT = ANCHORED
CONFIGS = {c.name: c for c in (PAPER, ANCHORED)}


def _sigmoid(x: np.ndarray) -> np.ndarray:
    return 0.5 * (1.0 + np.tanh(0.5 * x))


def _logit(y: np.ndarray) -> np.ndarray:
    y = np.clip(y, 1e-15, 1 - 1e-15)
    return np.log(y) - np.log1p(-y)


@dataclass(frozen=True)
class TrainedNet:
    """Weights and scaling of one network; `predict` maps physical inputs to the value.

    Scaling: x_s = s((x − x_offset)/x_scale), y_s = s((y − y_offset)/y_scale), with s the
    logistic for `scaling == "logistic"` and the identity otherwise.  For a "log_anchor"
    target, y is log(value / anchor).
    """

    config: NetConfig
    hidden_weight: np.ndarray  # (h, 6)
    hidden_bias: np.ndarray  # (h,)
    output_weight: np.ndarray  # (1, h)
    output_bias: np.ndarray  # (1,)
    x_offset: np.ndarray  # (6,)
    x_scale: np.ndarray  # (6,)
    y_offset: np.ndarray  # (1,)
    y_scale: np.ndarray  # (1,)

    @property
    def hidden_size(self) -> int:
        return int(self.hidden_weight.shape[0])

    def scale_inputs(self, x: ArrayLike) -> np.ndarray:
        z = (np.asarray(x, dtype=float) - self.x_offset) / self.x_scale
        return _sigmoid(z) if self.config.scaling == "logistic" else z

    def scale_targets(self, y: ArrayLike) -> np.ndarray:
        z = (np.asarray(y, dtype=float) - self.y_offset[0]) / self.y_scale[0]
        return _sigmoid(z) if self.config.scaling == "logistic" else z

    def unscale_targets(self, y_s: ArrayLike) -> np.ndarray:
        y = np.asarray(y_s, dtype=float)
        z = _logit(y) if self.config.scaling == "logistic" else y
        return self.y_offset[0] + self.y_scale[0] * z

    def forward_scaled(self, x_s: np.ndarray) -> np.ndarray:
        h = x_s @ self.hidden_weight.T + self.hidden_bias
        if self.config.hidden_activation == "tanh":
            h = np.tanh(h)
        out = (h @ self.output_weight.T + self.output_bias)[:, 0]
        return _sigmoid(out) if self.config.output_activation == "logistic" else out

    def without_correction(self) -> TrainedNet:
        """This network with its output layer zeroed: an anchored network that reproduces
        its anchor (see `twin.loop.training.gate_networks`)."""
        return dataclasses.replace(self, output_weight=np.zeros_like(self.output_weight),
                                   output_bias=np.zeros_like(self.output_bias))

    def predict(self, x: ArrayLike, anchor: ArrayLike | None = None) -> np.ndarray:
        """Corrected values (W/m³ or m²K/W) for input rows x (N, 6); an anchored network
        needs the anchor values (N,) it corrects."""
        x = np.atleast_2d(np.asarray(x, dtype=float))
        y = self.unscale_targets(self.forward_scaled(self.scale_inputs(x)))
        if not self.config.anchored:
            return y
        if anchor is None:
            raise ValueError("an anchored network needs the anchor values")
        return np.asarray(anchor, dtype=float) * np.exp(y)


@contextlib.contextmanager
def deterministic_torch(seed: int) -> Iterator[None]:
    """Seeded, deterministic, single-threaded torch; the previous settings come back after."""
    import torch

    threads = torch.get_num_threads()
    was_deterministic = torch.are_deterministic_algorithms_enabled()
    torch.manual_seed(seed)
    torch.set_num_threads(1)
    torch.use_deterministic_algorithms(True)
    try:
        yield
    finally:
        torch.use_deterministic_algorithms(was_deterministic)
        torch.set_num_threads(threads)


def split_indices(
    n: int, seed: int, test_fraction: float = TEST_FRACTION
) -> tuple[np.ndarray, np.ndarray]:
    """Random (train, test) index split with a fixed seed (the paper's 80/20)."""
    order = np.random.default_rng(seed).permutation(n)
    n_test = max(1, int(round(test_fraction * n))) if n > 1 else 0
    return np.sort(order[n_test:]), np.sort(order[:n_test])


def split_by_run(
    runs: ArrayLike, seed: int, test_fraction: float = TEST_FRACTION
) -> tuple[np.ndarray, np.ndarray]:
    """(train, test) sample indices with whole runs held out (a seeded `test_fraction` of
    the distinct runs, at least one when there are two or more).

    Samples of one run (its windows, its training passes) are strongly alike; a random
    sample split would put near-copies on both sides and make the held-out error, and the
    early stopping that reads it, flatter than on a run never seen.
    """
    names = np.asarray(runs).astype(str)
    distinct = np.unique(names)
    _, held = split_indices(len(distinct), seed, test_fraction)
    test = np.isin(names, distinct[held])
    return np.flatnonzero(~test), np.flatnonzero(test)


def r_squared(target: ArrayLike, predicted: ArrayLike) -> float:
    """Coefficient of determination 1 − SS_res/SS_tot (NaN if the target is constant)."""
    t = np.asarray(target, dtype=float)
    p = np.asarray(predicted, dtype=float)
    ss_tot = float(np.sum((t - t.mean()) ** 2))
    if ss_tot == 0:
        return float("nan")
    return 1.0 - float(np.sum((t - p) ** 2)) / ss_tot


@dataclass(frozen=True)
class TrainingHistory:
    train_mse: np.ndarray  # per epoch, scaled units
    test_mse: np.ndarray
    epochs: int
    stopped_at_goal: bool


def fit_scaling(
    config: NetConfig, x_train: np.ndarray, y_train: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(x_offset, x_scale, y_offset, y_scale) of a configuration from training data."""
    if config.scaling == "logistic":
        return (np.zeros(x_train.shape[1]), np.full(x_train.shape[1], PAPER_SCALE),
                np.zeros(1), np.full(1, PAPER_SCALE))
    x_std = x_train.std(axis=0)
    if config.anchored:  # no offset: an output of 0 is the anchor itself
        y_off, y_std = np.zeros(1), np.atleast_1d(np.sqrt(np.mean(y_train**2)))
    else:
        y_off, y_std = np.atleast_1d(y_train.mean()), np.atleast_1d(y_train.std())
    return (x_train.mean(axis=0), np.where(x_std > 0, x_std, 1.0),
            y_off, np.where(y_std > 0, y_std, 1.0))


def train_network(
    x: np.ndarray,
    value: np.ndarray,
    train: np.ndarray,
    test: np.ndarray,
    *,
    config: NetConfig,
    hidden: int,
    epochs: int = MAX_EPOCHS,
    seed: int = 0,
    learning_rate: float = LEARNING_RATE,
    goal_mse: float = GOAL_MSE,
    anchor: np.ndarray | None = None,
) -> tuple[TrainedNet, TrainingHistory]:
    """Train one network on rows `train` of (x (N, 6), value (N,)); `test` is held out.
    An anchored configuration learns log(value / anchor) (anchor (N,))."""
    import torch

    if epochs < 1:
        raise ValueError("epochs must be at least 1")
    x = np.asarray(x, dtype=float)
    value = np.asarray(value, dtype=float)
    if config.anchored:
        if anchor is None:
            raise ValueError("an anchored configuration needs the anchor values")
        # rows of a stopped bearing (anchor 0) carry no correction; the caller leaves them out
        with np.errstate(divide="ignore", invalid="ignore"):
            y = np.log(value / np.asarray(anchor, dtype=float))
    else:
        y = value
    x_off, x_sc, y_off, y_sc = fit_scaling(config, x[train], y[train])
    shell = TrainedNet(config, np.zeros((hidden, 6)), np.zeros(hidden), np.zeros((1, hidden)),
                       np.zeros(1), x_off, x_sc, y_off, y_sc)
    xs = torch.from_numpy(shell.scale_inputs(x))
    ys = torch.from_numpy(shell.scale_targets(y))

    with deterministic_torch(seed):
        hidden_layer = torch.nn.Linear(6, hidden, dtype=torch.float64)
        output_layer = torch.nn.Linear(hidden, 1, dtype=torch.float64)
        if config.anchored:
            # start from the anchor itself (output 0): early stopping then can only move
            # away from the ratio law as far as the held-out runs confirm
            torch.nn.init.zeros_(output_layer.weight)
            torch.nn.init.zeros_(output_layer.bias)
        params = [*hidden_layer.parameters(), *output_layer.parameters()]
        optimizer = torch.optim.Rprop(params, lr=learning_rate)
        train_idx = torch.from_numpy(np.asarray(train))
        test_idx = torch.from_numpy(np.asarray(test))

        def forward(rows: torch.Tensor) -> torch.Tensor:
            h = hidden_layer(rows)
            if config.hidden_activation == "tanh":
                h = torch.tanh(h)
            out = output_layer(h)[:, 0]
            return torch.sigmoid(out) if config.output_activation == "logistic" else out

        x_train, y_train = xs[train_idx], ys[train_idx]
        x_test, y_test = xs[test_idx], ys[test_idx]
        train_curve, test_curve = [], []
        stopped = False
        weights = (hidden_layer.weight, output_layer.weight)
        best_test, best_state = np.inf, None
        if config.early_stopping and len(test):
            with torch.no_grad():
                best_test = float(torch.mean((forward(x_test) - y_test) ** 2))
            best_state = [p.detach().clone() for p in params]
        for _ in range(epochs):
            optimizer.zero_grad()
            mse = torch.mean((forward(x_train) - y_train) ** 2)
            loss = mse + config.weight_decay * sum(torch.sum(w**2) for w in weights)
            loss.backward()
            optimizer.step()
            train_curve.append(float(mse.detach()))
            with torch.no_grad():
                test_curve.append(
                    float(torch.mean((forward(x_test) - y_test) ** 2)) if len(test) else np.nan
                )
            if config.early_stopping and test_curve[-1] < best_test:
                best_test = test_curve[-1]
                best_state = [p.detach().clone() for p in params]
            if train_curve[-1] <= goal_mse:
                stopped = True
                break
        if best_state is not None:
            with torch.no_grad():
                for p, best in zip(params, best_state, strict=True):
                    p.copy_(best)
        net = TrainedNet(
            config,
            hidden_layer.weight.detach().numpy().copy(),
            hidden_layer.bias.detach().numpy().copy(),
            output_layer.weight.detach().numpy().copy(),
            output_layer.bias.detach().numpy().copy(),
            x_off, x_sc, y_off, y_sc,
        )
    history = TrainingHistory(
        np.array(train_curve), np.array(test_curve), len(train_curve), stopped
    )
    return net, history
