"""Analytic corrections of bearing heat and bearing/sleeve contact resistance.

The reference paper's Eq. 2, 3, 5 and 6 (shared REFERENCE.md §1), restated:

- Eq. 2, first heat correction:  H' = (t_m − t_amb) / (t_f − t_amb) · H
- Eq. 3, second heat correction: C_H = Δt_m / Δt_f,  H'' = C_H · H'
- Eq. 5, pressure correction of the contact resistance (interpretation below): R'
- Eq. 6, second resistance correction: C_C = Δt_m / Δt_f,  R'' = C_C · R'

t_m is measured, t_f simulated ("FEM") at the bearing's key point; H and R are the values
the simulation that produced t_f used.  In the online twin that is the previous window's
value, so the corrections act as a multiplicative feedback and leave a value that already
matches the measurement unchanged.

Interpretations (the paper is terse or garbled here):

- Eq. 3's Δt is the temperature *rise over one window* (60 s), so C_H reacts to the current
  heating rate while Eq. 2 reacts to the accumulated rise.
- Eq. 6's Δt is the temperature *drop across the contact*, ring minus sleeve
  (T1 − T2 front, T3 − T4 rear): at a contact the drop is heat flux × resistance, the
  direct signal of the resistance.  Measured drop larger than simulated → resistance too low.
- Eq. 5: Eq. 4 gives R ∝ P^−0.68 (r/(R·k) = 10^5.6 (P/E)^0.68).  The contact pressure of an
  interference fit is proportional to the interference, so a thermal change Δδ of the radial
  interference δ0 changes the pressure by ΔP/P = Δδ/δ0 and
  R' = R · (1 + Δδ/δ0)^−0.68, with Δδ = r_fit · (α_ring · (T_ring − T_0) − α_sleeve ·
  (T_sleeve − T_0)): a ring hotter than its sleeve tightens the fit and lowers R.  Relative
  to a reference state that already had a pressure factor, the ratio of the two factors is
  applied.

Guards (`RatioGuards`): a ratio of two small, noisy numbers is meaningless, so a ratio whose
denominator is below a documented floor, whose terms have opposite signs (one heating, one
cooling), or that is not finite (missing sensor) gives the neutral factor 1; every ratio is
clipped to documented limits; corrected values stay within a band around the nominal value,
which is positive, so no correction can produce a non-positive heat or resistance.

Sign (`guarded_ratio`'s `rises_only`).  Eq. 2 and Eq. 3 read a rise as the work of the
heat, so they hold only while the twin's rise is one: with the simulated rise below its
floor *or negative* they give 1.  Below ambient the ratio of two negative rises runs
backwards: a coolant colder than the air holds a slow bearing's ring under ambient, and a
ring measured 1.4 K below ambient against the twin's 1.8 K (warmer than the twin: the twin
has too little heat) gave 0.76 and cut the heat, which cooled the twin's ring further:
within five windows the front heat was at the 0.2× nominal guard, the twin's ring 4.2 K
below ambient against the measured 2.4 K, and it carried the 0.2 through a stop into the
restart (emulated 4000 rpm on a jacket 8 K below ambient: `ratio` 97.21 %, `bpnn` 97.51 %
temperature accuracy against open loop's 99.39 %; held, 99.27 and 99.37 %).  Likewise two
window rises that are both falls (a ring cooling after a speed step down): cooling faster
than the twin means less heat, not more.  Eq. 6 is not affected: the drop across a contact
is heat flux × resistance in either direction of the flux, so two negative drops (the
sleeve warmer than the ring, as a stop's cooling can leave it) are a resistance ratio as
two positive ones are; only opposite signs carry none.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

CONTACT_PRESSURE_EXPONENT = 0.68
"""Exponent of (P/E) in the contact-resistance correlation (REFERENCE.md §1, Eq. 4)."""


def _check_floor_and_band(guard: object, floor: str, band: str) -> None:
    """The field `floor` of `guard` must be positive and its `band` (low, high) must
    satisfy 0 < low <= 1 <= high (a neutral factor 1 must stay possible)."""
    name = type(guard).__name__
    if not getattr(guard, floor) > 0:
        raise ValueError(f"{name}.{floor} must be positive")
    low, high = getattr(guard, band)
    if not 0 < low <= 1 <= high:
        raise ValueError(f"{name}.{band} must satisfy 0 < low <= 1 <= high")


@dataclass(frozen=True)
class RatioGuard:
    """The guard of one ratio of a measured to a simulated change (°C or K).

    min_denominator  a simulated change below this gives the neutral factor 1
    limits           the clip of the ratio, low ≤ 1 ≤ high
    """

    min_denominator: float
    limits: tuple[float, float]

    def __post_init__(self) -> None:
        _check_floor_and_band(self, "min_denominator", "limits")


@dataclass(frozen=True)
class RatioGuards:
    """Limits that keep the ratio corrections finite, positive and calm.

    The floors are about ten times the sensor noise of a thermocouple channel (0.05 °C)
    so that a ratio is only taken when both rises are signal, not noise.
    """

    total: RatioGuard = RatioGuard(0.5, (0.5, 2.0))
    """Eq. 2: a simulated rise over ambient below 0.5 °C (the first seconds of a run) or
    negative (a ring below ambient) → 1."""
    window: RatioGuard = RatioGuard(0.1, (0.8, 1.25))
    """Eq. 3 (C_H): a simulated rise over one window below 0.1 °C (near balance) → 1; one
    window may change the heat by at most the clip's factor."""
    contact: RatioGuard = RatioGuard(0.1, (0.8, 1.25))
    """Eq. 6 (C_C): a simulated ring-to-sleeve drop below 0.1 °C → 1."""
    value_limits: tuple[float, float] = (0.2, 5.0)
    """Corrected H and R stay within these multiples of their nominal (Eq. 1 / Eq. 4) value."""
    min_relative_pressure: float = 0.1
    """Eq. 5: floor of P'/P = 1 + Δδ/δ0 (a fit that opens would make R infinite)."""

    def __post_init__(self) -> None:
        _check_floor_and_band(self, "min_relative_pressure", "value_limits")


