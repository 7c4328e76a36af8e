"""`twin train`: train the correction networks on recorded runs."""

from __future__ import annotations

import dataclasses
import os
from pathlib import Path

import typer

from twin.cli.inputs import MAX_SEED, REPLACE_BUNDLED_MODEL
from twin.loop.target_rules import TargetRule
from twin.wording import counted

MAX_EPOCHS = 100_000
"""Most Rprop epochs `--epochs` takes, 20× the default."""


def train(
    runs: list[Path] = typer.Argument(..., metavar="RUN", help="Recorded runs (CSV or "
                                      "Parquet) to train on; a folder stands for the runs in "
                                      "it, as in replay."),
    out: Path = typer.Option(..., "--out", metavar="MODEL",
                             help="Model file to write (.safetensors)."),
    # bounded: a run alone has no validation split to stop early, so 1e20 ran for ever
    epochs: int = typer.Option(5000, "--epochs", metavar="N", min=1, max=MAX_EPOCHS,
                               help="Maximum Rprop epochs."),
    seed: int = typer.Option(0, "--seed", metavar="N", min=0, max=MAX_SEED,
                             help="Seed of the 80/20 split and the weights."),
    paper_config: bool = typer.Option(
        False, "--paper-config",
        help="Save the paper's configuration (the paper's six inputs, linear hidden, "
        "logistic output, logistic scaling of X/1e6) instead of the default (a log-correction "
        "on the ratio-law value: tanh hidden, standardised inputs, weight decay, early "
        "stopping on held-out runs).",
    ),
    targets: TargetRule = typer.Option(
        TargetRule.FIT, "--targets",
        help="Target rule: 'fit' (each window's values fitted to the measured window by the "
        "twin, with two passes driven off the fit) or 'ratio' (the paper's Eq. 2/5/6 on "
        "fitted curves of a ratio-corrected simulation).",
    ),
    gate_runs: list[Path] = typer.Option(
        None, "--gate-runs", metavar="RUN",
        help="A recorded run (or a folder of runs) that the closed-loop check of the "
        "default networks replays besides the held-out runs; never trained on (repeat the "
        "option for more).",
    ),
    replace_bundled: bool = typer.Option(
        False, REPLACE_BUNDLED_MODEL,
        help="Let --out be the bundled model (twin/data/correction_model.safetensors, "
        "which every replay without --model reads); refused without it. `make model` "
        "passes it.",
    ),
    quiet: bool = typer.Option(False, "--quiet", help="No progress output."),
) -> None:
    """Train the 6-10-1 heat and 6-12-1 contact-resistance networks of both bearings.

    Writes MODEL and, beside it, MODEL.report.json and MODEL.report.html
    (loss curves, R² of both configurations, predicted vs target).
    """
    from twin.cli.inputs import check_not_bundled_model, expand_run_folders
    from twin.correction.modelfile import save_model
    from twin.correction.network import DEFAULT, PAPER
    from twin.correction.report import report_paths, write_report
    from twin.correction.samples import SampleSet, samples_for
    from twin.correction.training import train_model
    from twin.correction.training_data import run_curves
    from twin.errors import InputError
    from twin.io.destinations import check_out_file
    from twin.loop.runnames import check_distinct_names, run_name
    from twin.loop.training import gate_networks, training_simulator
    from twin.runs import read_table, run_from_table
    from twin.runs.table import check_distinct_tables
    from twin.spindle.model import SpindleModel

    runs, gate_runs = expand_run_folders(runs), expand_run_folders(list(gate_runs or []))
    check_out_file(out, inputs=runs + gate_runs, also=report_paths(out),
                   suffixes=(".safetensors",))  # what replay --model and model-info read
    check_not_bundled_model(out, replace=replace_bundled)
    # realpath: resolve() raised RuntimeError on a symlink loop, an internal error
    trained = {os.path.realpath(path) for path in runs}
    for path in gate_runs:  # the gate measures the networks on runs they never saw
        if os.path.realpath(path) in trained:
            raise InputError("is also a training run; the gate replays runs never trained "
                             "on: leave it out of the RUN list or of --gate-runs",
                             file=str(path), column="--gate-runs")
    named = [(str(path), run_name(path)) for path in runs]
    check_distinct_names(named)
    tables = [read_table(path) for path in [*runs, *gate_runs]]
    check_distinct_tables(tables, "a copy would be trained on twice, or held out or "
                          "gated on as a run the networks never saw while trained on")
    spindle = SpindleModel.load()  # the networks train on that spindle
    limit = spindle.spec.spindle.max_speed_rpm
    simulator = training_simulator(targets, spindle=spindle)
    sets, recorded = [], {}
    for path, (_, name), table in zip(runs, named, tables[:len(runs)], strict=True):
        # known by its file name: the held-out split is by run
        run = run_from_table(table, max_speed_rpm=limit)
        run = dataclasses.replace(run, name=name)
        recorded[name] = run
        if not quiet:
            typer.echo(f"simulating {path.name} …", err=True)
        sets.extend(samples_for(curves) for curves in run_curves(run, simulator))
    samples = SampleSet.concatenate(sets)
    chosen = PAPER if paper_config else DEFAULT
    if chosen.anchored and samples.anchors is None:
        raise InputError("the default (anchored) networks learn from the window fit: use "
                         "--targets fit, or --paper-config with --targets ratio",
                         column="--targets")
    # file names only: the model file must not depend on where the runs were kept
    meta = {"runs": [p.name for p in runs], "simulation": getattr(simulator, "__name__", ""),
            "targets": targets.value}
    results = {}
    # the other configuration too, for the report's comparison, where the samples allow it
    for config in (c for c in (DEFAULT, PAPER) if samples.anchors is not None or not c.anchored):
        if not quiet:
            typer.echo(f"training ({config.name} configuration) on "
                       f"{counted(len(samples), 'sample')} …", err=True)
        results[config.name] = train_model(samples, config=config, epochs=epochs, seed=seed,
                                           metadata=meta)
    model = results[chosen.name].model
    if chosen.anchored:
        if not quiet:
            told = {**model.metadata, "gate_runs": [p.name for p in gate_runs]}
            typer.echo(f"checking the networks in closed loop on {gated_runs(told)} …",
                       err=True)
        held_out = [recorded[name] for name in model.metadata["held_out_runs"]]
        held_out += [run_from_table(table, max_speed_rpm=limit)
                     for table in tables[len(runs):]]
        model, gate = gate_networks(model, held_out, spindle)
        model.metadata.update(networks_kept=gate["kept"], held_out_temperature_accuracy_pct=(
            gate.get("held_out_temperature_accuracy_pct", {})),
            gate_runs=[p.name for p in gate_runs])
        if not quiet:
            typer.echo(f"networks kept: {', '.join(gate['kept']) or 'none (the anchor)'}",
                       err=True)
    for stale in report_paths(out):
        # they describe the model replaced now: a stop while the new ones are drawn (a
        # second or so) left them beside it, as its report
        stale.unlink(missing_ok=True)
    save_model(model, out)
    results[chosen.name] = dataclasses.replace(results[chosen.name], model=model)
    json_path, html_path = write_report(out, results, chosen.name)
    if not quiet:
        for output, row in results[chosen.name].r2_table().items():
            r2 = {k: "n/a" if row[k] is None else f"{row[k]:.4f}"
                  for k in ("r2_value", "r2_factor")}
            typer.echo(f"{output:18s} R² {r2['r2_value']} (factor {r2['r2_factor']})")
        typer.echo(f"wrote {out}, {json_path.name}, {html_path.name}")


def gated_runs(meta: dict) -> str:
    """The runs the closed-loop gate replayed, as `train` and `model-info` tell them: one
    training run is split by its windows, so the gate replays the run the networks were
    trained on (it was told as "the held-out runs")."""
    gate = " and the gate runs" if meta.get("gate_runs") else ""
    if len(meta.get("training_runs", [])) == 1:
        return f"the run they were trained on (a single run: none is held out){gate}"
    return f"the held-out runs{gate}"

