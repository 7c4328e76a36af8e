"""Names and numbers of the twin's contract (shared DESIGN.md), defined once.

Sensors: the five thermocouples of the reference spindle (REFERENCE.md §1):
T1 front-bearing outer ring, T2 front-bearing sleeve, T3 rear-bearing outer ring,
T4 rear-bearing sleeve, T5 housing surface.  A recorded run stores them as `T1_C`..`T5_C`.

Windows: the corrections update the boundary conditions every `WINDOW_S` (60 s); within a
window the transient is re-solved in `STEPS_PER_WINDOW` (15) backward-Euler steps of
`STEP_S` (4 s).  Window k covers [60 k, 60 k + 60) s.
"""

from __future__ import annotations

import math

SENSOR_NAMES: tuple[str, ...] = ("T1", "T2", "T3", "T4", "T5")
"""The thermocouples T1..T5, in the order of every (…, 5) temperature array."""

SENSOR_LOCATIONS: dict[str, str] = {
    "T1": "front-bearing outer ring", "T2": "front-bearing sleeve",
    "T3": "rear-bearing outer ring", "T4": "rear-bearing sleeve", "T5": "housing surface",
}
"""Where each thermocouple sits (REFERENCE.md §1), as figures and pages name it."""

WINDOW_S = 60.0
"""Correction window length (s)."""

STEPS_PER_WINDOW = 15
"""Backward-Euler solver steps per window."""

STEP_S = WINDOW_S / STEPS_PER_WINDOW
"""Solver time step (s): 4 s."""


def windows_in(duration_s: float) -> int:
    """Whole 60 s windows in a run of `duration_s`: a replay keeps a field at each one's
    end, `WINDOW_S` · k for k = 1 … windows_in."""
    return math.floor(duration_s / WINDOW_S + 1e-9)


OPERATING_TEMPERATURE_C = (-40.0, 45.0)
"""The plausible ambient air and coolant inlet temperatures (°C, closed range): the one
range every command and reader accepts — a recorded run's `ambient_C` and `coolant_C` rows
(`twin replay`, `twin train`), `--ambient` and `--coolant` of `twin simulate` and `twin
synth`, a speed profile's `ambient_C` and a scenario's `[ambient]` and `[coolant]`.  The
lower end is the film, viscosity and fit models' envelope; the upper one is above any
machine-shop air or spindle coolant, and where a logged air or coolant temperature reads as
Fahrenheit (45 °F is 7 °C: a room or coolant logged in °F reads above it;
`twin.runs.validate`).

Why one range: until 2026-11-27 replay and simulate took −40..80 °C (replay refusing a
median of 45 °C or more as Fahrenheit), synth −30..45 and profiles and scenarios −30..60,
so a profile's 50 °C was emulated in full and only then refused, without its row, as a
run replay would read as Fahrenheit."""
