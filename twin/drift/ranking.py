"""Sensor ranking: grey relational grade (REFERENCE.md §4) and correlation clusters (§5).

Grey relational analysis compares the shape of every candidate series x_i with the
reference series x_0 (a drift):

    Δ_i(k) = |x_0(k) − x_i(k)|                       after normalising every series
    ξ_i(k) = (min_i min_k Δ + ρ·max_i max_k Δ) / (Δ_i(k) + ρ·max_i max_k Δ),  ρ = 0.5
    grade_i = mean_k ξ_i(k)

REFERENCE §4 normalises by the mean (`normalise="mean"`).  A drift starts at zero and
may change sign, so its mean can be near zero and mean-normalised temperatures barely
move (x/x̄ ≈ 1 ± 0.1 in °C); the ranking then mostly measures the drift itself.  The
ranking of sensors for a model therefore uses the min–max form (`normalise="range"`,
also standard in grey systems theory) and, for a drift falling with temperature, the
mirrored series.

Sensors that move together carry one piece of information: average-linkage clustering
on the distance 1 − |r| (Pearson r) groups them, and each cluster keeps its best-ranked
member (REFERENCE §4: "drop points that duplicate a symmetric partner").
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

RHO = 0.5
"""Distinguishing coefficient ρ of the grey relational coefficient (REFERENCE §4)."""

CLUSTER_MIN_ABS_R = 0.99
"""Sensors correlated at least this strongly (|r|) fall in one cluster."""


def _normalise(x: np.ndarray, how: str) -> np.ndarray:
    x = np.asarray(x, dtype=float)
    if how == "mean":
        mean = x.mean(axis=0)
        if np.any(mean == 0):
            raise ValueError("a series with zero mean cannot be mean-normalised")
        return x / mean
    if how == "range":
        lo, hi = x.min(axis=0), x.max(axis=0)
        span = np.where(hi > lo, hi - lo, 1.0)
        return (x - lo) / span
    raise ValueError(f"unknown normalisation {how!r}")


def grey_relational_grade(reference: np.ndarray, candidates: np.ndarray, rho: float = RHO,
                          normalise: str = "mean") -> np.ndarray:
    """Grey relational grade of every column of `candidates` (n, m) to `reference` (n,)."""
    x0 = _normalise(np.asarray(reference, dtype=float)[:, None], normalise)
    xi = _normalise(candidates, normalise)
    delta = np.abs(x0 - xi)
    d_min, d_max = delta.min(), delta.max()
    if d_max == 0:
        return np.ones(xi.shape[1])
    xi_k = (d_min + rho * d_max) / (delta + rho * d_max)
    return xi_k.mean(axis=0)


def sensor_grades(target: np.ndarray, T_C: np.ndarray, rho: float = RHO) -> np.ndarray:
    """Range-normalised grey relational grade of each sensor for one drift.

    A sensor that falls as the drift rises is as informative as one that rises with it,
    so each sensor is graded in the direction it correlates with the drift.
    """
    ok = np.isfinite(target)
    y, T = target[ok], T_C[ok]
    sign = np.sign([np.corrcoef(y, T[:, j])[0, 1] if np.ptp(T[:, j]) > 0 else 1.0
                    for j in range(T.shape[1])])
    sign[sign == 0] = 1.0
    return grey_relational_grade(y, T * sign, rho=rho, normalise="range")


def correlation_clusters(T_C: np.ndarray, min_abs_r: float = CLUSTER_MIN_ABS_R) -> np.ndarray:
    """Cluster label (0, 1, …) of every column: average linkage on 1 − |r|."""
    from scipy.cluster.hierarchy import fcluster, linkage
    from scipy.spatial.distance import squareform

    m = T_C.shape[1]
    if m == 1:
        return np.zeros(1, dtype=np.int64)
    std = T_C.std(axis=0)
    r = np.corrcoef(np.where(std > 0, T_C, T_C + np.arange(T_C.shape[0])[:, None]), rowvar=False)
    r = np.nan_to_num(r)
    distance = np.clip(1.0 - np.abs(r), 0.0, None)
    np.fill_diagonal(distance, 0.0)
    tree = linkage(squareform(distance, checks=False), method="average")
    labels = fcluster(tree, t=1.0 - min_abs_r, criterion="distance")
    # relabel in order of first appearance so the labels do not depend on scipy's numbering
    _, first = np.unique(labels, return_index=True)
    order = {labels[i]: k for k, i in enumerate(sorted(first))}
    return np.array([order[v] for v in labels], dtype=np.int64)


@dataclass(frozen=True)
class SensorRanking:
    """Sensors by decreasing mean grade, their grades per target and cluster labels."""

    sensors: list[str]
    grades: dict[str, list[float]]       # target -> grade of each sensor (in `sensors` order)
    mean_grade: list[float]
    cluster: list[int]
    representative: list[bool]           # best-graded member of its cluster

    def to_json(self) -> dict:
        return {"sensors": [
            {"sensor": s, "mean_grade": g, "cluster": c, "representative": r,
             "grades": {t: v[i] for t, v in self.grades.items()}}
            for i, (s, g, c, r) in enumerate(zip(self.sensors, self.mean_grade, self.cluster,
                                                  self.representative, strict=True))]}

    def pick(self, k: int | None = None) -> list[str]:
        """The best `k` cluster representatives (all of them for None), best first."""
        reps = [s for s, r in zip(self.sensors, self.representative, strict=True) if r]
        return reps if k is None else reps[:k]


def rank_sensors(names: Sequence[str], T_C: np.ndarray, targets: dict[str, np.ndarray],
                 min_abs_r: float = CLUSTER_MIN_ABS_R) -> SensorRanking:
    """Rank temperature sensors for the given drifts (grey relational grade, ρ = 0.5)."""
    grades = {t: sensor_grades(y, T_C) for t, y in targets.items()}
    mean = np.mean(list(grades.values()), axis=0)
    labels = correlation_clusters(T_C, min_abs_r)
    order = np.argsort(-mean, kind="stable")
    seen: set[int] = set()
    representative = []
    for i in order:
        representative.append(int(labels[i]) not in seen)
        seen.add(int(labels[i]))
    return SensorRanking(
        sensors=[names[i] for i in order],
        grades={t: [float(g[i]) for i in order] for t, g in grades.items()},
        mean_grade=[float(mean[i]) for i in order],
        cluster=[int(labels[i]) for i in order], representative=representative)
