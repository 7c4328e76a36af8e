"""`twin simulate`: open-loop forward run of the spindle at a constant speed."""

from __future__ import annotations

from pathlib import Path

import typer

from twin.cli.inputs import (
    MAX_SIZE_FACTOR,
    MIN_SIZE_FACTOR,
    RANGE_C,
    between,
    check_element_size,
    check_operating_options,
)


def simulate_command(
    speed: float = typer.Option(..., "--speed", metavar="RPM", help="Spindle speed, rpm."),
    minutes: float = typer.Option(..., "--minutes", metavar="M", callback=between(0.0),
                                  help="Duration, minutes (rounded up to whole 4 s "
                                  "steps)."),
    ambient: float = typer.Option(..., "--ambient", metavar="C", help="Ambient temperature, °C "
                                  f"({RANGE_C})."),
    out: Path = typer.Option(..., "--out", metavar="DIR", help="Output directory."),
    coolant: float | None = typer.Option(
        None, "--coolant", metavar="C",
        help=f"Coolant inlet temperature, °C ({RANGE_C}; default: the "
        "ambient)."
    ),
    spec: Path | None = typer.Option(None, "--spec", metavar="TOML", help="Spindle spec TOML."),
    size_factor: float = typer.Option(1.0, "--size-factor", metavar="F",
                                      callback=between(MIN_SIZE_FACTOR, MAX_SIZE_FACTOR),
                                      help="Mesh size multiplier."),
    field_every: float = typer.Option(
        60.0, "--field-every", metavar="S", min=0.0, help="Seconds between field snapshots, to the "
        "nearest whole 4 s step (0: only the end)."
    ),
    quiet: bool = typer.Option(False, "--quiet", help="Print nothing on success."),
) -> None:
    """Open-loop transient at a constant speed (4 s steps, nominal boundary conditions).

    Writes keypoints.csv, fields.pvd + fields/*.vtu and summary.json to OUT.
    """
    from twin.errors import InputError
    from twin.io.destinations import check_out_dir
    from twin.loop.summary import is_replay_folder
    from twin.runs.schema import MAX_DURATION_S
    from twin.spindle import SpindleModel, simulate, write_simulation
    from twin.spindle.spec import load_spec

    if minutes > MAX_DURATION_S / 60.0:
        raise InputError(f"must be at most {MAX_DURATION_S / 60.0:g} minutes (one day), got "
                         f"{minutes:g}", column="--minutes")
    check_out_dir(out, inputs=[spec],
                  owned=["fields"], files=["keypoints.csv", "fields.pvd", "summary.json"])
    if is_replay_folder(out):  # whose summary.json (and report's table) this one replaced
        raise InputError("is a twin replay output folder, whose summary.json this would "
                         "replace: choose another --out", file=str(out), column="--out")
    # validate the operating point before the (slower) model build
    the_spec = load_spec(spec, option="--spec")
    check_operating_options(the_spec, speed, ambient, coolant)
    check_element_size(the_spec, size_factor)
    model = SpindleModel.load(spec, size_factor=size_factor)
    every = field_every if field_every > 0 else minutes * 60.0
    result = simulate(model, speed, minutes, ambient, coolant, field_every_s=every)
    info = write_simulation(model, result, out)
    if not quiet:
        where = info["max_temperature_at"]
        # rounded before printing: a drift of -1e-17 µm (a standstill) printed as -0.00
        axial, radial = (round(info["nose_drift_um"][k], 2) + 0.0 for k in ("axial", "radial"))
        typer.echo(
            f"{speed:g} rpm, {info['minutes']:g} min: max {info['max_temperature_C']:.2f} °C in "
            f"{where['region']}, nose drift axial {axial:.2f} µm, radial {radial:.2f} µm -> "
            f"{out}"
        )
