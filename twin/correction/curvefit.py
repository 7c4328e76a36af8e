"""Smooth key-point temperature curves: a sum of two exponential rises per constant-speed span.

The paper fits measured and simulated key-point curves as functions of time before taking
the instantaneous rise ratios (REFERENCE.md §1, samples).  A thermal network warmed by
constant heat rises as a sum of exponentials; two terms (a fast local one, the bearing
ring, and a slow one, the housing) describe a 30 min run well.  After a speed change the
spindle starts a new rise from its current state, so each constant-speed span gets its own
fit.  Where a fit does not converge a smoothing spline (scipy) stands in.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike
from scipy.interpolate import make_smoothing_spline
from scipy.optimize import curve_fit

SPEED_CHANGE_RPM = 1.0
"""A speed differing from the previous sample by more than this starts a new span."""


def two_exponential_rise(
    t_s: ArrayLike, T0_C: float, a1_K: float, tau1_s: float, a2_K: float, tau2_s: float
) -> np.ndarray:
    """T0 + a1 (1 − e^(−t/τ1)) + a2 (1 − e^(−t/τ2))  [°C]."""
    t = np.asarray(t_s, dtype=float)
    return T0_C + a1_K * -np.expm1(-t / tau1_s) + a2_K * -np.expm1(-t / tau2_s)


@dataclass(frozen=True)
class SmoothCurve:
    """A fitted curve, piecewise over constant-speed spans; call it with times in s."""

    span_starts_s: np.ndarray
    pieces: tuple[Callable[[np.ndarray], np.ndarray], ...]
    rms_residual_C: float

    def __call__(self, t_s: ArrayLike) -> np.ndarray:
        t = np.atleast_1d(np.asarray(t_s, dtype=float))
        which = np.clip(np.searchsorted(self.span_starts_s, t, side="right") - 1, 0, None)
        out = np.empty_like(t)
        for k, piece in enumerate(self.pieces):
            sel = which == k
            if sel.any():
                out[sel] = piece(t[sel] - self.span_starts_s[k])
        return out


def _fit_span(t: np.ndarray, T: np.ndarray) -> Callable[[np.ndarray], np.ndarray]:
    """Fit one span (t from 0); falls back to a smoothing spline, a constant, or NaN."""
    if t.size == 0:
        return lambda x: np.full_like(np.asarray(x, dtype=float), np.nan)
    if t.size < 6 or np.ptp(T) == 0:
        level = float(np.mean(T))
        return lambda x: np.full_like(np.asarray(x, dtype=float), level)
    total = float(T[-1] - T[0])
    duration = max(float(t[-1]), 1.0)
    p0 = [float(T[0]), 0.5 * total, min(120.0, duration / 4), 0.5 * total, duration]
    span = float(np.ptp(T)) + 1.0
    lower = [float(T.min()) - span, -10 * span, 1.0, -10 * span, 1.0]
    upper = [float(T.max()) + span, 10 * span, 1e5, 10 * span, 1e6]
    try:
        params, _ = curve_fit(
            two_exponential_rise, t, T, p0=p0, bounds=(lower, upper), maxfev=4000
        )
        return lambda x, p=params: two_exponential_rise(x, *p)
    except (RuntimeError, ValueError):
        spline = make_smoothing_spline(t, T)
        return lambda x, s=spline: s(np.clip(x, t[0], t[-1]))


def fit_rise_curve(
    time_s: ArrayLike, temperature_C: ArrayLike, speed_rpm: ArrayLike | None = None
) -> SmoothCurve:
    """Fit a measured or simulated key-point curve; NaN samples are ignored."""
    time = np.asarray(time_s, dtype=float)
    temp = np.asarray(temperature_C, dtype=float)
    if speed_rpm is None:
        starts_idx = np.array([0])
    else:
        speed = np.asarray(speed_rpm, dtype=float)
        change = np.flatnonzero(np.abs(np.diff(speed)) > SPEED_CHANGE_RPM) + 1
        starts_idx = np.concatenate([[0], change])
    starts = time[starts_idx]
    ends = np.append(starts[1:], np.inf)
    pieces = []
    residuals = []
    for start, end in zip(starts, ends, strict=True):
        sel = (time >= start) & (time < end) & np.isfinite(temp)
        # the span's first sample is its starting state; include the sample at the
        # change so the new rise starts where the old one ended
        t = time[sel] - start
        piece = _fit_span(t, temp[sel])
        pieces.append(piece)
        if t.size:
            residuals.append(temp[sel] - piece(t))
    res = np.concatenate(residuals) if residuals else np.array([np.nan])
    return SmoothCurve(starts, tuple(pieces), float(np.sqrt(np.mean(res**2))))
