"""`make model`: regenerate the bundled correction model, deterministically.

Domain randomisation (issue 13): the networks train on `RUNS` emulated runs of `MINUTES`
min drawn from the test-bench suite distribution (`twin.plant.suite`, the sampler behind
`twin synth --suite`): speed profiles with steps, stops in every third run, drifting
ambient and coolant, bearing heat 0.6–1.6 and contact resistance 0.5–2 of nominal,
model-form error (motor loss, film groups, materials, thermocouple placement), sensor lag,
noise and faults.  The suite seed `SUITE_SEED` is none of the evaluation suites' (1, 2024,
555: README's accuracy tables): no model is measured on the runs it learnt from.
`twin train` then trains the networks with seed 0 (the default anchored configuration:
log-correction on the ratio-law value) and writes examples/correction_model.safetensors
plus its training report beside it.

The runs go to out/training_runs/ (regenerated, not committed).  Same code, same seeds →
the same model file (torch runs deterministic and single-threaded while training); its
SHA-256 is recorded in tests/test_examples.py (`BUNDLED_MODEL_SHA256`).
"""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
RUNS_DIR = ROOT / "out" / "training_runs"
MODEL = ROOT / "examples" / "correction_model.safetensors"

SUITE_SEED = 31
"""Training suite; 1, 2024 and 555 are evaluation suites and are never trained on."""
EVALUATION_SEEDS = (1, 2024, 555)
RUNS = 16
MINUTES = 30
SEED = 0


def twin(*args: str) -> None:
    subprocess.run([sys.executable, "-m", "twin", *args], check=True, cwd=ROOT)


def main() -> None:
    assert SUITE_SEED not in EVALUATION_SEEDS
    shutil.rmtree(RUNS_DIR, ignore_errors=True)  # a stale run must not join the training set
    twin("synth", "--suite", str(RUNS), "--seed", str(SUITE_SEED), "--minutes", str(MINUTES),
         "--out", str(RUNS_DIR), "--quiet")
    runs = sorted(str(p) for p in RUNS_DIR.glob("*.csv")
                  if not p.name.endswith((".truth.csv", ".profile.csv")))
    assert len(runs) == RUNS, runs
    twin("train", *runs, "--out", str(MODEL), "--seed", str(SEED))


if __name__ == "__main__":
    main()
