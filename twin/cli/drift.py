"""`twin drift fit | predict | report | select`: data-driven drift models (no FEM).

A typer sub-app; `twin/cli/__init__.py` adds it under the name `drift`.  Heavy imports
(torch, scikit-learn, matplotlib) stay inside the commands.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import typer

from twin.cli.inputs import MAX_SEED
from twin.errors import InputError, report_errors
from twin.helptext import PlainHelpCommand
from twin.io.destinations import check_out_dir, check_out_file

if TYPE_CHECKING:
    from twin.drift.data import DriftData

drift_app = typer.Typer(
    name="drift",
    help="Data-driven thermal-drift models fitted on measured temperatures (no FEM): "
    "fit, predict, report, select sensors.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    rich_markup_mode=None,  # click's plain help: readable at 80 columns (see twin.cli)
)


def _targets(text: str) -> list[str]:
    from twin.drift.data import DISPLACEMENT_SUFFIX

    names = list(dict.fromkeys(n.strip() for n in text.split(",") if n.strip()))
    if not names:
        raise InputError("name at least one displacement column", column="--target")
    for name in names:
        # any other column (a temperature) would also be read as a sensor: the model
        # would predict it from itself
        if not name.endswith(DISPLACEMENT_SUFFIX):
            raise InputError(f"{name!r} is not a displacement column (a name ending in "
                             f"{DISPLACEMENT_SUFFIX})", column="--target")
    return names


def _check_inputs(paths: Sequence[Path]) -> None:
    from twin.paths import check_input_file

    for path in paths:
        check_input_file(path)


def _progress(quiet: bool) -> Callable[[str], None]:
    start = time.perf_counter()

    def tell(message: str) -> None:
        if not quiet:
            typer.echo(f"[{time.perf_counter() - start:6.1f} s] {message}", err=True)

    return tell


def _report_findings(data: DriftData, quiet: bool) -> None:
    if quiet:
        return
    for file, dialect in data.dialects.items():
        typer.echo(f"note: {file}: read as {dialect}", err=True)
    for f in data.findings:
        typer.echo(f"note: {f['where']}: {f['repair']}", err=True)
    for name, why in data.left_out.items():
        typer.echo(f"note: temperature column {name!r} left out: {why}", err=True)
    # a speed logged as 'speed' or 'n_rpm' was dropped without a word, and fit chose among
    # the two methods that need no speed
    for file, names in data.not_read.items():
        typer.echo(f"note: {file}: column(s) {', '.join(map(repr, names))} not read (drift "
                   "data: time_s, speed_rpm, *_C temperatures, *_um displacements)", err=True)


def _tell_outside_range(outside: dict | None) -> None:
    """A note on the rows beyond the operating range the model was fitted on: a model
    extrapolates there, and its band is widened for it (`twin.drift.intervals`)."""
    if outside is None:
        return
    typer.echo(f"note: {outside['rows']} row{'s' * (outside['rows'] != 1)} "
               f"({outside['rows_pct']:.1f} %) outside the operating range the model was "
               f"fitted on (furthest: {outside['max_excess_spans']:.2f} of its span beyond, "
               f"in {outside['feature']}): the model extrapolates there; the 90 % interval "
               f"is widened for it, up to ×{outside['max_band_factor']:.2f}", err=True)


@drift_app.command("fit", cls=PlainHelpCommand)
@report_errors
def fit(
    data: list[Path] = typer.Argument(..., metavar="DATA", help="Data files (CSV or Parquet): "
                                      "time_s, optional speed_rpm, *_C temperatures, *_um "
                                      "drifts."),
    target: str = typer.Option(..., "--target", metavar="COL[,COL...]",
                               help="Displacement column(s) to model, "
                               "comma-separated (e.g. ch1_um,ch2_um)."),
    out: Path = typer.Option(..., "--out", metavar="MODEL",
                             help="Model file to write (.safetensors)."),
    method: str | None = typer.Option(
        None, "--method", metavar="M",
        help="Force a method: mlr, ridge_lagged, ridge_dynamic, bp, bayes, "
        "stack. Default: the best of all by time-blocked validation."),
    sensors: str = typer.Option(
        "auto", "--sensors", metavar="S",
        help="auto (best of every correlation cluster), K (best K of "
        "those; more than there are clusters is an error), all, or a comma-separated list "
        "of temperature columns."),
    seed: int = typer.Option(0, "--seed", metavar="N", min=0, max=MAX_SEED,
                             help="Seed of the network weights and k-means."),
    quiet: bool = typer.Option(False, "--quiet", help="No progress output."),
) -> None:
    """Fit a drift model; validation leaves one time block out at a time (never shuffled).

    A block is a file, or a quarter of the rows when one file is given; the
    sensors are picked again on the other blocks, and the interval is calibrated
    on them.
    """
    from twin.cli.inputs import check_not_bundled_model
    from twin.drift.data import read_drift_data
    from twin.drift.methods import method_named
    from twin.drift.model import fit_drift_model, listed_sensors
    from twin.drift.modelfile import save_drift_model

    check_out_file(out, inputs=data, suffixes=(".safetensors",))
    check_not_bundled_model(out)
    _check_inputs(data)
    if method is not None:
        method_named(method)
    targets = _targets(target)
    # a listed sensor is required in every file, another temperature column in none
    listed = listed_sensors(sensors)
    tell = _progress(quiet)
    tell(f"reading {len(data)} file(s)")
    drift_data = read_drift_data(data, sensors=listed, targets=targets)
    _report_findings(drift_data, quiet)
    model = fit_drift_model(drift_data, method=method, sensors=sensors, seed=seed,
                            progress=tell)
    save_drift_model(model, out)
    if not quiet:
        validation = model.metadata["validation"]["methods"]
        typer.echo(f"time-blocked validation ({model.metadata['validation']['blocks']} "
                   "blocks): RMSE µm per target, mean; coverage of the 90 % interval, "
                   "mean and worst block")
        for name, v in validation.items():
            per = " ".join(f"{v['rmse_um'][t]:6.2f}" for t in targets)
            cover = sum(v["coverage_90_pct"].values()) / len(targets)
            # the pooled share hid a block whose band missed most of it (27 % of ch2 on
            # the real step tests) behind blocks covered whole
            worst = min(min(c) for c in v["coverage_90_pct_per_block"].values())
            mark = "  <- chosen" if name == model.method else ""
            typer.echo(f"  {name:14s} {per}   mean {v['mean_rmse_um']:6.2f}   {cover:5.1f} %"
                       f"  worst {worst:5.1f} %{mark}")
        chosen = validation[model.method]
        outside = chosen.get("outside_range_pct_per_block", [])
        if any(outside):
            typer.echo("rows outside the operating range of the other blocks, per block: "
                       + " / ".join(f"{v:.0f} %" for v in outside) + " (their band is "
                       "widened with the distance; `predict` notes such rows)")
        typer.echo(f"sensors: {', '.join(model.spec.sensors)}")
        typer.echo(f"wrote {out}")


@drift_app.command("predict", cls=PlainHelpCommand)
@report_errors
def predict(
    model_file: Path = typer.Argument(..., metavar="MODEL", help="Drift model file."),
    data: Path = typer.Argument(..., metavar="DATA", help="Data file: time_s, speed_rpm (if "
                                "the model uses it) and the model's temperature columns."),
    out: Path = typer.Option(..., "--out", metavar="PRED.csv",
                             help="PRED.csv to write: time_s and per target "
                             "<target>, <target>_lo, <target>_hi (90 % interval)."),
    quiet: bool = typer.Option(False, "--quiet", help="No notes on stderr."),
) -> None:
    """Predict the drift, causally (a row's prediction uses rows up to it only)."""
    from twin.drift.data import read_drift_data
    from twin.drift.modelfile import load_drift_model
    from twin.drift.output import write_predictions

    check_out_file(out, inputs=[model_file, data], suffixes=(".csv",))
    _check_inputs([model_file, data])
    model = load_drift_model(model_file)
    drift_data = read_drift_data([data], sensors=model.spec.sensors, targets=model.targets,
                                 require_targets=False, require_speed=model.spec.uses_speed)
    _report_findings(drift_data, quiet)
    mean, lo, hi, excess, furthest = model.predict_data(drift_data)
    write_predictions(out, model, drift_data, mean, lo, hi)
    if not quiet:
        _tell_outside_range(model.outside_range(excess, furthest))
        rows = drift_data.n_samples
        typer.echo(f"wrote {out} ({rows} row{'s' * (rows != 1)})")


@drift_app.command("report", cls=PlainHelpCommand)
@report_errors
def report(
    model_file: Path = typer.Argument(..., metavar="MODEL", help="Drift model file."),
    data: list[Path] = typer.Argument(..., metavar="DATA",
                               help="Data files holding the model's targets."),
    out: Path = typer.Option(..., "--out", metavar="DIR",
                             help="Folder for metrics.json and report.html."),
    quiet: bool = typer.Option(False, "--quiet", help="No notes on stderr."),
) -> None:
    """Write metrics.json and a self-contained report.html (measured vs predicted)."""
    from twin.drift.data import read_drift_data
    from twin.drift.modelfile import load_drift_model
    from twin.drift.report import write_drift_report

    check_out_dir(out, inputs=[model_file, *data], files=["metrics.json", "report.html"])
    _check_inputs([model_file, *data])
    model = load_drift_model(model_file)
    drift_data = read_drift_data(data, sensors=model.spec.sensors, targets=model.targets,
                                 require_targets=True, require_speed=model.spec.uses_speed)
    _report_findings(drift_data, quiet)
    metrics, metrics_path, html_path = write_drift_report(out, model, drift_data,
                                                          model_file.name)
    if not quiet:
        for t, m in metrics["targets"].items():
            typer.echo(f"{t:12s} RMSE {m['rmse_um']:.2f} µm, 90 % interval coverage "
                       f"{m['coverage_90_pct']:.1f} %")
        _tell_outside_range(metrics["outside_range"])
        fitted = metrics["fitted_rows_pct"]
        if fitted:
            validation = model.metadata.get("validation", {})
            chosen = validation.get("methods", {}).get(validation.get("chosen"), {})
            unseen = (f" (time-blocked validation at fitting: {chosen['mean_rmse_um']:.2f} µm "
                      "mean RMSE on unseen blocks)" if "mean_rmse_um" in chosen else "")
            typer.echo(f"note: in-sample: {fitted:.0f} % of these rows are from data the "
                       f"model was fitted on, so these figures flatter it{unseen}")
        typer.echo(f"wrote {metrics_path} and {html_path}")


@drift_app.command("select", cls=PlainHelpCommand)
@report_errors
def select(
    data: list[Path] = typer.Argument(..., metavar="DATA", help="Data files (CSV or Parquet)."),
    target: str = typer.Option(..., "--target", metavar="COL[,COL...]",
                               help="Displacement column(s), comma-separated."),
    top: int | None = typer.Option(None, "--top", metavar="K", min=1, help="Show only the best K."),
    out: Path | None = typer.Option(None, "--out", metavar="FILE.json",
                                    help="Also write the ranking as JSON."),
) -> None:
    """Rank the temperature sensors: grey relational grade (ρ = 0.5), correlation clusters."""
    from twin.drift.data import read_drift_data
    from twin.drift.model import sensor_ranking
    from twin.io.atomic import write_json

    if out is not None:
        check_out_file(out, inputs=data, suffixes=(".json",))
    _check_inputs(data)
    drift_data = read_drift_data(data, targets=_targets(target))
    _report_findings(drift_data, quiet=False)
    ranking = sensor_ranking(drift_data)
    rows = ranking.to_json()["sensors"][: top or None]
    typer.echo(f"{'sensor':12s} {'grade':>6s} {'cluster':>7s}  kept")
    for r in rows:
        kept = "yes" if r["representative"] else "collinear"
        typer.echo(f"{r['sensor']:12s} {r['mean_grade']:6.3f} {r['cluster']:7d}  {kept}")
    if out is not None:
        write_json(out, {"targets": drift_data.targets, "sensors": rows})
        typer.echo(f"wrote {out}")
