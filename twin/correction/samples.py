"""Training samples for the networks, from arrays.

Two target rules (`RunCurves.fitted` decides, `samples_for` dispatches):

- "fit" (default, `fit_samples`): one sample per window; the inputs are what the network
  sees at the window start in the loop, the target the value the offline window fit
  (`twin.loop.windowfit`) found for that window.
- "ratio" (`build_samples`): the paper's five steps, below.

Per run: (1) the recorded speed, ambient and T1..T5; (2) the nominal heat (Eq. 1) and
resistance (Eq. 4) per window; (3) the same run simulated by the twin, with the values it
used per window; (4) measured and simulated key-point curves fitted as smooth functions of
time (`curvefit`); (5) targets H'' and R'' from the corrections (`formulas`) on the fitted
curves.

A sample at time t0 has the network inputs at t0 (causal: raw measured samples at or before
t0, the twin's temperature at t0) and as target the value that makes the simulation match
the measurement over the window [t0, t0 + 60 s) that the value will be used for: the
ratios are taken at the window end on the fitted curves (the fits may look ahead, they are
only used to build targets).  Samples lie every 60 s, and more densely early in the run
where the temperatures change fastest (the paper's weak spot near 200 s).

A stopped bearing (nominal heat 0) gets the heat target 0; `twin.correction.training`
leaves such samples out of its heat network (there is no heat to learn a factor for).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from twin.correction.curvefit import fit_rise_curve
from twin.correction.features import (
    BEARINGS,
    OUTPUTS,
    RING_SENSOR,
    SLEEVE_SENSOR,
    WINDOW_S,
    correction_factors,
    last_at_or_before,
    network_inputs,
    values_allowed,
)
from twin.correction.formulas import (
    ContactFit,
    RatioGuard,
    RatioGuards,
    contact_drop_ratio,
    contact_pressure_factor,
    limit_to_nominal,
    total_rise_ratio,
    window_rise_ratio,
)

TARGET_GAINS = (1.0, 0.0, 1.0)
"""Exponents on the Eq. 2, Eq. 3 and Eq. 6 factors for the targets.  C_H (Eq. 3) is left
out by default: for a simulation run with constant values, the total-rise ratio and the
window-rise ratio both estimate the same heat ratio, and their product counts it twice
(see `RatioCorrection`).  (1, 1, 1) is the paper's literal product."""


TARGET_GUARDS = RatioGuards(window=RatioGuard(0.1, (0.5, 2.0)), contact=RatioGuard(0.1, (0.5, 2.0)))
"""Targets come from smooth fitted curves of a whole run, not from one noisy window, so
the per-window limits of the online method are widened (the floors and the value band
stay)."""


