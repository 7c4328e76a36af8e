"""How far a row's operating point lies outside the rows a model was fitted on.

A drift model fitted on the 2500–5000 rpm step tests and asked about 1250 rpm (or fitted
up to 3750 and asked about 5000) extrapolates, and its error there is not that of the
blocks it was calibrated on: one band for every row covered 8 % of a probe's samples in
the 5000-rpm test while it covered every sample of the 2500-rpm one.

The operating point is what the user sets: the speed history (n, n² and their lags) for
a model that takes the speed; for one that does not, the temperature features, its only
inputs.  The temperatures are the machine's answer to it, and a left-out block's are
always a little outside the others' (a colder start, another ambient) without its error
growing.  A running spindle and a stopped one are two regimes (DESIGN: speed 0 is a stop,
no bearing or motor heat), so a running row is compared with the running training rows
and a stopped one (its lags still falling from the speed before) with the stopped ones:
1250 rpm lies between a stop and 2500 rpm, but no model fitted on stops and 2500–5000 rpm
has seen the spindle run that slowly.  The excess of a row is the largest, over those
features, of how far it lies beyond its regime's training range in units of that range's
span (0 inside): the band grows as a linear error would (see `twin.drift.intervals`).

A stopped row is also held against the *thermal state* the stopped training rows held:
its temperature features (rises and their lags, the model's other inputs), on the hot
side only.  A stop has no input but what the spindle still holds, and the speed lags fall
back inside their range within an hour or two while the heat stays: the stops after the
5000-rpm test cooled from hotter than any stop of the other three (the 90-min lag of one
sensor up to 0.63 spans above), unflagged, and a network's band covered 20 % of two
probes there (now 56–57 %; at two other network seeds 67–72 % → 100 %).  Hotter only, and
stopped rows only: the rises are against the file's first rows, so a left-out test's
temperatures lie a little outside the others' wherever the room was colder (and, running,
wherever the speed already says so).  Over six methods, three seeds and the four tests,
colder stops too widened the bands of the 2500 and 3750 rpm tests, whose speeds lie
inside, by 10 and 8 % on average, and running rows' temperatures too (either side) 1.2
and 1.5 times; hotter stops alone widen them by 0 and 0.4 %.  (The wider bands did cover
more of some worst blocks there: `bayes` and `stack` at 2500 rpm 52–56 → 78–84 % with
colder stops, `stack` at 3750 rpm 32–51 → 52–93 % with running rows too.)

How far above counts in spans of the feature's range over *every* training row, running
and stopped: the range the model was fitted over (as for a model without the speed,
whose operating features the temperatures are), where an error linear in the feature and
within ±w stays within ±w·(1 + 2e) at e spans beyond.  The stopped rows' own range is no
such unit: where the only stop fitted is a cold rest (stand data often begin so: a short
rest, then running) it spans the sensors' noise, and a warm stop later counted thousands
of spans.  Fitted on the real data's first 4.1 h (465 s of rest, then 1250 rpm), the 4-h
stop after them lay 8938 spans of a 90-min lag above the rest, a band ×17878 and 2.25 m
wide in its median, where the speed lags alone widen it ×4.1 as the spindle stops (523
µm over the stop); in the fitted range's span it lies 1.8 spans above at most, ×4.5
(1.21 mm: the heat outlasts the speed lags).  A floor on the stops' span (0.5 or 1 K)
left ×42 and ×22 there, and a model fitted on the rest and three runs 192 and 144 µm wide
in the median over the four tests, against 56 µm by the speed alone (58 µm so).  On the
four tests, whose folds hold 4-h stops, the unit changes little: the worst probe's
coverage over the 72 cases has median 96.1 % either way and minimum 31.6 → 31.5 %; the
1250 and 5000 rpm tests' bands are up to 1.3 % narrower.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from twin.drift.features import FeatureSpec

SPEED_PREFIX = "speed_"
SPEED_NOW = "speed_krpm"
"""The feature that tells a running row (non-zero) from a stopped one."""


def operating_features(spec: FeatureSpec) -> list[str]:
    """The feature names that set the operating point (see the module note)."""
    names = spec.names
    speed = [n for n in names if n.startswith(SPEED_PREFIX)]
    return speed or names


def state_features(spec: FeatureSpec) -> list[str]:
    """The temperature features a stopped row's thermal state is held against (see the
    module note): none for a model without the speed, whose operating features they are."""
    operating = operating_features(spec)
    return [n for n in spec.names if n not in operating]


def _running(spec: FeatureSpec, X: np.ndarray) -> np.ndarray | None:
    """Rows of X where the spindle runs; None for a model without the speed."""
    if SPEED_NOW not in spec.names:
        return None
    return X[:, spec.names.index(SPEED_NOW)] != 0


def _ends(x: np.ndarray) -> tuple[tuple[float, ...], tuple[float, ...]] | None:
    if x.shape[0] == 0:
        return None
    return tuple(float(v) for v in x.min(axis=0)), tuple(float(v) for v in x.max(axis=0))


@dataclass(frozen=True)
class OperatingRange:
    """The training rows' range of the operating features (`features`, names of
    `FeatureSpec.names`): `lo`, `hi` per feature over the running rows (every row for a
    model without the speed), `stopped_lo`, `stopped_hi` over the stopped ones (None
    without any: a stopped row is then held against the running rows' range, as a running
    row is without any running training row); `stopped_state_lo`, `stopped_state_hi` the
    stopped rows' range of the `state_features` (None in a file written before them, or
    without stopped training rows: no stopped row is then held against its state) and
    `state_span` their span over every training row, running and stopped, the unit a
    hotter stop's excess is counted in (None in a file written before it: its stops are
    then held against the speed alone, as before the state counted)."""

    features: tuple[str, ...]
    lo: tuple[float, ...]
    hi: tuple[float, ...]
    stopped_lo: tuple[float, ...] | None = None
    stopped_hi: tuple[float, ...] | None = None
    state_features: tuple[str, ...] = ()
    stopped_state_lo: tuple[float, ...] | None = None
    stopped_state_hi: tuple[float, ...] | None = None
    state_span: tuple[float, ...] | None = None

    @classmethod
    def of(cls, spec: FeatureSpec, X: np.ndarray) -> OperatingRange:
        """The ranges of the operating features over the rows of X (n, len(spec.names))."""
        features = operating_features(spec)
        x = X[:, [spec.names.index(f) for f in features]]
        running = _running(spec, X)
        if running is None:
            return cls(tuple(features), *_ends(x))
        run, stop = _ends(x[running]), _ends(x[~running])
        lo, hi = run or stop
        if not (run and stop):
            return cls(tuple(features), lo, hi)
        state = state_features(spec)
        if not state:
            return cls(tuple(features), lo, hi, *stop)
        columns = [spec.names.index(f) for f in state]
        span = tuple(float(v) for v in np.ptp(X[:, columns], axis=0))
        return cls(tuple(features), lo, hi, *stop, tuple(state),
                   *_ends(X[~running][:, columns]), span)

    @property
    def named(self) -> tuple[str, ...]:
        """The features `excess` indexes: the operating ones, then the state ones."""
        return self.features + self.state_features

    def to_json(self) -> dict:
        doc = {"features": list(self.features), "lo": list(self.lo), "hi": list(self.hi)}
        if self.stopped_lo is not None and self.stopped_hi is not None:
            doc.update(stopped_lo=list(self.stopped_lo), stopped_hi=list(self.stopped_hi))
        if self.stopped_state_lo is not None and self.stopped_state_hi is not None:
            doc.update(state_features=list(self.state_features),
                       stopped_state_lo=list(self.stopped_state_lo),
                       stopped_state_hi=list(self.stopped_state_hi))
            if self.state_span is not None:
                doc.update(state_span=list(self.state_span))
        return doc

    @classmethod
    def from_json(cls, doc: dict) -> OperatingRange:
        def floats(key: str) -> tuple[float, ...] | None:
            return None if doc.get(key) is None else tuple(float(v) for v in doc[key])

        return cls(tuple(doc["features"]), floats("lo"), floats("hi"),
                   floats("stopped_lo"), floats("stopped_hi"),
                   tuple(doc.get("state_features") or ()), floats("stopped_state_lo"),
                   floats("stopped_state_hi"), floats("state_span"))

    def excess(self, spec: FeatureSpec, X: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(excess (n,), index into `named` of the feature furthest out (n,)) of the rows
        of X (n, len(spec.names)).  A feature that held one value in training counts its
        distance in its own units (a speed in krpm, a rise in K); a stopped row's state
        counts in spans of the state's range over every training row (see the module
        note)."""
        x = X[:, [spec.names.index(f) for f in self.features]]
        excess, worst = range_excess(x, np.asarray(self.lo), np.asarray(self.hi))
        running = _running(spec, X)
        if running is not None and self.stopped_lo is not None and self.stopped_hi is not None:
            stopped = ~running
            excess[stopped], worst[stopped] = range_excess(
                x[stopped], np.asarray(self.stopped_lo), np.asarray(self.stopped_hi))
            if (self.stopped_state_lo is not None and self.stopped_state_hi is not None
                    and self.state_span is not None):
                state = X[stopped][:, [spec.names.index(f) for f in self.state_features]]
                hotter, which = range_excess(state, np.asarray(self.stopped_state_lo),
                                             np.asarray(self.stopped_state_hi), above_only=True,
                                             span=np.asarray(self.state_span))
                further = hotter > excess[stopped]
                excess[stopped] = np.where(further, hotter, excess[stopped])
                worst[stopped] = np.where(further, len(self.features) + which, worst[stopped])
        return excess, worst