DEFAULT_GUARDS = RatioGuards()


@dataclass(frozen=True)
class ContactFit:
    """Interference fit of a bearing outer ring in its sleeve (for Eq. 5).

    Defaults: outer-ring radius of a 7014-size angular-contact bearing, a light radial
    interference, GCr15 ring and steel-45 sleeve expansion (REFERENCE.md §2).
    """

    fit_radius_m: float = 0.055
    interference_m: float = 4e-6
    """Radial interference δ0 of the cold fit (m)."""
    alpha_ring_per_K: float = 13.3e-6
    alpha_sleeve_per_K: float = 12.2e-6

    def __post_init__(self) -> None:
        for name in ("fit_radius_m", "interference_m", "alpha_ring_per_K", "alpha_sleeve_per_K"):
            if not getattr(self, name) > 0:
                raise ValueError(f"ContactFit.{name} must be positive")


def guarded_ratio(numerator: ArrayLike, denominator: ArrayLike, guard: RatioGuard, *,
                  rises_only: bool = False) -> np.ndarray:
    """numerator / denominator, or 1 where that ratio carries no information.

    Neutral (1) where |denominator| < guard.min_denominator, where the two have opposite
    signs or the numerator is zero, or where either is not finite; with `rises_only`, also
    where the denominator is negative (a ratio of two falls: see the module doc, "Sign");
    otherwise clipped to `guard.limits`.
    """
    num = np.asarray(numerator, dtype=float)
    den = np.asarray(denominator, dtype=float)
    magnitude = den if rises_only else np.abs(den)
    usable = np.isfinite(num) & np.isfinite(den) & (magnitude >= guard.min_denominator)
    safe_den = np.where(usable, den, 1.0)
    ratio = np.where(usable, num / safe_den, 1.0)
    ratio = np.where(ratio > 0, ratio, 1.0)
    return np.clip(ratio, guard.limits[0], guard.limits[1])


def total_rise_ratio(
    measured_C: ArrayLike,
    simulated_C: ArrayLike,
    ambient_C: ArrayLike,
    guards: RatioGuards = DEFAULT_GUARDS,
) -> np.ndarray:
    """Eq. 2 factor (t_m − t_amb) / (t_f − t_amb), guarded; 1 unless the simulated ring is
    above ambient by at least the floor (below ambient the ratio runs backwards)."""
    amb = np.asarray(ambient_C, dtype=float)
    measured_rise = np.asarray(measured_C, dtype=float) - amb
    return guarded_ratio(measured_rise, np.asarray(simulated_C, dtype=float) - amb, guards.total,
                         rises_only=True)


def window_rise_ratio(
    measured_rise_C: ArrayLike, simulated_rise_C: ArrayLike, guards: RatioGuards = DEFAULT_GUARDS
) -> np.ndarray:
    """Eq. 3 coefficient C_H = Δt_m / Δt_f of the rises over one window, guarded; 1 unless
    the simulated ring rose by at least the floor (two falls: the ratio runs backwards)."""
    return guarded_ratio(measured_rise_C, simulated_rise_C, guards.window, rises_only=True)


def contact_drop_ratio(
    measured_drop_C: ArrayLike, simulated_drop_C: ArrayLike, guards: RatioGuards = DEFAULT_GUARDS
) -> np.ndarray:
    """Eq. 6 coefficient C_C = Δt_m / Δt_f of the ring-to-sleeve drops, guarded; two
    negative drops (the flux reversed) are a resistance ratio as two positive ones are."""
    return guarded_ratio(measured_drop_C, simulated_drop_C, guards.contact)


def heat_first_correction(
    heat_W_m3: ArrayLike,
    measured_C: ArrayLike,
    simulated_C: ArrayLike,
    ambient_C: ArrayLike,
    guards: RatioGuards = DEFAULT_GUARDS,
) -> np.ndarray:
    """Eq. 2: H' = (t_m − t_amb)/(t_f − t_amb) · H  [W/m³]."""
    return np.asarray(heat_W_m3, dtype=float) * total_rise_ratio(
        measured_C, simulated_C, ambient_C, guards
    )


