"""`twin model-info`: check a correction model file and say what it was trained on."""

from __future__ import annotations

from pathlib import Path

import typer


def model_info(model: Path = typer.Argument(..., help="Correction model file.")) -> None:
    """Check a correction model file and print what it was trained on and how well."""
    from twin.correction.modelfile import load_model

    m = load_model(model)
    meta = m.metadata
    typer.echo(f"{model}: {meta.get('config')} configuration, {meta.get('samples')} samples, "
               f"{len(meta.get('training_runs', []))} runs, seed {meta.get('seed')}, "
               f"targets {meta.get('targets', 'ratio')}")
    for output, r2 in (meta.get("r2") or {}).items():
        typer.echo(f"  {output:18s} R² {r2.get('value')}  factor R² {r2.get('factor')}")
