"""`twin train`: train the correction networks on recorded runs."""

from __future__ import annotations

from pathlib import Path

import typer

from twin.loop.target_rules import TargetRule


def train(
    runs: list[Path] = typer.Argument(..., help="Recorded runs (CSV or Parquet) to train on."),
    out: Path = typer.Option(..., "--out", help="Model file to write (.safetensors)."),
    epochs: int = typer.Option(5000, "--epochs", min=1, help="Maximum Rprop epochs."),
    seed: int = typer.Option(0, "--seed", min=0, help="Seed of the 80/20 split and the weights."),
    paper_config: bool = typer.Option(
        False, "--paper-config",
        help="Save the paper's configuration (linear hidden, logistic output, logistic "
        "scaling of X/1e6) instead of the default (tanh hidden, standardised factors).",
    ),
    targets: TargetRule = typer.Option(
        TargetRule.FIT, "--targets",
        help="Target rule: 'fit' (each window's values fitted to the measured window by the "
        "twin, with two passes driven off the fit) or 'ratio' (the paper's Eq. 2/5/6 on "
        "fitted curves of a ratio-corrected simulation).",
    ),
    quiet: bool = typer.Option(False, "--quiet", help="No progress output."),
) -> None:
    """Train the 6-10-1 heat and 6-12-1 contact-resistance networks of both bearings.

    Writes MODEL and, beside it, MODEL.report.json and MODEL.report.html (loss curves, R²
    of both configurations, predicted vs target).
    """
    from twin.correction.modelfile import save_model
    from twin.correction.network import DEFAULT, PAPER
    from twin.correction.report import report_paths, write_report
    from twin.correction.samples import SampleSet, samples_for
    from twin.correction.training import train_model
    from twin.correction.training_data import run_curves
    from twin.io.destinations import check_out_file
    from twin.loop.training import training_simulator
    from twin.runs import read_run
    from twin.spindle.spec import load_spec

    check_out_file(out, inputs=runs, also=report_paths(out))
    simulator = training_simulator(targets)
    limit_rpm = load_spec(None).spindle.max_speed_rpm  # the networks train on that spindle
    sets = []
    for path in runs:
        run = read_run(path, max_speed_rpm=limit_rpm)
        if not quiet:
            typer.echo(f"simulating {path.name} …", err=True)
        sets.extend(samples_for(curves) for curves in run_curves(run, simulator))
    samples = SampleSet.concatenate(sets)
    chosen = PAPER if paper_config else DEFAULT
    # file names only: the model file must not depend on where the runs were kept
    meta = {"runs": [p.name for p in runs], "simulation": getattr(simulator, "__name__", ""),
            "targets": targets.value}
    results = {}
    for config in (DEFAULT, PAPER):
        if not quiet:
            typer.echo(f"training ({config.name} configuration) on {len(samples)} samples …",
                       err=True)
        results[config.name] = train_model(samples, config=config, epochs=epochs, seed=seed,
                                           metadata=meta)
    save_model(results[chosen.name].model, out)
    json_path, html_path = write_report(out, results, chosen.name)
    if not quiet:
        for output, row in results[chosen.name].r2_table().items():
            typer.echo(f"{output:18s} R² {row['r2_value']:.4f} (factor {row['r2_factor']:.3f})")
        typer.echo(f"wrote {out}, {json_path.name}, {html_path.name}")
