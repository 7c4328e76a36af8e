"""The offline window fit: the boundary values that make the twin match a recorded window.

Training targets for the BP networks.  For window k the twin starts from its own state
(`WindowFeatures.twin_state`) and the fit chooses the four values (H_front, H_rear, R_front,
R_rear) that bring its T1..T4 over the coming 15 steps closest to the *measured* T1..T4 of
that window.  It looks ahead, so it is not a correction method: it runs only while training,
on recorded runs, where the future of every window is known.  The network then learns to
forecast, from data before the window, the value this fit finds.

Why not the ratio law (Eq. 2, 3, 6) for targets: the total-rise ratio mixes the heat error
of the whole history into one factor.  After a first window that overshoots (cold-oil
nominal heat, thermocouple lag), it halves the heat of the next window; on the emulated
runs it drove the contact resistance to 0.6× its true value, and networks trained on
those targets lost deformation accuracy against the open loop.  The fit reads the heat
error off the window itself.

The fit: parameters θ are log factors on the nominal values, p = p_nominal · e^θ, which
follow the twin's rings every solver step as in the loop (`Correction.loads_follow_rings`).
The window response is linear in the heat and mildly non-linear in the resistance, so two
Gauss–Newton steps converge, each with the residual of one window run as the loop runs it
and forward-difference sensitivities from five windows with the nominal values held at the
window start (one factorization each instead of fifteen; the ring's feedback on the heat
changes a sensitivity by a few per cent, which moves the steps, not where they end).  A
Gaussian prior θ ~ N(0, prior_spread²) against a residual noise of `noise_C` keeps an
unidentifiable value (a rear drop of a few tenths of a kelvin) near its nominal:

    minimise  Σ (T_twin(θ) − T_meas)² / noise_C²  +  Σ θ² / prior_spread²

What drives the twin from window to window (`drive`): the fit itself ("fit"), or the
ratio-law value the anchored networks correct ("anchor", `twin.correction.methods.
ratio_anchor`, chained on itself as in `BpnnCorrection`), so the networks see the states
the ratio law leads the twin into — the states they will correct in the loop.  Every
window also records the anchor and the anchored networks' input rows (`anchors`,
`anchored_inputs`), whatever the drive.
`drive_spread` > 0 advances the twin with the driving values scattered (seeded
log-normal, double spread on the resistances), while the target stays the fit from the
state reached.  The networks then see windows that start with the twin off the
measurement and learn how to pull it back, which an exact fit trajectory (twin always on
the measurement) never shows them.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from twin.contract import STEP_S, STEPS_PER_WINDOW
from twin.correction.features import OUTPUTS, WindowFeatures, correction_factors
from twin.correction.methods import ratio_anchor
from twin.correction.result import Correction
from twin.loop.replay import direct_window_solver, solve_following_rings
from twin.runs import RecordedRun
from twin.spindle.model import SpindleModel

FIT_SENSORS = (0, 1, 2, 3)
"""T1..T4: the rings and sleeves of both bearings (T5, the housing, hardly sees them)."""
DRIVE_SPREAD_WEIGHTS = np.array([1.0, 1.0, 2.0, 2.0])
"""Drive scatter per value (H_front, H_rear, R_front, R_rear) in units of `drive_spread`."""
LOG_FACTOR_LIMIT = float(np.log(4.0))
"""Bound of a fitted log factor: the fit keeps each value within ×/÷ 4 of nominal."""


@dataclass
class WindowFit:
    """Look-ahead least-squares fit of each window's values (see the module doc).

    Use it as the corrector of `replay_method` on a recorded run; `fitted` collects the
    fitted values per window (the targets), the replay's corrections the values driven.
    """

    run: RecordedRun
    model: SpindleModel
    noise_C: float = 0.05
    """Assumed residual noise of a thermocouple sample, K."""
    prior_spread: float = 0.25
    """Standard deviation of the log-factor prior (0.25: a factor within ≈ ×/÷ 1.3)."""
    iterations: int = 2
    step: float = 0.05
    """Forward-difference step on the log factor."""
    drive_spread: float = 0.0
    seed: int = 0
    drive: str = "fit"
    """"fit" or "anchor": the values the twin advances with (before the scatter)."""
    name: str = "fit"
    rerun_missed_speed: bool = False
    """True: the loop re-runs a window with a missed speed change, as for `BpnnCorrection`
    (`twin.loop.replay`), and the fit, the anchor and the networks' inputs start from the
    re-run.  Off for the bundled model: trained that way, the networks did worse on the
    held-out runs (mean temperature accuracy 98.91 against 98.94 %, bpnn re-running in
    both) and on suites 555 and 1; the windows it changes are a few per run, and the
    fit without it (the twin left off by the missed step) shows the networks how to pull
    a twin back, as the scattered passes do."""
    fitted: list[np.ndarray] = field(default_factory=list)
    anchors: list[np.ndarray] = field(default_factory=list)
    anchored_inputs: list[np.ndarray] = field(default_factory=list)
    """Per window (4, 6): the anchored networks' input rows, in OUTPUTS order."""

    def __post_init__(self) -> None:
        if self.drive not in ("fit", "anchor"):
            raise ValueError(f"WindowFit.drive must be 'fit' or 'anchor', not {self.drive!r}")
    _theta: np.ndarray = field(default_factory=lambda: np.zeros(4))
    _anchor_factors: np.ndarray = field(default_factory=lambda: np.ones(4))
    _rng: np.random.Generator | None = None

    def correct(self, features: WindowFeatures) -> Correction:
        f = features
        if f.twin_state is None:
            raise ValueError("the window fit needs the twin's state (run it through replay_method)")
        if f.window == 0:
            for records in (self.fitted, self.anchors, self.anchored_inputs):
                records.clear()
            self._theta = np.zeros(4)
            self._anchor_factors = np.ones(4)
            self._rng = np.random.default_rng(self.seed)
        nominal = np.asarray(f.nominal, dtype=float)
        theta = self._fit(f, nominal)
        self._theta = theta
        fitted = nominal * np.exp(theta)
        self.fitted.append(fitted)
        anchor = ratio_anchor(f, self._anchor_factors)
        self.anchors.append(anchor)
        rows = f.anchored_inputs(anchor)
        self.anchored_inputs.append(np.vstack([rows[o] for o in OUTPUTS]))
        self._anchor_factors = correction_factors(anchor, nominal, fallback=self._anchor_factors)
        driven = anchor if self.drive == "anchor" else fitted
        if self.drive_spread > 0:
            scatter = self._rng.normal(0.0, self.drive_spread, 4) * DRIVE_SPREAD_WEIGHTS
            driven = driven * np.exp(scatter)
        # the twin advances as every method's twin does: the values are factors on the
        # nominal values, which follow its rings every solver step
        return Correction.relative_to(driven, f.carried_previous(), loads_follow_rings=True)

    def _fit(self, f: WindowFeatures, nominal: np.ndarray) -> np.ndarray:
        times = f.start_s + STEP_S * np.arange(1, STEPS_PER_WINDOW + 1)
        measured = self.run.at(times)
        target = measured.T_valid_C[:, FIT_SENSORS]
        seen = np.isfinite(target)
        theta = self._theta.copy()  # warm start: the values change slowly window to window
        if not seen.any():
            return theta
        weight = (self.noise_C / self.prior_spread) ** 2
        for _ in range(self.iterations):
            # the residual from the window as the loop runs it (loads following the rings),
            # the sensitivities from windows with the loads held: a fifth of the cost, and
            # Gauss-Newton needs only their direction (the heat's feedback through the ring
            # changes them by a few per cent)
            residual = (self._window(f, nominal, theta, follow=True) - target)[seen]
            base = self._window(f, nominal, theta)
            jacobian = np.empty((residual.size, 4))
            for j in range(4):
                probe = theta.copy()
                probe[j] += self.step
                jacobian[:, j] = (self._window(f, nominal, probe) - base)[seen] / self.step
            normal = jacobian.T @ jacobian + weight * np.eye(4)
            step = np.linalg.solve(normal, -jacobian.T @ residual - weight * theta)
            # a window of few valid samples (dropouts, spikes) can throw Gauss-Newton far off:
            # keep the factors within ×/÷ 4 of nominal (LOG_FACTOR_LIMIT)
            theta = np.clip(theta + step, -LOG_FACTOR_LIMIT, LOG_FACTOR_LIMIT)
        return theta

    def _window(self, f: WindowFeatures, nominal: np.ndarray, theta: np.ndarray,
                follow: bool = False) -> np.ndarray:
        """T1..T4 of the twin over the window (15, 4) with the log factors `theta` on the
        nominal values: following the rings every step (`follow`) or held at `nominal`."""
        T, bc = f.twin_state
        solver = direct_window_solver(self.model)
        if follow:
            steps = solve_following_rings(self.model, solver, T, f.start_s, f.window, bc,
                                          np.exp(theta))
        else:
            steps, _ = solver(bc, Correction(*(nominal * np.exp(theta))), T, f.start_s,
                              f.window)
        return (self.model.sensor_matrix[list(FIT_SENSORS)] @ steps.T).T