def heat_second_correction(first_W_m3: ArrayLike, C_H: ArrayLike) -> np.ndarray:
    """Eq. 3: H'' = C_H · H'  [W/m³]."""
    return np.asarray(first_W_m3, dtype=float) * np.asarray(C_H, dtype=float)


def contact_pressure_factor(
    ring_rise_K: ArrayLike,
    sleeve_rise_K: ArrayLike,
    fit: ContactFit = ContactFit(),
    guards: RatioGuards = DEFAULT_GUARDS,
) -> np.ndarray:
    """Eq. 5 factor (P'/P)^−0.68 = (1 + Δδ/δ0)^−0.68 of a fit whose ring and sleeve have
    warmed by the given rises (K) since assembly (in practice: since the run started cold).

    Non-finite rises (a missing sensor) give the neutral factor 1.
    """
    ring = np.asarray(ring_rise_K, dtype=float)
    sleeve = np.asarray(sleeve_rise_K, dtype=float)
    delta_m = fit.fit_radius_m * (fit.alpha_ring_per_K * ring - fit.alpha_sleeve_per_K * sleeve)
    relative_pressure = 1.0 + delta_m / fit.interference_m
    relative_pressure = np.where(np.isfinite(relative_pressure), relative_pressure, 1.0)
    relative_pressure = np.maximum(relative_pressure, guards.min_relative_pressure)
    return relative_pressure ** (-CONTACT_PRESSURE_EXPONENT)


def resistance_first_correction(
    resistance_m2K_W: ArrayLike,
    pressure_factor_now: ArrayLike,
    pressure_factor_reference: ArrayLike = 1.0,
) -> np.ndarray:
    """Eq. 5: R' = R · f(now) / f(reference)  [m²K/W].

    `pressure_factor_reference` is the factor of the state R belongs to: 1 for the cold
    nominal value of Eq. 4, the previous window's factor for a value already corrected.
    """
    return (
        np.asarray(resistance_m2K_W, dtype=float)
        * np.asarray(pressure_factor_now, dtype=float)
        / np.asarray(pressure_factor_reference, dtype=float)
    )


def resistance_second_correction(first_m2K_W: ArrayLike, C_C: ArrayLike) -> np.ndarray:
    """Eq. 6: R'' = C_C · R'  [m²K/W]."""
    return np.asarray(first_m2K_W, dtype=float) * np.asarray(C_C, dtype=float)


def series_resistance_correction(
    resistance_m2K_W: float, C_C: float, metal_m2K_W: float, noise_log_step: float,
    limits: tuple[float, float],
) -> float:
    """Eq. 6 for a drop that also crosses metal in series with the contact: R + R_m is
    scaled by the part of the drop ratio C_C beyond its noise, R alone by the rest  [m²K/W].

    Eq. 6 (R'' = C_C · R') takes the ring-to-sleeve drop as proportional to R.  Between
    the sensors it is heat flux × (R + R_m), R_m the conduction of the metal between them
    and the contact, so d log(drop) = R/(R + R_m) · d log R and Eq. 6 closes only that
    share of a resistance's log error per window.  Scaling R + R_m by the drop ratio is
    Newton's step on it, but it also multiplies the ratio's noise by (R + R_m)/R; so a
    ratio within `noise_log_step` of 1 (|log C_C| ≤ it: the drop's noise over the drop)
    moves R as Eq. 6 does, and only the part beyond goes through R + R_m:

        R_n = R' · C_n,   R'' = (R_n + R_m) · C_C / C_n − R_m,   C_n = C_C clipped to e^±noise

    The step R''/R' is kept within `limits`; R_m = 0 or an infinite noise step is Eq. 6.
    """
    log_ratio = float(np.log(C_C))
    noise = float(np.clip(log_ratio, -noise_log_step, noise_log_step))
    within_noise = float(resistance_m2K_W) * float(np.exp(noise))
    beyond = float(np.exp(log_ratio - noise))
    new = (within_noise + metal_m2K_W) * beyond - metal_m2K_W
    return float(np.clip(new, limits[0] * resistance_m2K_W, limits[1] * resistance_m2K_W))


def limit_to_nominal(
    value: ArrayLike, nominal: ArrayLike, guards: RatioGuards = DEFAULT_GUARDS
) -> np.ndarray:
    """Clip a corrected heat or resistance into `guards.value_limits` × its nominal value.

    Non-finite values become the nominal value.  A nominal value of 0 (the heat of a
    stopped bearing) gives 0: there is no heat to correct.
    """
    nom = np.asarray(nominal, dtype=float)
    if np.any(~(nom >= 0)):
        raise ValueError("nominal heat and resistance must be ≥ 0")
    low, high = guards.value_limits
    val = np.asarray(value, dtype=float)
    # a non-finite value (e.g. a network fed a NaN) falls back to the nominal value
    val = np.where(np.isfinite(val), val, nom)
    return np.clip(val, low * nom, high * nom)
