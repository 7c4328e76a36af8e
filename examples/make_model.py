"""`make model`: regenerate the bundled correction model, deterministically.

The paper's 20 thermal tests: 20 emulated runs of 30 min at 20 speeds between 6000 and
13000 rpm (every speed of the paper's Table 2 among them), leaving out 7800 and 10800 rpm,
which are kept for validation as in the paper.  Each run is written by `twin synth` with a
fixed seed and ambient; `twin train` then trains the networks with seed 0 and writes
examples/correction_model.safetensors plus its training report beside it.

The runs go to out/training_runs/ (regenerated, not committed).  Same code, same seeds →
the same model file (torch runs deterministic and single-threaded while training).
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
RUNS_DIR = ROOT / "out" / "training_runs"
MODEL = ROOT / "examples" / "correction_model.safetensors"

SPEEDS_RPM = [6000, 6300, 6600, 6900, 7200, 7500, 8100, 8400, 8700, 9000,
              9300, 9600, 9900, 10200, 10500, 11100, 11400, 12000, 12600, 13000]
VALIDATION_RPM = (7800, 10800)
MINUTES = 30
SEED = 0


def training_plan(seed: int = SEED) -> list[tuple[int, float, int]]:
    """(speed rpm, ambient °C, synth seed) per training run; ambients like the paper's."""
    assert len(SPEEDS_RPM) == 20 and not set(SPEEDS_RPM) & set(VALIDATION_RPM)
    ambients = np.random.default_rng(seed).uniform(23.9, 25.5, len(SPEEDS_RPM))
    pairs = zip(SPEEDS_RPM, ambients, strict=True)
    return [(s, round(float(a), 2), 1000 + i) for i, (s, a) in enumerate(pairs)]


def twin(*args: str) -> None:
    subprocess.run([sys.executable, "-m", "twin", *args], check=True, cwd=ROOT)


def main() -> None:
    RUNS_DIR.mkdir(parents=True, exist_ok=True)
    runs = []
    for speed, ambient, seed in training_plan():
        path = RUNS_DIR / f"train_{speed}rpm_{MINUTES}min.csv"
        twin("synth", "--speed", str(speed), "--minutes", str(MINUTES), "--ambient",
             str(ambient), "--seed", str(seed), "--out", str(path), "--quiet")
        runs.append(str(path))
    twin("train", *runs, "--out", str(MODEL), "--seed", str(SEED))


if __name__ == "__main__":
    main()
