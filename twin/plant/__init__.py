"""The emulated spindle ("plant"): a truth model that produces recorded runs.

    scenario    scenario TOML (truth factors, sensors, faults) → `Scenario`
    profile     speed profile CSV → `SpeedProfile`
    timetable   `TimeTable` (linear), `StepTable` (held)
    truth       default truth factors (seeded) and their merge with a scenario
    sensors     thermocouple lag, noise, faults
    emulator    the truth FEM run and `synthesize` (used by `twin synth`)
"""
