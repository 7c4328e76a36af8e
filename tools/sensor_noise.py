"""The white noise of every temperature and displacement channel of recorded data.

    python tools/sensor_noise.py DATA ... [--json FILE]

DATA is any file `twin drift` reads (CSV or Parquet: `time_s`, optional `speed_rpm`,
`*_C`, `*_um`; a recorded run is one).  Per channel it prints the robust second-difference
estimate the replay's quality check uses (`twin.runs.quality.noise_sigma`), over the
whole file and, where the file has a speed column, over the running (speed > 0) and the
stopped stretches apart: a turning spindle shakes its probes.

Why it is here: the emulated spindle's sensor noise (`twin/plant/suite.py`) should be no
kinder than a real machine's.  On `examples/real/train.csv` (15 s sampling) the
thermocouples give 0.005–0.021 °C (one channel 0.10 °C) and the probes 0.02–0.04 µm while
running, 0.004–0.012 °C (the one 0.08 °C) and 0.012–0.017 µm stopped; the suite draws
0.02–0.1 °C and 0.05–0.3 µm per 1 s sample.  Even if the real logger averaged its 15 s
(noise per second √15 ≈ 3.9 times higher: up to 0.08 °C and 0.14 µm), the suite's upper
ends lie above the real machine.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from twin.drift.data import displacement_columns, read_drift_table, temperature_columns
from twin.errors import InputError
from twin.runs.quality import noise_sigma
from twin.runs.schema import SPEED


def channel_noise(path: Path) -> dict[str, dict[str, float]]:
    """{channel: {"all": σ, "running": σ, "stopped": σ}} of one file (running/stopped
    only where it has a speed column and such stretches)."""
    table = read_drift_table(path)
    speed = table.columns.get(SPEED)
    out: dict[str, dict[str, float]] = {}
    for name in temperature_columns(table) + displacement_columns(table):
        values = table.columns[name]
        sigmas = {"all": noise_sigma(values)}
        if speed is not None:
            for label, keep in (("running", speed > 0), ("stopped", speed == 0)):
                if np.count_nonzero(keep) >= 5:
                    sigmas[label] = noise_sigma(values, keep)
        out[name] = sigmas
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("data", nargs="+", type=Path)
    parser.add_argument("--json", type=Path, help="also write the figures to this file")
    args = parser.parse_args(argv)
    report = {}
    try:
        for path in args.data:
            report[str(path)] = channel_noise(path)
    except InputError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    for file, channels in report.items():
        print(file)
        for name, sigmas in channels.items():
            unit = "um" if name.endswith("_um") else "C"
            cells = "  ".join(f"{k} {v:.4f}" for k, v in sigmas.items())
            print(f"  {name:12s} {unit:2s} {cells}")
    if args.json is not None:
        args.json.write_text(json.dumps(report, indent=1) + "\n", encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
