"""What every model file of the twin is: safetensors tensors and one JSON metadata entry.

Two kinds share the form and the `.safetensors` suffix: the correction model (`twin
train`, `twin.correction.modelfile`) and the drift model (`twin drift fit`,
`twin.drift.modelfile`).  `read_model_file` reads either up to its JSON document and
checks what they have in common (a readable file, the kind's metadata entry, its format
and version), so a file refused by both loaders is refused in the same words, and a model
of the other kind is named as such.  Nothing is unpickled or executed.
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass

import numpy as np

from twin.errors import InputError
from twin.paths import MAX_INPUT_BYTES, read_input_bytes


@dataclass(frozen=True)
class ModelKind:
    """A kind of model file: its metadata key, format and version, and for a user given
    it where the other kind belongs, what writes it and what reads it."""

    name: str  # "correction"
    key: str  # the safetensors metadata entry holding the JSON
    format: str
    version: int
    written_by: str  # "twin train"
    read_by: str  # "'twin replay --model' or 'twin model-info'"


CORRECTION = ModelKind("correction", "spindle_twin", "spindle-twin-correction", 1,
                       "twin train", "'twin replay --model' or 'twin model-info'")
DRIFT = ModelKind("drift", "spindle_twin_drift", "spindle-twin-drift", 1,
                  "twin drift fit", "'twin drift predict' or 'twin drift report'")
KINDS = (CORRECTION, DRIFT)


def read_model_file(path: str | os.PathLike[str], kind: ModelKind, *,
                    option: str | None = None,
                    max_bytes: int = MAX_INPUT_BYTES) -> tuple[dict[str, np.ndarray], dict]:
    """The tensors and the JSON document of a model file of `kind`, its format and
    version checked; anything else is an InputError naming the file (and `option`, the
    command-line option that gave it, where the file cannot be read)."""
    from safetensors import SafetensorError
    from safetensors.numpy import load

    file = str(path)
    raw = read_input_bytes(path, column=option, max_bytes=max_bytes)
    try:
        tensors = load(raw)
        header = json.loads(raw[8 : 8 + int.from_bytes(raw[:8], "little")])
    except (SafetensorError, ValueError, UnicodeDecodeError, RecursionError) as exc:
        raise InputError(f"not a readable safetensors model file ({exc})", file=file) from None
    metadata = header.get("__metadata__") if isinstance(header, dict) else None
    metadata = metadata if isinstance(metadata, dict) else {}
    try:
        doc = json.loads(metadata[kind.key])
    except (KeyError, TypeError, ValueError, RecursionError):
        other = next((k for k in KINDS if k is not kind and k.key in metadata), None)
        if other is not None:
            raise InputError(f"is a {other.name} model ({other.written_by}), not a "
                             f"{kind.name} model: use it with {other.read_by}",
                             file=file) from None
        raise InputError(f"no '{kind.key}' metadata: not a spindle-twin {kind.name} model",
                         file=file) from None
    if not isinstance(doc, dict) or doc.get("format") != kind.format:
        raise InputError(f"metadata format is not {kind.format!r}", file=file)
    if doc.get("version") != kind.version:
        raise InputError(f"model version {doc.get('version')!r} is not supported "
                         f"(expected {kind.version})", file=file)
    return tensors, doc
