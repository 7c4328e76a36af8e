"""`twin report`: rebuild a replay folder's report.html and summary.json."""

from __future__ import annotations

from pathlib import Path

import typer

from twin.errors import InputError


def report(out: Path = typer.Argument(..., help="a replay output folder")) -> None:
    """Rebuild DIR/report.html and DIR/summary.json from a replay folder."""
    from twin.loop.report import build_report

    if not out.is_dir() or not any(out.glob("*/accuracy.json")):
        raise InputError("not a replay folder (no <run>/accuracy.json inside)", file=str(out))
    path = build_report(out)
    typer.echo(f"wrote {path}")