def range_excess(x: np.ndarray, lo: np.ndarray, hi: np.ndarray, above_only: bool = False,
                 span: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Per row of x (n, k), the largest of (x − hi)/span and (lo − x)/span over the
    columns (0 inside [lo, hi]; span = hi − lo unless given, 1 where it is 0), and its
    column; with `above_only`, of (x − hi)/span alone."""
    x = np.atleast_2d(np.asarray(x, dtype=float))
    if x.shape[1] == 0:
        return np.zeros(x.shape[0]), np.zeros(x.shape[0], dtype=np.int64)
    span = hi - lo if span is None else span
    span = np.where(span > 0, span, 1.0)
    beyond = x - hi if above_only else np.maximum(x - hi, lo - x)
    out = np.maximum(beyond / span, 0.0)
    worst = np.argmax(out, axis=1)
    return out[np.arange(x.shape[0]), worst], worst


def fold_excess(spec_of_fold: Sequence[FeatureSpec], X_of_fold: Sequence[np.ndarray],
                folds: Sequence[tuple[np.ndarray, np.ndarray]], n_rows: int) -> np.ndarray:
    """Excess of every left-out row over its fold's training rows (validation order)."""
    out = np.zeros(n_rows)
    for spec, X, (train, test) in zip(spec_of_fold, X_of_fold, folds, strict=True):
        out[test] = OperatingRange.of(spec, X[train]).excess(spec, X[test])[0]
    return out
