"""`twin replay`, `twin snapshot`, `twin report`: what users run."""

from __future__ import annotations

from pathlib import Path

import typer

from twin.cli import command
from twin.errors import InputError

EXAMPLES_DIR = Path(__file__).resolve().parent.parent / "examples"
METHOD_NAMES = ("open_loop", "ratio", "bpnn")


def bundled_runs() -> list[Path]:
    runs = sorted((EXAMPLES_DIR / "runs").glob("*.csv"))
    return [r for r in runs if not r.name.endswith(".truth.csv")]


def bundled_model() -> Path | None:
    for candidate in sorted(EXAMPLES_DIR.glob("*.safetensors")):
        return candidate
    return None


def _methods(text: str) -> list[str]:
    methods = [m.strip() for m in text.split(",") if m.strip()]
    bad = [m for m in methods if m not in METHOD_NAMES]
    if bad or not methods:
        raise InputError(
            f"unknown method {bad[0] if bad else text!r}; choose from {', '.join(METHOD_NAMES)}",
            column="--methods",
        )
    return list(dict.fromkeys(methods))


def _model_for(methods: list[str], model: Path | None) -> str | None:
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

    load_model(model)  # a bad model is bad input for every run: fail before the batch
    return str(model)


@command("replay")
def replay(
    runs: list[Path] = typer.Argument(
        None, help="recorded runs (CSV/Parquet); none: the bundled example runs"
    ),
    out: Path = typer.Option(..., "--out", help="output folder"),
    model: Path | None = typer.Option(None, "--model", help="correction model (bpnn)"),
    methods: str = typer.Option(
        "open_loop,ratio,bpnn", "--methods", help="comma-separated: open_loop, ratio, bpnn"
    ),
    jobs: int = typer.Option(1, "--jobs", min=1, help="local worker processes"),
    dask: str | None = typer.Option(
        None, "--dask", help="address of a dask.distributed scheduler, e.g. tcp://127.0.0.1:8786"
    ),
    snapshots: str = typer.Option("end", "--snapshots", help="none | end | every"),
    resume: bool = typer.Option(False, "--resume", help="skip runs already finished"),
    quiet: bool = typer.Option(False, "--quiet", help="no progress output"),
) -> None:
    """Replay recorded runs through the twin and write fields, metrics and a report."""
    from rich.console import Console

    from twin.loop.batch import replay_batch
    from twin.loop.report import build_report
    from twin.loop.runfiles import SNAPSHOT_CHOICES

    if snapshots not in SNAPSHOT_CHOICES:
        raise InputError(
            f"must be one of {', '.join(SNAPSHOT_CHOICES)}, got {snapshots!r}", column="--snapshots"
        )
    if dask and jobs > 1:
        raise InputError("use either --jobs or --dask, not both", column="--dask")
    method_list = _methods(methods)
    paths = list(runs) if runs else bundled_runs()
    if not paths:
        raise InputError(
            "no runs given and no bundled example runs found", file=str(EXAMPLES_DIR / "runs")
        )
    model_path = _model_for(method_list, model)
    console = Console(stderr=True, quiet=quiet)
    console.print(f"replaying {len(paths)} run(s) with {', '.join(method_list)} → {out}")

    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

    with Progress(
        TextColumn("{task.description}"),
        BarColumn(),
        TextColumn("{task.fields[status]}"),
        TimeElapsedColumn(),
        console=console,
        disable=quiet,
    ) as progress:
        tasks = {Path(p).stem: progress.add_task(Path(p).stem, total=1, status="") for p in paths}

        def tell(name: str, status: str) -> None:
            progress.update(tasks[name], completed=1, status=status[:80])

        result = replay_batch(
            paths,
            out,
            method_list,
            model_path,
            jobs=jobs,
            dask_address=dask,
            snapshots=snapshots,
            resume=resume,
            progress=tell,
        )
    build_report(out, rebuild_summary=False)
    for failure in result.failed:
        typer.echo(f"error: {failure['error']}", err=True)
    if not quiet and result.accuracies:
        console.print(_mean_line(out))
        console.print(f"report: {Path(out) / 'report.html'}")
    if result.exit_code:
        raise typer.Exit(result.exit_code)


def _mean_line(out: Path) -> str:
    import json

    summary = json.loads((Path(out) / "summary.json").read_text())
    parts = []
    for m, v in summary.get("mean", {}).items():
        t = v.get("temperature_accuracy_pct")
        d = v.get("deformation_accuracy_pct")
        parts.append(f"{m}: T {t:.2f} %" + (f", deformation {d:.2f} %" if d is not None else ""))
    return "mean accuracy — " + "; ".join(parts)


@command("snapshot")
def snapshot(
    run: Path = typer.Argument(..., help="recorded run (CSV/Parquet)"),
    time_s: float = typer.Option(..., "--time", help="run time of the picture, s"),
    out: Path = typer.Option(..., "--out", help="PNG file"),
    field: str = typer.Option("temperature", "--field", help="temperature | displacement"),
    method: str = typer.Option("bpnn", "--method", help="open_loop | ratio | bpnn"),
    model: Path | None = typer.Option(None, "--model", help="correction model (bpnn)"),
    section: bool = typer.Option(False, "--section", help="flat r–z section, not 3-D"),
) -> None:
    """Headless picture of the twin's field at a time of a recorded run."""
    from twin.correction.methods import make_corrector
    from twin.loop.replay import replay_method
    from twin.loop.runfiles import default_spindle
    from twin.loop.snapshot import FIELDS, render_snapshot
    from twin.runs import read_run

    if field not in FIELDS:
        raise InputError(f"must be one of {', '.join(FIELDS)}, got {field!r}", column="--field")
    (method_name,) = _methods(method)
    model_path = _model_for([method_name], model)
    if out.suffix.lower() != ".png":
        raise InputError("the picture must be a .png file", file=str(out), column="--out")
    recorded = read_run(run)
    spindle = default_spindle()
    try:
        r = replay_method(
            recorded,
            spindle,
            make_corrector(method_name, model_path),
            keep_fields=False,
            field_at_s=time_s,
        )
    except ValueError as exc:
        raise InputError(str(exc), file=str(run), column="--time") from None
    ((t, T),) = r.fields.items()
    render_snapshot(
        spindle,
        T,
        out,
        field=field,
        section=section,
        T_initial_C=r.T_initial_C,
        title=f"{recorded.name} · {method_name} · t = {t:.0f} s",
    )
    typer.echo(f"wrote {out}")


@command("report")
def report(out: Path = typer.Argument(..., help="a replay output folder")) -> None:
    """Rebuild DIR/report.html and DIR/summary.json from a replay folder."""
    from twin.loop.report import build_report

    if not out.is_dir() or not any(out.glob("*/accuracy.json")):
        raise InputError("not a replay folder (no <run>/accuracy.json inside)", file=str(out))
    path = build_report(out)
    typer.echo(f"wrote {path}")
