"""Seeded scenario suites: `twin synth --suite N --seed S [--minutes M] --out DIR`.

Run i of suite S is drawn from its own seed sequence (S, i), so a case does not depend on
how many others the suite has, and any one of them can be redrawn alone:

    case = draw_case(suite_seed=1, index=4, minutes=40)    # a SuiteCase
    run = synthesize_case(case)                             # its SynthRun
    paths = write_case(case, Path("out/suite"))             # the four files

Each case is written as `<name>.profile.csv` and `<name>.scenario.toml` (with the exact
`twin synth` command line that reproduces it in its header), then synthesized from the
files just written, so `twin synth --profile … --scenario … --seed …` gives the same
`<name>.csv` and `<name>.truth.csv` byte for byte.

The distribution (U: uniform, logU: log-uniform; factor tables hold three points at the
start, middle and end of the run, each within ±8 % of the run's draw and inside the range):

    =========================  ===========================================================
    speed profile              1–4 steps, U(3000 rpm, the spindle's limit) rounded to
                               100 rpm, step changes U(15–85 %) of the run (10 s grid)
    stop                       in every third run (i = 2, 5, 8, …): 0 rpm from U(35–75 %)
                               of the run for U(10–30 %) of it; past 95 % it lasts to the
                               end (a cool-down run)
    ambient                    U(18, 30) °C at the start, drift U(−1.5, +2.5) K over the run
    coolant inlet              ambient + U(−2, +1) K, drifting U(0, 2) K over the run
    bearing_heat front/rear    U(0.6, 1.6)
    contact_resistance f/r     logU(0.5, 2.0)
    motor_heat                 U(0.7, 1.35), constant
    film.coolant|housing|
      air_gap|rotor            U(0.6, 1.5) each, constant
    material                   conductivity U(0.9, 1.1), expansion U(0.95, 1.05)
    sensors                    lag_s U(4, 20), noise_C U(0.02, 0.1), noise_um U(0.05, 0.3),
                               placement_mm U(0, 2); T1..T5 calibration offsets
                               U(−0.3, 0.3) K each (drawn last: the other draws are those
                               of the suites before offsets existed)
    faults                     stuck T sensor with p = 0.2; 1–2 dropouts (30–300 s) with
                               p = 0.3; 1–3 spikes (±3–8 °C) with p = 0.3
    =========================  ===========================================================

Sensor noise against a real machine (`tools/sensor_noise.py`): the real data in
`examples/real` (15 s sampling) have 0.005–0.016 °C thermocouple noise and 0.02–0.04 µm
on the probes of a running spindle; even as 15 s averages (√15 more per 1 s sample) that
is at most 0.06 °C and 0.15 µm, below the upper ends drawn here.

Calibration offsets: a Pt100 of tolerance class A reads within ±0.21 K at 30 °C, class B
within ±0.45 K; thermocouples of one stand calibrated together agree to a few tenths.
Drawn uniform over ±0.3 K, an offset is never known to the twin (the truth file records
it).  The ambient and coolant readings get none here: their offsets move every method's
boundary alike (a scenario's `[sensors] offset_C` can give them one).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from twin.contract import SENSOR_NAMES
from twin.plant.scenario import Scenario, dump_scenario, parse_scenario
from twin.plant.truth import FILM_GROUPS

if TYPE_CHECKING:
    from twin.plant.emulator import SynthRun
    from twin.plant.profile import SpeedProfile
    from twin.spindle.model import SpindleModel

MIN_SPEED_RPM = 3000.0
STOP_EVERY = 3
"""Every third run (index 2, 5, 8, …) has a stop: a third of the suite."""
DEFAULT_MINUTES = 40.0
DEFAULT_RATE_HZ = 1.0
TEMPERATURE_SENSORS = SENSOR_NAMES

RANGES: dict[str, tuple[float, float]] = {
    "ambient_C": (18.0, 30.0),
    "ambient_drift_K": (-1.5, 2.5),
    "coolant_offset_K": (-2.0, 1.0),
    "coolant_drift_K": (0.0, 2.0),
    "bearing_heat": (0.6, 1.6),
    "contact_resistance": (0.5, 2.0),
    "motor_heat": (0.7, 1.35),
    "film": (0.6, 1.5),
    "conductivity": (0.9, 1.1),
    "expansion": (0.95, 1.05),
    "lag_s": (4.0, 20.0),
    "noise_C": (0.02, 0.1),
    "noise_um": (0.05, 0.3),
    "placement_mm": (0.0, 2.0),
    "calibration_offset_C": (-0.3, 0.3),
}
"""The ranges of the module doc's table (the single source of the numbers)."""
TABLE_WOBBLE = 0.08
"""Factor tables move within ±8 % of the run's draw over the run."""


