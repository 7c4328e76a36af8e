"""An ensemble as a mean and anomalies, over the augmented state [T (n dofs), φ (p)].

Members are never stored as n full fields each: member j is mean + anomalies[:, j].  The
anomalies are kept centred (zero mean over the members), so the sample covariance is
A Aᵀ/(N − 1) and the mean is the one trajectory the deck runs.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class Ensemble:
    """Mean and centred anomalies of the field (°C) and the log-factors."""

    field_mean: np.ndarray  # (n,)
    field_anomalies: np.ndarray  # (n, N)
    log_factor_mean: np.ndarray  # (p,)
    log_factor_anomalies: np.ndarray  # (p, N)

    @property
    def size(self) -> int:
        return self.field_anomalies.shape[1]

    @classmethod
    def initial(
        cls,
        field_C: np.ndarray,
        field_sd_C: float,
        prior_sd: np.ndarray,
        members: int,
        rng: np.random.Generator,
    ) -> Ensemble:
        """A spindle at rest: the field known up to a uniform offset of `field_sd_C`, the
        log-factors at 0 with the prior spreads.  The anomalies' sample covariance equals the
        prior exactly — right spreads and no spurious correlations between parameters, which
        a small random ensemble would feed into every later update."""
        p = len(prior_sd)
        if members < p + 2:
            raise ValueError(f"an ensemble of {p} parameters needs at least {p + 2} members, "
                             f"got {members}")
        z = orthonormal_rows(rng.standard_normal((p + 1, members)))
        offsets = field_sd_C * z[0]
        return cls(
            field_mean=np.asarray(field_C, float).copy(),
            field_anomalies=np.outer(np.ones(len(field_C)), offsets),
            log_factor_mean=np.zeros(p),
            log_factor_anomalies=np.asarray(prior_sd, float)[:, None] * z[1:],
        )

    def stacked(self) -> tuple[np.ndarray, np.ndarray]:
        """(mean, anomalies) of the augmented state [T; φ]."""
        return (
            np.r_[self.field_mean, self.log_factor_mean],
            np.vstack([self.field_anomalies, self.log_factor_anomalies]),
        )

    @classmethod
    def from_stacked(cls, mean: np.ndarray, anomalies: np.ndarray, n_field: int) -> Ensemble:
        return cls(mean[:n_field].copy(), anomalies[:n_field].copy(),
                   mean[n_field:].copy(), anomalies[n_field:].copy())

    def log_factor_sd(self) -> np.ndarray:
        return np.sqrt(np.sum(self.log_factor_anomalies**2, axis=1) / (self.size - 1))


def orthonormal_rows(z: np.ndarray) -> np.ndarray:
    """Rows centred, mutually orthogonal and of unit sample spread: Z Zᵀ/(N − 1) = I."""
    k, n = z.shape
    q, _ = np.linalg.qr((z - z.mean(axis=1, keepdims=True)).T)
    return np.sqrt(n - 1) * q[:, :k].T


def standardized(z: np.ndarray) -> np.ndarray:
    """Rows centred and scaled to unit sample spread (ddof = 1)."""
    z = z - z.mean(axis=1, keepdims=True)
    sd = np.sqrt(np.sum(z**2, axis=1, keepdims=True) / (z.shape[1] - 1))
    return z / np.where(sd > 0, sd, 1.0)


def add_random_walk(
    anomalies: np.ndarray, walk_sd: np.ndarray, rng: np.random.Generator
) -> np.ndarray:
    """Anomalies with an independent centred random-walk step of spread walk_sd per row
    (the parameters may move between windows; without it the filter would freeze them)."""
    steps = standardized(rng.standard_normal(anomalies.shape)) * np.asarray(walk_sd)[:, None]
    return anomalies + steps


def cap_spread(anomalies: np.ndarray, max_sd: np.ndarray) -> np.ndarray:
    """Rows whose sample spread exceeds max_sd scaled back to it (an unobserved parameter
    must not random-walk beyond its prior: that spread would only feed spurious updates)."""
    n = anomalies.shape[1]
    sd = np.sqrt(np.sum(anomalies**2, axis=1) / (n - 1))
    scale = np.where(sd > max_sd, max_sd / np.where(sd > 0, sd, 1.0), 1.0)
    return anomalies * scale[:, None]
