"""The correction model file: the four networks in one safetensors file.

Tensors `<output>.<part>` (output in OUTPUTS; part in PARTS) in float64, and in the
safetensors header one metadata entry `spindle_twin` holding JSON: format and version,
the configuration, input names and units, hidden sizes, training runs, R², seed, and a
SHA-256 of the tensor data.  Loading reads only tensors and JSON (no unpickling), checks
every name, shape, value, the metadata's types and the checksum, and raises `InputError`
naming the file and what is wrong.

The checksum detects corruption, not forgery: it is a plain SHA-256 of the tensors
stored in the same file, so whoever edits the weights can recompute it and the file
loads.  A model file is trusted like code you install; keep it where only you write.
Loading never unpickles or executes anything, so a forged file can give wrong
corrections but cannot run foreign code.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike
from pydantic import BaseModel, ConfigDict, ValidationError

from twin.correction.features import (
    ANCHORED_INPUT_NAMES,
    HIDDEN_SIZES,
    INPUT_NAMES,
    OUTPUTS,
    TARGET_UNITS,
    kind_of,
)
from twin.correction.network import CONFIGS, NetConfig, TrainedNet
from twin.errors import InputError, MetadataError
from twin.io.atomic import write_bytes
from twin.modelfile import CORRECTION, read_model_file

FORMAT = CORRECTION.format
VERSION = CORRECTION.version
METADATA_KEY = CORRECTION.key
PARTS = ("hidden_weight", "hidden_bias", "output_weight", "output_bias",
         "x_offset", "x_scale", "y_offset", "y_scale")


@dataclass(frozen=True)
class CorrectionModel:
    """The four trained networks and what is known about their training."""

    nets: dict[str, TrainedNet]
    metadata: dict[str, Any] = field(default_factory=dict)

    def predict(self, output: str, x: ArrayLike, anchor: ArrayLike | None = None) -> np.ndarray:
        """Corrected values of `output` (e.g. 'heat_front') for input rows x (N, 6); an
        anchored model needs the anchor values (N,) it corrects."""
        return self.nets[output].predict(x, anchor)

    @property
    def config_name(self) -> str:
        return self.nets[OUTPUTS[0]].config.name

    @property
    def anchored(self) -> bool:
        """True if the networks correct the ratio-law value (the anchored configuration)."""
        return self.nets[OUTPUTS[0]].config.anchored


class _Metadata(BaseModel):
    """Types of the metadata fields the twin reads (others are kept as they are)."""

    model_config = ConfigDict(extra="allow", strict=True)
    version: int
    config: str
    outputs: list[str]
    hidden_sizes: dict[str, int]
    inputs: dict[str, list[str]] = {}
    r2: dict[str, dict[str, float | None]] | None = None
    training_runs: list[str] = []
    runs: list[str] = []
    samples: int | None = None
    seed: int | None = None
    targets: str | None = None
    sha256: str


def input_names(config: NetConfig) -> dict[str, tuple[str, ...]]:
    """The six input names per network kind of a configuration."""
    return ANCHORED_INPUT_NAMES if config.anchored else INPUT_NAMES


def _expected_shape(part: str, hidden: int) -> tuple[int, ...]:
    return {
        "hidden_weight": (hidden, 6), "hidden_bias": (hidden,), "output_weight": (1, hidden),
        "output_bias": (1,), "x_offset": (6,), "x_scale": (6,), "y_offset": (1,),
        "y_scale": (1,),
    }[part]


def _digest(tensors: dict[str, np.ndarray]) -> str:
    h = hashlib.sha256()
    for name in sorted(tensors):
        h.update(name.encode())
        h.update(np.ascontiguousarray(tensors[name], dtype="<f8").tobytes())
    return h.hexdigest()


def save_model(model: CorrectionModel, path: str | Path) -> Path:
    """Write the model atomically (temporary file in the same folder, then rename)."""
    from safetensors.numpy import save

    path = Path(path)
    tensors = {
        f"{output}.{part}": np.ascontiguousarray(getattr(model.nets[output], part), dtype="<f8")
        for output in OUTPUTS
        for part in PARTS
    }
    config = model.nets[OUTPUTS[0]].config
    meta = dict(model.metadata)
    meta.update(
        format=FORMAT,
        version=VERSION,
        config=config.name,
        outputs=list(OUTPUTS),
        hidden_sizes={o: model.nets[o].hidden_size for o in OUTPUTS},
        inputs={o: list(input_names(config)[kind_of(o)]) for o in OUTPUTS},
        units={o: TARGET_UNITS[kind_of(o)] for o in OUTPUTS},
        sha256=_digest(tensors),
    )
    data = save(tensors, metadata={METADATA_KEY: json.dumps(meta, sort_keys=True)})
    write_bytes(path, data)
    return path


def load_model(path: str | Path, option: str | None = "--model") -> CorrectionModel:
    """Read and check a model file; any problem raises InputError naming the file (and
    `option`, the command-line option that gave it, if any)."""
    path = Path(path)
    tensors, meta = read_model_file(path, CORRECTION, option=option, max_bytes=64 * 2**20)
    try:
        _Metadata.model_validate(meta)
    except ValidationError as exc:
        raise MetadataError.from_validation(exc, str(path)) from None
    config = CONFIGS.get(meta.get("config"))
    if config is None:
        raise InputError(f"unknown network configuration {meta.get('config')!r} (expected "
                         f"one of {', '.join(CONFIGS)}; retrain with `twin train`)",
                         file=str(path))
    if meta.get("outputs") != list(OUTPUTS):
        raise InputError(f"outputs must be {list(OUTPUTS)}", file=str(path))
    for output in OUTPUTS:
        # a model trained on other inputs (an earlier release) would be fed rows it never
        # saw, in the same six columns: refuse it rather than predict nonsense
        want = list(input_names(config)[kind_of(output)])
        if meta.get("inputs", {}).get(output, want) != want:  # absent: not checked
            raise InputError(f"{output}: inputs {meta['inputs'][output]} are not this "
                             f"version's {want}; retrain with `twin train`", file=str(path))

    expected = {f"{o}.{p}" for o in OUTPUTS for p in PARTS}
    missing, extra = sorted(expected - set(tensors)), sorted(set(tensors) - expected)
    if missing or extra:
        what = "; ".join(
            s for s in (f"missing tensors {missing}" if missing else "",
                        f"unexpected tensors {extra}" if extra else "") if s
        )
        raise InputError(what, file=str(path))
    nets = {}
    for output in OUTPUTS:
        hidden = meta.get("hidden_sizes", {}).get(output)
        if hidden != HIDDEN_SIZES[kind_of(output)]:
            raise InputError(
                f"{output}: hidden size {hidden!r}, expected {HIDDEN_SIZES[kind_of(output)]}",
                file=str(path),
            )
        parts = {}
        for part in PARTS:
            name = f"{output}.{part}"
            array = tensors[name]
            want = _expected_shape(part, hidden)
            if array.shape != want:
                raise InputError(
                    f"tensor {name!r} has shape {list(array.shape)}, expected {list(want)}",
                    file=str(path),
                )
            if array.dtype != np.float64:
                raise InputError(f"tensor {name!r} is {array.dtype}, expected float64",
                                 file=str(path))
            if not np.all(np.isfinite(array)):
                raise InputError(f"tensor {name!r} holds non-finite values", file=str(path))
            if part in ("x_scale", "y_scale") and np.any(array == 0):
                raise InputError(f"tensor {name!r} holds a zero scale", file=str(path))
            parts[part] = array
        nets[output] = TrainedNet(config, **parts)
    if meta.get("sha256") != _digest(tensors):
        raise InputError("checksum mismatch: the weights were modified or damaged",
                         file=str(path))
    return CorrectionModel(nets, meta)