@dataclass(frozen=True)
class RunCurves:
    """One run, recorded and simulated: the arrays the sample builder needs.

    time_s (n,), speed_rpm (n,), ambient_C (n,), measured_C (n, 5): the recording.
    sim_time_s (m,), simulated_C (m, 5): the twin's T1..T5 for the same run.
    nominal, used: (windows, 4) or (4,) in BoundaryValues order; `used` are the values the
    simulation ran with in each window (= nominal for an open-loop simulation).
    """

    name: str
    time_s: np.ndarray
    speed_rpm: np.ndarray
    ambient_C: np.ndarray
    measured_C: np.ndarray
    sim_time_s: np.ndarray
    simulated_C: np.ndarray
    nominal: np.ndarray
    used: np.ndarray
    window_s: float = WINDOW_S
    fitted: np.ndarray | None = None
    """(windows, 4): the window fit's values (the "fit" targets); None for the ratio rule."""
    anchors: np.ndarray | None = None
    """(windows, 4): the ratio-law value (the anchored networks' anchor) at each window."""
    anchored_inputs: np.ndarray | None = None
    """(windows, 4, 6): the anchored networks' input rows at each window start, in OUTPUTS
    order (`WindowFeatures.anchored_inputs`, recorded by the simulation that saw them)."""

    def __post_init__(self) -> None:
        n = len(self.time_s)
        for name in ("speed_rpm", "ambient_C"):
            if np.shape(getattr(self, name)) != (n,):
                raise ValueError(f"RunCurves.{name} must have shape ({n},)")
        if np.shape(self.measured_C) != (n, 5):
            raise ValueError(f"RunCurves.measured_C must have shape ({n}, 5)")
        if np.shape(self.simulated_C) != (len(self.sim_time_s), 5):
            raise ValueError(f"RunCurves.simulated_C must have shape ({len(self.sim_time_s)}, 5)")
        if n < 2 or np.any(np.diff(self.time_s) <= 0):
            raise ValueError("RunCurves.time_s must be increasing with at least two samples")
        for name in ("nominal", "used", "fitted"):
            if getattr(self, name) is None and name == "fitted":
                continue
            v = np.asarray(getattr(self, name), dtype=float)
            if v.shape[-1] != 4 or v.ndim > 2 or not values_allowed(v.reshape(-1, 4).T):
                raise ValueError(f"RunCurves.{name} must have shape (windows, 4) or (4,), "
                                 "heats ≥ 0 (0 at a stop) and resistances positive")

    def per_window(self, name: str, window: np.ndarray) -> np.ndarray:
        v = np.asarray(getattr(self, name), dtype=float)
        if v.ndim == 1:
            return np.broadcast_to(v, (len(window), 4))
        return v[np.clip(window, 0, len(v) - 1)]


@dataclass(frozen=True)
class SampleSet:
    """Samples of the four networks: inputs[output] (N, 6), targets[output] (N,)."""

    inputs: dict[str, np.ndarray]
    targets: dict[str, np.ndarray]
    time_s: np.ndarray
    run: np.ndarray
    fit_rms_C: dict[str, float] = field(default_factory=dict)
    anchored_inputs: dict[str, np.ndarray] | None = None
    """Input rows (N, 6) of the anchored networks per output (None: not recorded)."""
    anchors: dict[str, np.ndarray] | None = None
    """The ratio-law value (N,) each anchored network corrects, per output."""

    def __len__(self) -> int:
        return len(self.time_s)

    @staticmethod
    def concatenate(sets: list[SampleSet]) -> SampleSet:
        if not sets:
            raise ValueError("no samples to concatenate")
        anchored = all(s.anchors is not None for s in sets)
        return SampleSet(
            inputs={o: np.concatenate([s.inputs[o] for s in sets]) for o in OUTPUTS},
            targets={o: np.concatenate([s.targets[o] for s in sets]) for o in OUTPUTS},
            time_s=np.concatenate([s.time_s for s in sets]),
            run=np.concatenate([s.run for s in sets]),
            fit_rms_C={k: v for s in sets for k, v in s.fit_rms_C.items()},
            anchored_inputs=({o: np.concatenate([s.anchored_inputs[o] for s in sets])
                              for o in OUTPUTS} if anchored else None),
            anchors=({o: np.concatenate([s.anchors[o] for s in sets]) for o in OUTPUTS}
                     if anchored else None),
        )


def sample_times(
    duration_s: float,
    window_s: float = WINDOW_S,
    dense_until_s: float = 600.0,
    dense_step_s: float = 20.0,
) -> np.ndarray:
    """Window starts 0, 60, … (each followed by a full window) plus dense early times."""
    last_start = duration_s - window_s + 1e-9
    regular = np.arange(0.0, last_start, window_s)
    dense = np.arange(0.0, min(dense_until_s, last_start), dense_step_s) if dense_step_s > 0 else []
    return np.unique(np.concatenate([regular, dense]))


