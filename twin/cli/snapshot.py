"""`twin snapshot`: a headless picture of the twin's field at a time of a recorded run."""

from __future__ import annotations

from pathlib import Path

import typer

from twin.cli.inputs import Field, Method, checked_model
from twin.errors import InputError
from twin.io.destinations import check_out_file


def snapshot(
    run: Path = typer.Argument(..., metavar="RUN", help="recorded run (CSV/Parquet)"),
    time_s: float = typer.Option(..., "--time", metavar="S", min=0.0,
                                 help="run time of the picture, s"),
    out: Path = typer.Option(..., "--out", metavar="FILE.png", help="PNG file"),
    field: Field = typer.Option(Field.TEMPERATURE, "--field", help="the field shown"),
    method: Method = typer.Option(Method.BPNN, "--method", help="correction method"),
    model: Path | None = typer.Option(None, "--model", metavar="MODEL",
                                      help="correction model (bpnn)"),
    section: bool = typer.Option(False, "--section", help="flat r–z section, not 3-D"),
) -> None:
    """Headless picture of the twin's field at a time of a recorded run."""
    from twin.correction.methods import make_corrector
    from twin.loop.replay import check_field_time, replay_method
    from twin.loop.snapshot import render_snapshot, snapshot_title
    from twin.runs import read_run
    from twin.spindle.model import SpindleModel

    method_name = method.value
    check_out_file(out, inputs=[run, model], suffixes=(".png",))
    model_path = checked_model([method_name], model)
    spindle = SpindleModel.load()
    recorded = read_run(run, max_speed_rpm=spindle.spec.spindle.max_speed_rpm)
    try:
        check_field_time(recorded, time_s)
    except ValueError as exc:  # only this: any other ValueError is an internal error
        raise InputError(str(exc), file=str(run), column="--time") from None
    r = replay_method(
        recorded,
        spindle,
        make_corrector(method_name, model_path, spindle=spindle),
        keep_fields=False,
        field_at_s=time_s,
    )
    ((t, T),) = r.fields.items()
    render_snapshot(
        spindle,
        T,
        out,
        field=field.value,
        section=section,
        T_initial_C=r.start_reference_C,
        title=snapshot_title(recorded.name, method_name, t, recorded),
    )
    typer.echo(f"wrote {out}")
