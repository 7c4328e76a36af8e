"""Regenerate the bundled demo runs in examples/runs/ (`make examples`).

Deterministic: the same seeds, speeds and ambients give the same files.  Each run comes
with RUN.truth.csv (the emulator's truth, for evaluation only).  Written by `twin synth
--replace-bundled-runs`: without the option every command refuses an --out there, since
every `twin replay` without RUN reads these runs.

    spindle_9000rpm_30min        the reference paper's Table 1 case (25.34 °C ambient)
    spindle_7800rpm_30min        validation speeds of the paper (not in its training set)
    spindle_10800rpm_30min
    spindle_steps_faults_30min   6000 → 9000 → 12000 rpm with a stuck sensor, dropouts
                                 and spikes (examples/scenarios/)
    spindle_warm_12000_7000rpm_30min  recorded from 15 min into a 12000 rpm run, which
                                 drops to 7000 rpm 10 min later (the logger started on a
                                 warm spindle, probes zeroed then: the replay fits its
                                 start field, `twin.loop.start_field`)
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent

RATE_HZ = 0.5  # small files; the run contract accepts down to one sample per 10 s

RUNS = [
    # name, speed rpm (None: profile), ambient °C, seed, profile, scenario, recorded from min
    ("spindle_9000rpm_30min", 9000.0, 25.34, 9000, None, None, 0),
    ("spindle_7800rpm_30min", 7800.0, 24.80, 7800, None, None, 0),
    ("spindle_10800rpm_30min", 10800.0, 25.10, 10800, None, None, 0),
    ("spindle_steps_faults_30min", None, 24.60, 612, "steps_6000_12000.csv", "faults.toml", 0),
    ("spindle_warm_12000_7000rpm_30min", None, 24.90, 1207, "warm_12000_7000.csv", None, 15),
]


def main() -> None:
    (HERE / "runs").mkdir(exist_ok=True)
    for name, speed, ambient, seed, profile, scenario, record_from in RUNS:
        # relative to ROOT: the run's header names its profile and scenario as given
        args = ["--speed", f"{speed:g}"] if speed is not None else [
            "--profile", f"examples/scenarios/{profile}"]
        if scenario:
            args += ["--scenario", f"examples/scenarios/{scenario}"]
        if record_from:  # 30 min recorded either way
            args += ["--record-from", f"{record_from:g}"]
        subprocess.run([sys.executable, "-m", "twin", "synth", *args, "--minutes",
                        f"{30 + record_from:g}",
                        "--ambient", f"{ambient:g}", "--seed", str(seed), "--rate",
                        f"{RATE_HZ:g}", "--out", f"examples/runs/{name}.csv",
                        "--replace-bundled-runs"], check=True, cwd=ROOT)


if __name__ == "__main__":
    main()
