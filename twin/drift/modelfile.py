"""The drift model file: parameters as safetensors tensors, everything else as JSON.

Tensors are float64 arrays named as the method stores them, plus the chosen method's
out-of-fold validation under `validation.*` (for the report); the safetensors header
holds one metadata entry `spindle_twin_drift` with JSON: format, version, method,
targets, feature spec, interval rule, metadata (ranking, validation), a SHA-256 of the
tensors and one of the rest of that JSON (the reference temperatures and interval
widths are numbers there too: a damaged digit moved every prediction or band silently;
files written before it load without that check).  Loading reads tensors and JSON only
(no unpickling) and checks them: the JSON's fields by their types (`twin.drift.modeldoc`,
what guards a file written before the JSON's checksum), the tensors against the method,
features and targets they must fit.  As for the correction model, the checksums detect
corruption, not forgery.
"""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path

import numpy as np
from pydantic import ValidationError

from twin.drift.data import array_digest
from twin.drift.features import FeatureSpec
from twin.drift.methods import METHODS
from twin.drift.model import DriftModel
from twin.drift.modeldoc import ModelDocument
from twin.errors import InputError, MetadataError
from twin.io.atomic import write_bytes
from twin.modelfile import DRIFT, read_model_file

FORMAT = DRIFT.format
VERSION = DRIFT.version
METADATA_KEY = DRIFT.key
VALIDATION = "validation."
"""Prefix of the tensors holding the out-of-fold validation (shown by `twin drift report`)."""


def _metadata_digest(doc: dict) -> str:
    """SHA-256 of the model's JSON without its checksums (keys sorted, as written)."""
    rest = {k: v for k, v in doc.items() if k not in ("sha256", "metadata_sha256")}
    return hashlib.sha256(json.dumps(rest, sort_keys=True, allow_nan=True).encode()).hexdigest()


def save_drift_model(model: DriftModel, path: str | os.PathLike[str]) -> Path:
    """Write the model atomically."""
    from safetensors.numpy import save

    tensors = {k: np.ascontiguousarray(v, dtype="<f8") for k, v in model.params.items()}
    tensors.update({f"{VALIDATION}{k}": np.ascontiguousarray(v, dtype="<f8")
                    for k, v in model.validation.items()})
    doc = {"format": FORMAT, "version": VERSION, "method": model.method,
           "targets": model.targets, "features": model.spec.to_json(),
           "interval": model.interval, "metadata": model.metadata, "sha256": array_digest(tensors)}
    doc["metadata_sha256"] = _metadata_digest(doc)
    data = save(tensors, metadata={METADATA_KEY: json.dumps(doc, sort_keys=True,
                                                             allow_nan=True)})
    return write_bytes(path, data)


def load_drift_model(path: str | os.PathLike[str]) -> DriftModel:
    """Read and check a drift model file; any problem raises InputError naming the file."""
    file = str(path)
    tensors, doc = read_model_file(path, DRIFT)
    if doc.get("method") not in METHODS:
        raise InputError(f"unknown method {doc.get('method')!r}", file=file)
    for name, array in tensors.items():
        if array.dtype != np.float64 or not np.all(np.isfinite(array)):
            raise InputError(f"tensor {name!r} is not finite float64", file=file)
    if doc.get("sha256") != array_digest(tensors):
        raise InputError("checksum mismatch: the weights were modified or damaged", file=file)
    if "metadata_sha256" in doc and doc["metadata_sha256"] != _metadata_digest(doc):
        raise InputError("checksum mismatch: the metadata (sensors, reference temperatures, "
                         "interval) were modified or damaged", file=file)
    try:
        checked = ModelDocument.model_validate(doc)
    except ValidationError as exc:
        raise MetadataError.from_validation(exc, file) from None
    except RecursionError:
        raise MetadataError("nested too deeply", file=file) from None
    problem = checked.per_target_problem()
    if problem is not None:
        raise MetadataError(problem[1], file=file, field=problem[0])
    spec = FeatureSpec.from_json(doc["features"])
    params = {k: v for k, v in tensors.items() if not k.startswith(VALIDATION)}
    _check_weights_fit(checked, spec, params, file)
    validation = {k[len(VALIDATION):]: v for k, v in tensors.items() if k.startswith(VALIDATION)}
    return DriftModel(checked.method, list(checked.targets), spec, params,
                      dict(doc["interval"]), dict(doc.get("metadata", {})), validation)


def _check_weights_fit(doc: ModelDocument, spec: FeatureSpec, params: dict[str, np.ndarray],
                       file: str) -> None:
    """MetadataError unless the weights are the method's and take the features' columns
    and give the targets (the tensors have their own checksum: the JSON is what is off)."""
    method = METHODS[doc.method]
    if spec.groups != method.groups:
        raise MetadataError(f"method {doc.method!r} takes the feature groups "
                            f"{', '.join(method.groups)}", file=file, field="features.groups")
    columns = len(spec.names)
    for name, array in params.items():
        if name.endswith("x_offset") and array.shape != (columns,):
            raise MetadataError(
                f"{len(spec.sensors)} sensors and {len(spec.taus_min)} lags make {columns} "
                f"feature columns; the weights take {array.shape[0] if array.ndim else 0}",
                file=file, field="features")
    rng = doc.interval.operating_range
    for key in ("features", "state_features"):
        named = [] if rng is None else getattr(rng, key) or []
        unknown = [f for f in named if f not in spec.names]
        if unknown:
            raise MetadataError(f"{unknown[0]!r} is none of the model's features",
                                file=file, field=f"interval.operating_range.{key}")
    try:
        mean, std = method.predict(params, np.zeros((2, columns)))
    except (KeyError, ValueError, IndexError):
        raise MetadataError(f"the weights are not those of method {doc.method!r}",
                            file=file, field="method") from None
    p = len(doc.targets)
    if mean.shape != (2, p) or (std is not None and std.shape != (2, p)):
        raise MetadataError(f"{p} targets; the weights predict {mean.shape[-1]}", file=file,
                            field="targets")
