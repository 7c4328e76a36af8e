"""The recorded-run schema (shared DESIGN.md, "Recorded run"): column names and units.

A recorded run is a table with one row per sample.  Temperatures are in °C, speed in rpm,
time in s, displacements in µm.  Column names carry their unit as a suffix.
"""

from __future__ import annotations

from twin.contract import SENSOR_NAMES

TIME = "time_s"
SPEED = "speed_rpm"
AMBIENT = "ambient_C"
COOLANT = "coolant_C"
TEMPERATURES: tuple[str, ...] = tuple(f"{s}_C" for s in SENSOR_NAMES)
DISPLACEMENTS: tuple[str, ...] = ("disp_x_um", "disp_y_um", "disp_z_um")

REQUIRED: tuple[str, ...] = (TIME, SPEED, AMBIENT, *TEMPERATURES)
OPTIONAL: tuple[str, ...] = (COOLANT, *DISPLACEMENTS)
ALL_COLUMNS: tuple[str, ...] = REQUIRED + OPTIONAL

CELSIUS_COLUMNS: tuple[str, ...] = (AMBIENT, COOLANT, *TEMPERATURES)
"""Columns holding temperatures in °C (checked for Kelvin/Fahrenheit mix-ups)."""


MAX_SAMPLE_INTERVAL_S = 10.0
"""The contract accepts any sample rate of at least one sample per 10 s (median interval)."""

MAX_DURATION_S = 24 * 3600.0
"""Longest run the twin replays: one day (1440 windows), the longest run `twin synth`
writes.  Checked on the time column before anything is allocated per step or window."""

MAX_SAMPLES = 1_000_000
"""Most samples a run may hold (a day at about 11 Hz); a faster log must be resampled."""