def _inputs_at(c: RunCurves, t0: np.ndarray, nominal: np.ndarray) -> dict[str, np.ndarray]:
    """Network inputs at times t0 (causal: raw samples at or before, the twin's state)."""
    return network_inputs(
        speed_rpm=[last_at_or_before(c.time_s, c.speed_rpm, t)[0] for t in t0],
        ambient_C=[last_at_or_before(c.time_s, c.ambient_C, t)[0] for t in t0],
        run_time_s=t0 - c.time_s[0],
        measured_C=np.array([last_at_or_before(c.time_s, c.measured_C, t) for t in t0]),
        simulated_C=np.array([last_at_or_before(c.sim_time_s, c.simulated_C, t) for t in t0]),
        nominal=nominal,
    )


def build_samples(
    curves: RunCurves,
    *,
    dense_until_s: float = 600.0,
    dense_step_s: float = 20.0,
    guards: RatioGuards = TARGET_GUARDS,
    gains: tuple[float, float, float] = TARGET_GAINS,
    fits: tuple[ContactFit, ContactFit] = (ContactFit(), ContactFit(fit_radius_m=0.0425)),
) -> SampleSet:
    """Network inputs and targets H'', R'' for one run (see the module docstring)."""
    c = curves
    W = c.window_s
    t0 = sample_times(float(c.time_s[-1] - c.time_s[0]), W, dense_until_s, dense_step_s)
    t0 = t0 + float(c.time_s[0])
    t_end = t0 + W
    window = np.floor((t0 - c.time_s[0]) / W + 1e-9).astype(int)
    nominal = c.per_window("nominal", window)
    used = c.per_window("used", window)

    inputs = _inputs_at(c, t0, nominal)

    sim_speed = np.interp(c.sim_time_s, c.time_s, c.speed_rpm)
    fit_rms = {}
    fitted_m, fitted_f = {}, {}
    for j in sorted(set(RING_SENSOR.values()) | set(SLEEVE_SENSOR.values())):
        fm = fit_rise_curve(c.time_s, c.measured_C[:, j], c.speed_rpm)
        ff = fit_rise_curve(c.sim_time_s, c.simulated_C[:, j], sim_speed)
        fitted_m[j], fitted_f[j] = fm, ff
        fit_rms[f"{c.name}:T{j + 1}:measured"] = fm.rms_residual_C
        fit_rms[f"{c.name}:T{j + 1}:simulated"] = ff.rms_residual_C

    a, b, g_c = gains
    start = float(c.time_s[0])
    targets = {}
    for k, bearing in enumerate(BEARINGS):
        ring, sleeve = RING_SENSOR[bearing], SLEEVE_SENSOR[bearing]
        m_ring, f_ring = fitted_m[ring], fitted_f[ring]
        m_sleeve, f_sleeve = fitted_m[sleeve], fitted_f[sleeve]
        ambient_end = np.interp(t_end, c.time_s, c.ambient_C)
        ratio_total = total_rise_ratio(m_ring(t_end), f_ring(t_end), ambient_end, guards)
        C_H = window_rise_ratio(
            m_ring(t_end) - m_ring(t0), f_ring(t_end) - f_ring(t0), guards
        )
        heat = used[:, k] * ratio_total**a * C_H**b
        targets[f"heat_{bearing}"] = limit_to_nominal(heat, nominal[:, k], guards)

        ring0, sleeve0 = m_ring(start), m_sleeve(start)
        fp_end = contact_pressure_factor(
            m_ring(t_end) - ring0, m_sleeve(t_end) - sleeve0, fits[k], guards
        )
        fp_start = contact_pressure_factor(
            m_ring(t0) - ring0, m_sleeve(t0) - sleeve0, fits[k], guards
        )
        C_C = contact_drop_ratio(
            m_ring(t_end) - m_sleeve(t_end), f_ring(t_end) - f_sleeve(t_end), guards
        )
        # the drop is heat flux × resistance: the part of the drop ratio that the heat
        # correction of the same window already explains is taken out
        heat_factor = correction_factors(targets[f"heat_{bearing}"], used[:, k])
        resistance = used[:, 2 + k] * fp_end / fp_start * (C_C / heat_factor) ** g_c
        targets[f"resistance_{bearing}"] = limit_to_nominal(
            resistance, nominal[:, 2 + k], guards
        )

    return SampleSet(
        inputs=inputs,
        targets={o: targets[o] for o in OUTPUTS},
        time_s=t0 - start,
        run=np.full(len(t0), c.name, dtype=object),
        fit_rms_C=fit_rms,
    )


