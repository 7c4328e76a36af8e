"""`twin model-info`: check a correction model file and say what it was trained on."""

from __future__ import annotations

from pathlib import Path

import typer


def model_info(model: Path = typer.Argument(..., metavar="MODEL",
                                                 help="Correction model file.")) -> None:
    """Check a correction model file and print what it was trained on and how well."""
    from twin.cli.train import gated_runs
    from twin.correction.modelfile import load_model
    from twin.wording import counted

    m = load_model(model, option=None)  # an argument, not --model
    meta = m.metadata
    samples = meta.get("samples")
    told = counted(samples, "sample") if isinstance(samples, int) else f"{samples} samples"
    typer.echo(f"{model}: {meta.get('config')} configuration, {told}, "
               f"{counted(len(meta.get('training_runs', [])), 'run')}, seed {meta.get('seed')}, "
               f"targets {meta.get('targets', 'ratio')}")
    for output, r2 in (meta.get("r2") or {}).items():
        typer.echo(f"  {output:18s} R² {_r2(r2.get('value'))}  factor R² {_r2(r2.get('factor'))}")
    if "networks_kept" in meta:
        # the R² above are the networks'; a network the gate left out is zeroed and bpnn
        # gives the anchor (the ratio law) in its place, whatever its R²
        kept = ", ".join(meta["networks_kept"]) or "none (bpnn gives the anchor)"
        scores = meta.get("held_out_temperature_accuracy_pct") or {}
        typer.echo(f"networks kept by the closed-loop gate: {kept}"
                   + (f"; temperature accuracy on {gated_runs(meta)}: " if scores else "")
                   + ", ".join(f"{group} {pct:.2f} %" for group, pct in scores.items()))


def _r2(value: float | None) -> str:
    return "—" if value is None else f"{value:.2f}"
