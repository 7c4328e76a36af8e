"""`twin replay`: recorded runs through the twin, with fields, metrics and a report."""

from __future__ import annotations

from pathlib import Path

import typer

from twin.cli.inputs import (
    WindowEnds,
    bundled_runs,
    bundled_runs_dir,
    checked_model,
    dask_address,
    expand_run_folders,
    method_list,
)
from twin.errors import InputError, raise_if_interrupted
from twin.io.destinations import check_out_dir
from twin.wording import counted


def replay(
    runs: list[Path] = typer.Argument(
        None, metavar="RUN", help="recorded runs (CSV/Parquet) or folders of them, e.g. a "
        "`twin synth --suite` folder; none: the bundled example runs"
    ),
    out: Path = typer.Option(..., "--out", metavar="DIR", help="output folder"),
    model: Path | None = typer.Option(None, "--model", metavar="MODEL",
                                      help="correction model (bpnn)"),
    methods: str = typer.Option(
        "open_loop,ratio,bpnn,estimator", "--methods", metavar="M[,M...]", callback=method_list,
        help="comma-separated: open_loop, ratio, bpnn, estimator",
    ),
    jobs: int = typer.Option(1, "--jobs", metavar="N", min=1, max=256,
                             help="local worker processes"),
    dask: str | None = typer.Option(
        None, "--dask", metavar="ADDRESS", callback=dask_address,
        help="address of a dask.distributed scheduler, e.g. tcp://127.0.0.1:8786"
    ),
    snapshots: WindowEnds = typer.Option(
        WindowEnds.END, "--snapshots", help="field pictures: none, at the end, every window"
    ),
    fields: WindowEnds = typer.Option(
        WindowEnds.EVERY, "--fields",
        help="field files (fields/*.vtu + fields.pvd): every window end, the last one only "
        "(end), or none; about 220 kB a window of the default spindle",
    ),
    resume: bool = typer.Option(
        False, "--resume", help="skip runs already finished (same input, methods, model, code, "
        "--fields); a skipped run gets the --snapshots it lacks, drawn from its field files"),
    quiet: bool = typer.Option(False, "--quiet", help="no progress output"),
    drift_assimilation: bool = typer.Option(
        True, "--drift-assimilation/--no-drift-assimilation",
        help="estimator: also update with the recorded axial drift where the run has it",
    ),
) -> None:
    """Replay recorded runs through the twin and write fields, metrics and a report."""
    from rich.console import Console

    from twin.loop.report import build_report, run_plotter
    if dask and jobs > 1:
        raise InputError("use either --jobs or --dask, not both", column="--dask")
    chosen = methods.split(",")
    paths = expand_run_folders(list(runs)) if runs else bundled_runs()
    if not paths:
        where = [str(p) for p in runs] if runs else [str(bundled_runs_dir())]
        raise InputError("no recorded runs (CSV/Parquet) found", file=", ".join(where))
    check_out_dir(out, inputs=[*paths, model], owned=[Path(p).stem for p in paths],
                  files=["summary.json", "report.html"])
    from twin.spindle.output import is_simulation_folder

    if is_simulation_folder(out):  # whose summary.json this one would replace
        raise InputError("is a twin simulate output folder, whose summary.json this would "
                         "replace: choose another --out", file=str(out), column="--out")
    model_path = checked_model(chosen, model)
    from twin.loop.runnames import named_runs

    named_runs(paths)  # a name clash refused before any progress row is drawn
    console = Console(stderr=True, quiet=quiet)
    console.print(f"replaying {counted(len(paths), 'run')} with {', '.join(chosen)} → {out}")
    if dask:  # an unreachable one takes 20 s to be told
        console.print(f"connecting to the dask scheduler at {dask} …")

    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn
    from rich.table import Column

    # the first run's figures are drawn by a child forked now, which loads matplotlib on
    # the idle core while this process imports the solver (a batch run by worker processes
    # or dask draws in those)
    in_this_process = not dask and (jobs <= 1 or len(paths) <= 1)
    # redrawn when a run finishes, not by rich's refresh thread: a process running no other
    # thread may fork (twin.loop.overlap)
    # the run names keep their width: a status is what gets cut (a failed run's row goes,
    # and its error is printed whole after the bar)
    names = Column(no_wrap=True, min_width=min(60, max(len(Path(p).stem) for p in paths)))
    with run_plotter(fork=in_this_process) as plotter, Progress(
        TextColumn("{task.description}", table_column=names),
        BarColumn(),
        TextColumn("{task.fields[status]}",
                   table_column=Column(no_wrap=True, overflow="ellipsis")),
        TimeElapsedColumn(),
        console=console,
        disable=quiet,
        auto_refresh=False,
    ) as progress:
        from twin.loop.batch import FAILED, replay_batch

        tasks = {Path(p).stem: progress.add_task(Path(p).stem, total=1, status="") for p in paths}

        def tell(name: str, status: str) -> None:
            if status.startswith(FAILED):
                # its error is printed whole after the batch, one line: its row, cut to
                # the width left and with a bar drawn as if done, went away too late
                _drop_row(name)
            else:
                progress.update(tasks[name], completed=1, status=status, refresh=True)
            raise_if_interrupted()  # a Ctrl-C a library swallowed stops the batch here

        def _drop_row(name: str) -> None:
            task = tasks.pop(name, None)
            if task is not None:
                progress.remove_task(task)
                progress.refresh()

        def tell_window(name: str, method: str, done: int, total: int) -> None:
            # a long run (a 24-h one replays for minutes) showed a bar standing at 0:00:00
            # until it was done: the bar is redrawn here, as no refresh thread may run
            if name not in tasks:
                return
            progress.update(tasks[name], completed=done / total,
                            status=f"{100 * done // total} % ({method})", refresh=True)

        try:
            raise_if_interrupted()  # the solver's imports may have swallowed one
            result = replay_batch(
                paths,
                out,
                chosen,
                model_path,
                jobs=jobs,
                dask_address=dask,
                snapshots=snapshots.value,
                fields=fields.value,
                resume=resume,
                progress=tell,
                assimilate_drift=drift_assimilation,
                plotter=plotter if in_this_process else None,
                on_window=None if quiet else tell_window,
            )
        except KeyboardInterrupt:
            # the run under way went with its folder (a failed rerun leaves no earlier
            # result standing): summary.json and report.html must not list that result.
            # No DIR yet (a Ctrl-C while the dask scheduler was reached): nothing to list,
            # and rebuilding would make DIR with an empty report
            if out.is_dir():
                build_report(out)
            raise
        for failure in result.failed:  # those refused before they started too
            _drop_row(failure["run"])
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
    runs = summary.get("runs", [])
    parts = []
    for m, v in summary.get("mean", {}).items():
        t = v.get("temperature_accuracy_pct")
        d = v.get("deformation_accuracy_pct")
        # a folder may hold runs replayed with other methods: a mean over fewer runs says so
        n = sum(m in r.get("methods", {}) for r in runs)
        over = "" if n == len(runs) else f" ({n} of {counted(len(runs), 'run')})"
        parts.append(f"{m}{over}: T {t:.2f} %"
                     + (f", deformation {d:.2f} %" if d is not None else ""))
    return "mean accuracy — " + "; ".join(parts)