def fit_samples(curves: RunCurves, guards: RatioGuards = TARGET_GUARDS) -> SampleSet:
    """One sample per window: the loop's network inputs at its start, the fitted value.

    A window in which a bearing's ring or sleeve sensor has no valid sample gets no target
    for that bearing (NaN): the fit had nothing to tell its heat from its resistance by, and
    wanders (the ×/÷ 4 bound of `twin.loop.windowfit` on a run with a dead T4)."""
    c = curves
    if c.fitted is None:
        raise ValueError(f"{c.name}: no window-fit values; simulate the run with the window fit")
    fitted = np.asarray(c.fitted, dtype=float)
    windows = np.arange(len(fitted))
    start = float(c.time_s[0])
    t0 = start + c.window_s * windows
    nominal = c.per_window("nominal", windows)
    inputs = _inputs_at(c, t0, nominal)
    targets = limit_to_nominal(fitted, nominal, guards)
    for k, bearing in enumerate(BEARINGS):
        seen = _seen_in_windows(c, t0, (RING_SENSOR[bearing], SLEEVE_SENSOR[bearing]))
        targets[~seen, k] = np.nan
        targets[~seen, 2 + k] = np.nan
    anchored_inputs = anchors = None
    if c.anchors is not None and c.anchored_inputs is not None:
        rows = np.asarray(c.anchored_inputs, dtype=float)
        anchored_inputs = {o: rows[:, i, :] for i, o in enumerate(OUTPUTS)}
        anchors = {o: np.asarray(c.anchors, dtype=float)[:, i] for i, o in enumerate(OUTPUTS)}
    return SampleSet(
        inputs=inputs,
        targets={o: targets[:, i] for i, o in enumerate(OUTPUTS)},
        time_s=t0 - start,
        run=np.full(len(t0), c.name, dtype=object),
        anchored_inputs=anchored_inputs,
        anchors=anchors,
    )


def _seen_in_windows(c: RunCurves, t0: np.ndarray, sensors: tuple[int, ...]) -> np.ndarray:
    """Per window starting at t0, True if every one of `sensors` has a finite measured
    sample in [t0, t0 + window)."""
    seen = np.ones(len(t0), dtype=bool)
    for i, start in enumerate(t0):
        inside = (c.time_s >= start) & (c.time_s < start + c.window_s)
        seen[i] = bool(np.all(np.isfinite(c.measured_C[inside][:, list(sensors)]).any(axis=0)))
    return seen


def samples_for(curves: RunCurves) -> SampleSet:
    """The samples of a run under its target rule: window fit if fitted, else the ratio law."""
    return build_samples(curves) if curves.fitted is None else fit_samples(curves)


def open_loop_curves(
    name: str,
    time_s: ArrayLike,
    speed_rpm: ArrayLike,
    ambient_C: ArrayLike,
    measured_C: ArrayLike,
    sim_time_s: ArrayLike,
    simulated_C: ArrayLike,
    nominal: ArrayLike,
) -> RunCurves:
    """RunCurves of a run simulated open loop (the simulation used the nominal values)."""
    nom = np.asarray(nominal, dtype=float)
    return RunCurves(
        name=name,
        time_s=np.asarray(time_s, dtype=float),
        speed_rpm=np.asarray(speed_rpm, dtype=float),
        ambient_C=np.asarray(ambient_C, dtype=float),
        measured_C=np.asarray(measured_C, dtype=float),
        sim_time_s=np.asarray(sim_time_s, dtype=float),
        simulated_C=np.asarray(simulated_C, dtype=float),
        nominal=nom,
        used=nom,
    )
