"""The bundled correction model is the one `make model` writes, trained on no evaluation suite.

`make model` (examples/make_model.py) is byte-reproducible: rerunning it rewrites
examples/correction_model.safetensors with this SHA-256.  Whoever regenerates the model
updates the checksum here (and the README's accuracy tables, measured on fresh suites).
"""

from __future__ import annotations

import hashlib
import importlib.util
from pathlib import Path

from twin.correction.modelfile import load_model

ROOT = Path(__file__).resolve().parent.parent
BUNDLED_MODEL = ROOT / "examples" / "correction_model.safetensors"
BUNDLED_MODEL_SHA256 = "4fba336e0640eabe6c4c2890b35c75abb734bff19d6a9aac1f35d6496fc7c8e3"


def _make_model():
    spec = importlib.util.spec_from_file_location("make_model", ROOT / "examples" / "make_model.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_bundled_model_is_the_recorded_make_model_output():
    assert hashlib.sha256(BUNDLED_MODEL.read_bytes()).hexdigest() == BUNDLED_MODEL_SHA256


def test_bundled_model_learnt_from_the_training_suite_only():
    plan = _make_model()
    model = load_model(BUNDLED_MODEL)
    assert model.anchored and model.config_name == "anchored"
    meta = model.metadata
    assert plan.SUITE_SEED not in plan.EVALUATION_SEEDS
    expected = [f"suite{plan.SUITE_SEED}_{i:03d}" for i in range(1, plan.RUNS + 1)]
    assert meta["training_runs"] == expected
    assert set(meta["held_out_runs"]) < set(expected)
    # the closed-loop check also replayed the gate suite, which no network learnt from
    assert plan.GATE_SEED not in (plan.SUITE_SEED, *plan.EVALUATION_SEEDS)
    assert meta["gate_runs"] == [f"suite{plan.GATE_SEED}_{i:03d}.csv"
                                 for i in range(1, plan.GATE_RUNS + 1)]
    # the paper's topology: 6-10-1 heat, 6-12-1 resistance
    assert meta["hidden_sizes"] == {"heat_front": 10, "heat_rear": 10,
                                    "resistance_front": 12, "resistance_rear": 12}
    # the networks kept are those that beat the anchor in closed loop on the held-out runs
    scores = meta["held_out_temperature_accuracy_pct"]
    kept = "+".join(meta["networks_kept"]) or "anchor"
    assert scores[kept] == max(scores.values())
    for output, net in model.nets.items():
        zeroed = not net.output_weight.any() and not net.output_bias.any()
        assert zeroed == (output.split("_")[0] not in meta["networks_kept"]), output
