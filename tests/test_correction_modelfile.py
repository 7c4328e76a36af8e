"""The model file: round trip, and clear errors for damaged or wrong files (exit 2)."""

import json
import struct

import numpy as np
import pytest
from typer.testing import CliRunner

from twin.correction.features import HIDDEN_SIZES, OUTPUTS, kind_of
from twin.correction.modelfile import CorrectionModel, load_model, save_model
from twin.correction.network import DEFAULT, PAPER, TrainedNet
from twin.errors import InputError


def _model(config=DEFAULT, seed=0):
    rng = np.random.default_rng(seed)
    nets = {}
    for output in OUTPUTS:
        h = HIDDEN_SIZES[kind_of(output)]
        nets[output] = TrainedNet(
            config, rng.normal(size=(h, 6)), rng.normal(size=h), rng.normal(size=(1, h)),
            rng.normal(size=1), rng.normal(size=6), rng.uniform(1, 2, 6), rng.normal(size=1),
            rng.uniform(1, 2, 1))
    return CorrectionModel(nets, {"training_runs": ["a", "b"], "seed": seed})


@pytest.mark.parametrize("config", [DEFAULT, PAPER])
def test_round_trip(tmp_path, config):
    model = _model(config)
    path = save_model(model, tmp_path / "m.safetensors")
    back = load_model(path)
    assert back.config_name == config.name
    assert back.metadata["training_runs"] == ["a", "b"]
    x = np.random.default_rng(1).uniform(0.5, 2, size=(7, 6)) * [9000, 25, 30, 30, 600, 1e6]
    for output in OUTPUTS:
        for part in ("hidden_weight", "output_bias", "x_scale"):
            assert np.array_equal(getattr(back.nets[output], part),
                                  getattr(model.nets[output], part))
        anchor = x[:, 5] if config.anchored else None
        assert np.array_equal(back.predict(output, x, anchor), model.predict(output, x, anchor))
    # the file names the inputs of its configuration
    names = back.metadata["inputs"]["heat_front"]
    assert ("drop_level_error_per_drop" in names) == config.anchored
    assert ("nominal_heat_W_m3" in names) == (not config.anchored)
    assert not list(tmp_path.glob(".*.tmp"))  # atomic write left nothing behind


def _header(raw):
    n = struct.unpack("<Q", raw[:8])[0]
    return n, json.loads(raw[8:8 + n])


def _with_header(raw, header):
    n = _header(raw)[0]
    text = json.dumps(header).encode()
    text += b" " * (n - len(text)) if len(text) <= n else b""
    return struct.pack("<Q", len(text)) + text + raw[8 + n:]


def test_flipped_weight_byte_is_caught(tmp_path):
    path = save_model(_model(), tmp_path / "m.safetensors")
    raw = bytearray(path.read_bytes())
    raw[-3] ^= 0x01
    path.write_bytes(bytes(raw))
    with pytest.raises(InputError, match="checksum") as err:
        load_model(path)
    assert str(path) in str(err.value)


def test_truncated_file(tmp_path):
    path = save_model(_model(), tmp_path / "m.safetensors")
    path.write_bytes(path.read_bytes()[:100])
    with pytest.raises(InputError, match="not a readable safetensors") as err:
        load_model(path)
    assert err.value.file == str(path)


def test_wrong_shape_is_named(tmp_path):
    from safetensors.numpy import load, save

    path = save_model(_model(), tmp_path / "m.safetensors")
    raw = path.read_bytes()
    meta = _header(raw)[1]["__metadata__"]
    tensors = load(raw)
    tensors["heat_rear.hidden_weight"] = np.zeros((11, 6))
    path.write_bytes(save(tensors, metadata=meta))
    with pytest.raises(InputError, match=r"heat_rear.hidden_weight.*\[11, 6\].*\[10, 6\]"):
        load_model(path)


def test_wrong_hidden_size_missing_tensor_and_foreign_file(tmp_path):
    from safetensors.numpy import load, save

    path = save_model(_model(), tmp_path / "m.safetensors")
    raw = path.read_bytes()
    meta = json.loads(_header(raw)[1]["__metadata__"]["spindle_twin"])
    tensors = load(raw)
    meta["hidden_sizes"]["resistance_front"] = 10
    path.write_bytes(save(tensors, metadata={"spindle_twin": json.dumps(meta)}))
    with pytest.raises(InputError, match="resistance_front: hidden size 10, expected 12"):
        load_model(path)
    del tensors["heat_front.y_scale"]
    path.write_bytes(save(tensors, metadata={"spindle_twin": json.dumps(meta)}))
    with pytest.raises(InputError, match="missing tensors"):
        load_model(path)
    path.write_bytes(save({"w": np.zeros(3)}))
    with pytest.raises(InputError, match="not a spindle-twin correction model"):
        load_model(path)
    with pytest.raises(InputError, match="cannot read"):
        load_model(tmp_path / "absent.safetensors")


def test_cli_exit_2_on_a_damaged_model(tmp_path):
    from twin.cli import app

    path = save_model(_model(), tmp_path / "m.safetensors")
    ok = CliRunner().invoke(app, ["model-info", str(path)])
    assert ok.exit_code == 0, ok.output
    raw = bytearray(path.read_bytes())
    raw[-1] ^= 0xFF
    path.write_bytes(bytes(raw))
    bad = CliRunner().invoke(app, ["model-info", str(path)])
    assert bad.exit_code == 2
    assert "m.safetensors" in bad.output and "checksum" in bad.output
    assert "Traceback" not in bad.output
