"""Names and numbers of the twin's contract (shared DESIGN.md), defined once.

Sensors: the five thermocouples of the reference spindle (REFERENCE.md §1):
T1 front-bearing outer ring, T2 front-bearing sleeve, T3 rear-bearing outer ring,
T4 rear-bearing sleeve, T5 housing surface.  A recorded run stores them as `T1_C`..`T5_C`.

Windows: the corrections update the boundary conditions every `WINDOW_S` (60 s); within a
window the transient is re-solved in `STEPS_PER_WINDOW` (15) backward-Euler steps of
`STEP_S` (4 s).  Window k covers [60 k, 60 k + 60) s.
"""

from __future__ import annotations

SENSOR_NAMES: tuple[str, ...] = ("T1", "T2", "T3", "T4", "T5")
"""The thermocouples T1..T5, in the order of every (…, 5) temperature array."""

WINDOW_S = 60.0
"""Correction window length (s)."""

STEPS_PER_WINDOW = 15
"""Backward-Euler solver steps per window."""

STEP_S = WINDOW_S / STEPS_PER_WINDOW
"""Solver time step (s): 4 s."""
