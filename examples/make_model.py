"""`make model`: regenerate the bundled correction model, deterministically.

Domain randomisation (issue 13): the networks train on `RUNS` emulated runs of `MINUTES`
min drawn from the test-bench suite distribution (`twin.plant.suite`, the sampler behind
`twin synth --suite`): speed profiles with steps, stops in every third run, drifting
ambient and coolant, bearing heat 0.6–1.6 and contact resistance 0.5–2 of nominal,
model-form error (motor loss, film groups, materials, thermocouple placement), sensor lag,
noise and faults.  The suite seed `SUITE_SEED` is none of the evaluation suites'
(`EVALUATION_SEEDS`, README's accuracy tables): no model is measured on the runs it learnt
from.
`twin train` then trains the networks with seed 0 (the default anchored configuration:
log-correction on the ratio-law value) and writes examples/correction_model.safetensors
plus its training report beside it.

The closed-loop check that decides which networks are kept (`twin.loop.training.
gate_networks`) replays the held-out runs and `GATE_RUNS` more runs of suite `GATE_SEED`,
which no network trains on (`twin train --gate-runs`): three held-out runs alone were too
few to decide on.

The runs go to out/training_runs/ and out/gate_runs/ (regenerated, not committed).  Same
code, same seeds → the same model file (torch runs deterministic and single-threaded while
training); its SHA-256 is recorded in tests/test_bundled_model.py (`BUNDLED_MODEL_SHA256`).
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
"""Training suite; the evaluation suites are never trained on."""
GATE_SEED = 32
"""Suite of the closed-loop check's extra runs (not trained on, not an evaluation suite)."""
EVALUATION_SEEDS = (1, 77, 555, 2024, 8080, 31337, 4242, 90210)
RUNS = 16
GATE_RUNS = 8
MINUTES = 30
SEED = 0
GATE_DIR = ROOT / "out" / "gate_runs"


def twin(*args: str) -> None:
    subprocess.run([sys.executable, "-m", "twin", *args], check=True, cwd=ROOT)


def suite(seed: int, n: int, folder: Path) -> list[str]:
    """The recorded runs of a freshly drawn suite in `folder` (emptied first: a stale run
    must not join the set)."""
    shutil.rmtree(folder, ignore_errors=True)
    twin("synth", "--suite", str(n), "--seed", str(seed), "--minutes", str(MINUTES),
         "--out", str(folder), "--quiet")
    runs = sorted(str(p) for p in folder.glob("*.csv")
                  if not p.name.endswith((".truth.csv", ".profile.csv")))
    assert len(runs) == n, runs
    return runs


def main() -> None:
    assert len({SUITE_SEED, GATE_SEED} | set(EVALUATION_SEEDS)) == 2 + len(EVALUATION_SEEDS)
    runs = suite(SUITE_SEED, RUNS, RUNS_DIR)
    gate = suite(GATE_SEED, GATE_RUNS, GATE_DIR)
    # the bundled model: train refuses to replace it without the option
    twin("train", *runs, "--out", str(MODEL), "--replace-bundled-model", "--seed", str(SEED),
         *[arg for path in gate for arg in ("--gate-runs", path)])


if __name__ == "__main__":
    main()
