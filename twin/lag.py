"""The first-order lag τ·y' + y = x, sampled: the one implementation in the twin.

Three parts of the twin lag a signal this way, and all call `first_order_lag`:
  - a thermocouple in a bore follows its metal with a time constant of a few to tens of
    seconds (its mass and the contact conductance): the emulator's recorded T1..T5
    (`twin.plant.emulator`) and the estimator's readings (`twin.estimation.method`,
    `twin.loop.replay`); the emulated X/Y tilt follows the housing (`twin.plant.truth`).
    The input is linear between rows (the field between time steps);
  - the drift models' lagged features (`twin.drift.features`): a causal filter of logged
    samples, each held over the step that ends at it, restarted at every file's start.

The module sits at the top of the package and imports numpy and scipy only, so the
plant, the estimator and the drift models share it without depending on each other
(`twin.drift` must not import `twin.plant`).

Over a step h = t₁ − t₀, with w = 1 − exp(−h/τ) the weight of the new sample,
    y₁ = y₀ + w·(x₁ − y₀) − c·(x₁ − x₀)
exactly: c = 0 for x held at x₁ over the step, c = τ·w/h − (1 − w) for x linear over it
(a rising ramp stays below its end value x₁ within the step, so y rises by less; c → 0
as h → 0, so a jump of x in no time does not move y).  One recursion, two ways to run it:
  - constant steps of the linear form over at least `FILTER_MIN_ROWS` rows as a linear
    filter (scipy.signal.lfilter: the emulator's truth over long runs, many columns);
  - otherwise row by row: an estimator window's 16 rows cost less so than the filter's
    set-up, and `twin replay` does not import scipy.signal (0.5 s of start-up) for them.
    The held form always runs so: the drift models were fitted on its exact rounding, and
    their network fits are chaotic in it (run as a filter, the features of examples/real
    moved by 1e-13 and a refit's validation RMSE by up to 0.4 µm on a probe), so the
    drift features stay bit for bit what they were.
"""

from __future__ import annotations

from typing import Literal

import numpy as np

CONSTANT_STEP_RTOL = 1e-9
"""Steps equal to this relative tolerance count as constant (the filter then uses their
mean: a change of exp(−h/τ) far below the rounding of any logged value)."""

FILTER_MIN_ROWS = 200
"""Records of constant steps at least this long run as a linear filter (shorter: row by row)."""


def first_order_lag(x: np.ndarray, time_s: np.ndarray, tau_s: float | np.ndarray,
                    start: np.ndarray | float | None = None, *,
                    between: Literal["linear", "held"] = "linear",
                    segment_starts: np.ndarray | None = None) -> np.ndarray:
    """The response y of τ·y' + y = x to samples x at times `time_s` (s), τ = `tau_s` (s).

    x: (n, ...) along axis 0, any unit; y has its unit and shape, or (n, k, ...) for k
    time constants at once (`tau_s` of shape (k,)).  `between`: "linear" (exact for x
    linear between rows) or "held" (exact for x held at each row's value over the step
    that ends at it: y[i] = y[i−1] + (1 − exp(−Δt/τ))·(x[i] − y[i−1])).  y starts at
    `start` (None: settled, y = x at the first row).  `segment_starts`: rows where the
    signal starts anew (separate records): y = x there.  τ ≤ 0: y = x.
    """
    x = np.asarray(x, dtype=float)
    time_s = np.asarray(time_s, dtype=float)
    taus = np.asarray(tau_s, dtype=float)
    if time_s.shape != x.shape[:1]:
        raise ValueError(f"time_s has {time_s.shape} rows, x {x.shape[:1]}")
    if between not in ("linear", "held"):
        raise ValueError(f"between must be 'linear' or 'held', not {between!r}")
    if taus.ndim > 1:
        raise ValueError(f"tau_s must be a number or a 1-d array, not of shape {taus.shape}")
    lagging = taus > 0.0
    if taus.ndim == 0 and not lagging:
        return x.copy()
    # x with an axis per time constant after the rows: y[i] has the shape of x_k[i]
    x_k = x.reshape(x.shape[:1] + (1,) * taus.ndim + x.shape[1:])
    y = np.empty(x.shape[:1] + taus.shape + x.shape[1:])
    if x.shape[0] and np.any(lagging):
        bounds = {0, x.shape[0]}
        if segment_starts is not None:
            bounds |= {int(i) for i in np.asarray(segment_starts, dtype=np.int64)}
        bounds_sorted = sorted(bounds)
        for k, (lo, hi) in enumerate(zip(bounds_sorted[:-1], bounds_sorted[1:], strict=True)):
            y[lo] = x_k[lo] if start is None or k > 0 else start
            _record(x_k[lo:hi], time_s[lo:hi], np.where(lagging, taus, 1.0), between,
                    y[lo:hi])
    if taus.ndim:
        y[:, ~lagging] = x_k  # τ ≤ 0: the input itself, exactly
    return y


