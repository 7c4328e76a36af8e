"""`twin report`: rebuild a replay folder's report.html and summary.json."""

from __future__ import annotations

import json
from pathlib import Path

import typer

from twin.errors import EXIT_INPUT_ERROR, InputError


def report(out: Path = typer.Argument(..., metavar="DIR", help="a replay output folder")) -> None:
    """Rebuild DIR/report.html and DIR/summary.json from a replay folder."""
    from twin.io.destinations import check_out_dir
    from twin.loop.report import build_report
    from twin.loop.summary import is_replay_folder

    if not out.exists():
        raise InputError("no such folder", file=str(out))
    if not out.is_dir():
        raise InputError("is a file; a replay folder (twin replay --out DIR) is expected",
                         file=str(out))
    if not is_replay_folder(out):
        if (out / "accuracy.json").is_file():  # DIR/<run>/ given for DIR
            raise InputError("is one run's folder of a replay (it holds accuracy.json): give "
                             f"the replay's folder, {out.parent}", file=str(out))
        raise InputError("not a replay folder (no <run>/accuracy.json inside)", file=str(out))
    # the folder is the command's argument, no option: the writer's checks named '--out'
    check_out_dir(out, option=None, files=["summary.json", "report.html"])
    path = build_report(out)
    typer.echo(f"wrote {path}")
    # runs the report leaves out (an unreadable accuracy.json, a run that failed in the
    # replay): named as `twin replay` names them, and exit 2 as it does
    failed = json.loads((out / "summary.json").read_text(encoding="utf-8"))["failed"]
    for failure in failed:
        typer.echo(f"error: {failure['error']}", err=True)
    if failed:
        raise typer.Exit(EXIT_INPUT_ERROR)
