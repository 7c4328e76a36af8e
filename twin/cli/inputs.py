"""Inputs several `twin` commands share: the bundled examples, the correction methods
and the correction model check.  Light on purpose: `twin --help` imports it."""

from __future__ import annotations

from pathlib import Path

from twin.data import bundled_path
from twin.errors import InputError

METHOD_NAMES = ("open_loop", "ratio", "bpnn", "estimator")


def bundled_runs_dir() -> Path:
    """Where the example recorded runs shipped with the twin are (package data)."""
    return bundled_path("runs").resolve()


def bundled_runs() -> list[Path]:
    """The example recorded runs shipped with the twin (their `.truth.csv` left out)."""
    runs = sorted(bundled_runs_dir().glob("*.csv"))
    return [r for r in runs if not r.name.endswith(".truth.csv")]


def bundled_model() -> Path | None:
    """The default correction model shipped with the twin, if any."""
    model = bundled_path("correction_model.safetensors").resolve()
    return model if model.is_file() else None


def parse_methods(text: str) -> list[str]:
    """`open_loop,ratio` → ["open_loop", "ratio"], each known and listed once."""
    methods = [m.strip() for m in text.split(",") if m.strip()]
    bad = [m for m in methods if m not in METHOD_NAMES]
    if bad or not methods:
        raise InputError(
            f"unknown method {bad[0] if bad else text!r}; choose from {', '.join(METHOD_NAMES)}",
            column="--methods",
        )
    return list(dict.fromkeys(methods))


def checked_model(methods: list[str], model: Path | None) -> str | None:
    """The model file the methods need (the bundled one by default), loaded once to check
    it: a bad model is bad input for every run, so it fails before any work starts."""
    if "bpnn" not in methods:
        return str(model) if model else None
    model = model or bundled_model()
    if model is None:
        raise InputError(
            "the bpnn method needs a correction model: pass --model FILE", column="--model"
        )
    if not Path(model).is_file():
        raise InputError("model file not found", file=str(model), column="--model")
    from twin.correction.modelfile import load_model

    load_model(model)
    return str(model)
