"""Regenerate the bundled demo runs in examples/runs/ (`make examples`).

Deterministic: the same seeds, speeds and ambients give the same files.  Each run comes
with RUN.truth.csv (the emulator's truth, for evaluation only).

    spindle_9000rpm_30min        the reference paper's Table 1 case (25.34 °C ambient)
    spindle_7800rpm_30min        validation speeds of the paper (not in its training set)
    spindle_10800rpm_30min
    spindle_steps_faults_30min   6000 → 9000 → 12000 rpm with a stuck sensor, dropouts
                                 and spikes (examples/scenarios/)
"""

from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))

RATE_HZ = 0.5  # small files; the run contract accepts down to one sample per 10 s

RUNS = [
    # name, speed rpm (None: profile), ambient °C, seed, profile, scenario
    ("spindle_9000rpm_30min", 9000.0, 25.34, 9000, None, None),
    ("spindle_7800rpm_30min", 7800.0, 24.80, 7800, None, None),
    ("spindle_10800rpm_30min", 10800.0, 25.10, 10800, None, None),
    ("spindle_steps_faults_30min", None, 24.60, 612, "steps_6000_12000.csv", "faults.toml"),
]


def main() -> None:
    from twin.plant.emulator import synthesize, write_synth
    from twin.plant.profile import read_speed_profile
    from twin.plant.scenario import load_scenario

    out_dir = HERE / "runs"
    out_dir.mkdir(exist_ok=True)
    for name, speed, ambient, seed, profile, scenario in RUNS:
        scenario_path = HERE / "scenarios" / scenario if scenario else None
        profile_path = HERE / "scenarios" / profile if profile else None
        run = synthesize(
            speed_rpm=speed,
            profile=read_speed_profile(profile_path) if profile_path else None,
            minutes=30.0, ambient_C=ambient, seed=seed, rate_hz=RATE_HZ,
            scenario=load_scenario(scenario_path),
            scenario_name=f"examples/scenarios/{scenario}" if scenario else None,
            profile_name=f"examples/scenarios/{profile}" if profile else None,
        )
        path, truth = write_synth(run, out_dir / f"{name}.csv")
        print(f"{path.relative_to(HERE.parent)}  ({run.n_samples} samples, "
              f"{run.elapsed_s:.1f} s)  + {truth.name}")


if __name__ == "__main__":
    main()