def _record(x_k: np.ndarray, time_s: np.ndarray, taus: np.ndarray, between: str,
            y: np.ndarray) -> None:
    """Fill y[1:] of one record from y[0]: x_k (rows, 1 per τ…, columns…), taus () or (k,)."""
    if x_k.shape[0] < 2:
        return
    h = np.diff(time_s)
    constant = (between == "linear" and x_k.shape[0] >= FILTER_MIN_ROWS
                and np.ptp(h) <= CONSTANT_STEP_RTOL * abs(h[0]))
    if constant:
        h = np.full(1, h.mean())
    # per step and τ, broadcast over the columns
    trailing = (1,) * (x_k.ndim - 1 - taus.ndim)
    h = h.reshape(h.shape + (1,) * taus.ndim)
    w = -np.expm1(-h / taus)
    if between == "held":
        _rows(y, w.reshape(w.shape + trailing), x_k)
        return
    ramp = np.divide(taus * w, h, out=np.ones_like(w), where=h != 0) - (1.0 - w)
    w, ramp = w.reshape(w.shape + trailing), ramp.reshape(ramp.shape + trailing)
    drive = np.diff(x_k, axis=0) * ramp
    if constant:
        from scipy.signal import lfilter  # only for long records: kept off replay's start-up

        # y₁ = (1 − w)·y₀ + (w·x₁ − c·Δx), one τ at a time (lfilter takes one set of
        # coefficients)
        x_full, drive = np.broadcast_to(x_k, y.shape), np.broadcast_to(drive, y[1:].shape)
        for j in np.ndindex(taus.shape):
            rows, wj = (slice(None), *j), w[(0, *j)].item()
            y[1:][rows], _ = lfilter([1.0], [1.0, wj - 1.0], wj * x_full[1:][rows] - drive[rows],
                                     axis=0, zi=(1.0 - wj) * y[:1][rows])
        return
    _rows(y, w, x_k, drive)


def _rows(y: np.ndarray, w: np.ndarray, x_k: np.ndarray, drive: np.ndarray | None = None
          ) -> None:
    """y[i] = y[i−1] + w[i−1]·(x[i] − y[i−1]) (− drive[i−1]) row by row, on flat rows
    (broadcast once: a Python loop pays per numpy call, not per element)."""
    n = y.shape[0]
    flat = np.empty((n, y[0].size))
    x_flat = np.broadcast_to(x_k, y.shape).reshape(n, -1)
    w_flat = np.broadcast_to(w, y[1:].shape).reshape(n - 1, -1)
    prev = flat[0] = y[0].reshape(-1)
    if drive is None:
        for i in range(1, n):
            prev = flat[i] = prev + w_flat[i - 1] * (x_flat[i] - prev)
    else:
        d_flat = np.broadcast_to(drive, y[1:].shape).reshape(n - 1, -1)
        for i in range(1, n):
            prev = flat[i] = prev + w_flat[i - 1] * (x_flat[i] - prev) - d_flat[i - 1]
    y[1:] = flat[1:].reshape(y[1:].shape)