@dataclass(frozen=True)
class SuiteCase:
    """One drawn run: its name, synth seed, length, speed profile and scenario."""

    name: str
    suite_seed: int
    index: int
    seed: int
    minutes: float
    rate_hz: float
    profile_rows: tuple[tuple[float, float], ...]
    """(time_s, speed_rpm): each speed holds until the next row."""
    scenario: Scenario

    @property
    def ambient_C(self) -> float:
        """The ambient at the start (the `--ambient` of the reproducing command)."""
        return float(self.scenario.ambient.ambient_C[0])

    @property
    def has_stop(self) -> bool:
        return any(speed == 0.0 for _, speed in self.profile_rows)

    def command(self) -> str:
        """The `twin synth` command line that reproduces this case from its files."""
        return (f"twin synth --profile {self.name}.profile.csv --scenario "
                f"{self.name}.scenario.toml --seed {self.seed} --minutes {self.minutes:g} "
                f"--ambient {self.ambient_C:g} --rate {self.rate_hz:g} --out {self.name}.csv")


def case_name(suite_seed: int, index: int) -> str:
    return f"suite{suite_seed}_{index + 1:03d}"


def _r(x: float, digits: int = 4) -> float:
    return round(float(x), digits)


def _factor_table(rng: np.random.Generator, low: float, high: float, duration_s: float,
                  log: bool = False) -> dict:
    base = math.exp(rng.uniform(math.log(low), math.log(high))) if log else rng.uniform(low, high)
    wobble = base * (1.0 + rng.uniform(-TABLE_WOBBLE, TABLE_WOBBLE, 3))
    return {"time_s": [0.0, _r(duration_s / 2, 1), _r(duration_s, 1)],
            "factor": [_r(min(max(w, low), high)) for w in wobble]}


def _speed_profile(rng: np.random.Generator, duration_s: float, max_speed_rpm: float,
                   stop: bool) -> tuple[tuple[float, float], ...]:
    n_steps = int(rng.integers(1, 5))
    speeds = np.round(rng.uniform(MIN_SPEED_RPM, max_speed_rpm, n_steps) / 100.0) * 100.0
    changes = np.unique(np.round(rng.uniform(0.15, 0.85, n_steps - 1) * duration_s / 10.0) * 10.0)
    times = np.r_[0.0, changes]
    rows = [(float(t), float(s)) for t, s in zip(times, speeds, strict=False)]
    stop_at = _r(rng.uniform(0.35, 0.75) * duration_s / 10.0, 0) * 10.0
    stop_end = stop_at + _r(rng.uniform(0.10, 0.30) * duration_s / 10.0, 0) * 10.0
    if not stop:
        return tuple(rows)

    def speed_at(t: float) -> float:
        return [s for time, s in rows if time <= t][-1]

    resumed = [] if stop_end >= 0.95 * duration_s else [(stop_end, speed_at(stop_end))]
    before = [r for r in rows if r[0] < stop_at]
    after = [r for r in rows if r[0] > stop_end and resumed]
    return tuple([*before, (stop_at, 0.0), *resumed, *after])


def _faults(rng: np.random.Generator, duration_s: float) -> dict:
    faults: dict = {}
    if rng.uniform() < 0.2:
        faults["stuck"] = [str(rng.choice(TEMPERATURE_SENSORS))]
    if rng.uniform() < 0.3:
        drops = []
        for _ in range(int(rng.integers(1, 3))):
            start = _r(rng.uniform(0.1, 0.9) * duration_s, 0)
            drops.append({"sensor": str(rng.choice(TEMPERATURE_SENSORS)), "start_s": start,
                          "end_s": start + _r(rng.uniform(30.0, 300.0), 0)})
        faults["dropouts"] = drops
    if rng.uniform() < 0.3:
        faults["spikes"] = [
            {"sensor": str(rng.choice(TEMPERATURE_SENSORS)),
             "time_s": _r(rng.uniform(0.05, 0.95) * duration_s, 0),
             "size": _r(rng.choice([-1.0, 1.0]) * rng.uniform(3.0, 8.0), 2)}
            for _ in range(int(rng.integers(1, 4)))]
    return faults


def draw_case(suite_seed: int, index: int, minutes: float = DEFAULT_MINUTES,
              max_speed_rpm: float = 15000.0, rate_hz: float = DEFAULT_RATE_HZ) -> SuiteCase:
    """Run `index` of suite `suite_seed` (see the module doc for the distribution)."""
    if not (minutes > 0 and index >= 0):
        raise ValueError("minutes must be positive and index ≥ 0")
    sequence = np.random.SeedSequence([int(suite_seed), int(index)])
    rng = np.random.default_rng(sequence)
    duration = float(minutes) * 60.0
    u = rng.uniform
    rows = _speed_profile(rng, duration, max_speed_rpm, stop=index % STOP_EVERY == STOP_EVERY - 1)
    ambient0 = _r(u(*RANGES["ambient_C"]), 2)
    ambient_drift = u(*RANGES["ambient_drift_K"])
    coolant0 = ambient0 + u(*RANGES["coolant_offset_K"])
    coolant_drift = u(*RANGES["coolant_drift_K"])
    half, end = _r(duration / 2, 1), _r(duration, 1)
    data = {
        "ambient": {"time_s": [0.0, half, end],
                    "ambient_C": [ambient0, _r(ambient0 + ambient_drift * u(0.3, 0.7), 2),
                                  _r(ambient0 + ambient_drift, 2)]},
        "coolant": {"time_s": [0.0, _r(duration / 3, 1), end],
                    "inlet_C": [_r(coolant0, 2), _r(coolant0 + coolant_drift * u(0.4, 0.8), 2),
                                _r(coolant0 + coolant_drift, 2)]},
        "bearing_heat": {side: _factor_table(rng, *RANGES["bearing_heat"], duration)
                         for side in ("front", "rear")},
        "contact_resistance": {side: _factor_table(rng, *RANGES["contact_resistance"], duration,
                                                   log=True) for side in ("front", "rear")},
        "motor_heat": {"time_s": [0.0], "factor": [_r(u(*RANGES["motor_heat"]))]},
        "film": {g: {"time_s": [0.0], "factor": [_r(u(*RANGES["film"]))]} for g in FILM_GROUPS},
        "material": {"conductivity": _r(u(*RANGES["conductivity"])),
                     "expansion": _r(u(*RANGES["expansion"]))},
        "sensors": {k: _r(u(*RANGES[k]), 3)
                    for k in ("lag_s", "noise_C", "noise_um", "placement_mm")},
        "faults": _faults(rng, duration),
    }
    data["sensors"]["offset_C"] = {s: _r(u(*RANGES["calibration_offset_C"]), 3) + 0.0
                                   for s in TEMPERATURE_SENSORS}
    scenario = Scenario.model_validate(data)
    seed = int(sequence.generate_state(1)[0])
    return SuiteCase(name=case_name(suite_seed, index), suite_seed=int(suite_seed),
                     index=int(index), seed=seed, minutes=float(minutes), rate_hz=float(rate_hz),
                     profile_rows=rows, scenario=scenario)


def draw_suite(n: int, suite_seed: int, minutes: float = DEFAULT_MINUTES,
               max_speed_rpm: float = 15000.0, rate_hz: float = DEFAULT_RATE_HZ
               ) -> list[SuiteCase]:
    """The first `n` cases of suite `suite_seed`."""
    return [draw_case(suite_seed, i, minutes, max_speed_rpm, rate_hz) for i in range(n)]


def profile_text(case: SuiteCase) -> str:
    lines = [f"# suite {case.suite_seed}, run {case.index + 1}: speed profile (a speed holds "
             "until the next row; 0 is a stop)", "time_s,speed_rpm"]
    lines += [f"{t:g},{s:g}" for t, s in case.profile_rows]
    return "\n".join(lines) + "\n"


def scenario_text(case: SuiteCase) -> str:
    header = (f"suite {case.suite_seed}, run {case.index + 1} (twin.plant.suite)\n"
              f"reproduce: {case.command()}")
    return dump_scenario(case.scenario, header)


def speed_profile(case: SuiteCase) -> SpeedProfile:
    """The case's speed profile, as `read_speed_profile` reads it from `profile_text`
    (times and speeds are whole numbers, so the CSV holds them exactly)."""
    from twin.plant.profile import SpeedProfile
    from twin.plant.timetable import StepTable

    times, speeds = zip(*case.profile_rows, strict=True)
    return SpeedProfile(StepTable(np.array(times), np.array(speeds)))


def synthesize_case(case: SuiteCase, model: SpindleModel | None = None) -> SynthRun:
    """The case's run, synthesized exactly as `twin synth` does from the case's files.

    `model`: the truth's nominal SpindleModel, loaded once for a whole suite (None: loaded
    here)."""
    from twin.plant.emulator import synthesize

    name = case.name
    scenario = parse_scenario(scenario_text(case), f"{name}.scenario.toml")
    return synthesize(profile=speed_profile(case), minutes=case.minutes,
                      ambient_C=case.ambient_C, seed=case.seed, scenario=scenario,
                      rate_hz=case.rate_hz, scenario_name=f"{name}.scenario.toml",
                      profile_name=f"{name}.profile.csv", model=model)


def write_case(case: SuiteCase, out_dir: Path,
               model: SpindleModel | None = None) -> dict[str, Path]:
    """Write the case's profile and scenario, then its run and truth; paths by kind
    (`model` as in `synthesize_case`).  The run is emulated first: written before it, a
    profile and scenario stopped there (Ctrl-C, a failure) stood beside the run of an
    earlier suite of the same seed and another length, as if they described it."""
    from twin.io.atomic import write_text
    from twin.plant.emulator import write_synth

    files = {kind: Path(out_dir) / name for kind, name in case_files(case.name).items()}
    synthesized = synthesize_case(case, model)
    profile = write_text(files["profile"], profile_text(case))
    scenario = write_text(files["scenario"], scenario_text(case))
    run, truth = write_synth(synthesized, files["run"])
    return {"run": run, "truth": truth, "scenario": scenario, "profile": profile}


def case_files(name: str) -> dict[str, str]:
    """The names of the four files a suite's case `name` is written as, by kind."""
    return {"run": f"{name}.csv", "truth": f"{name}.truth.csv",
            "scenario": f"{name}.scenario.toml", "profile": f"{name}.profile.csv"}
