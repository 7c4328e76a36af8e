"""`twin synth`: an emulated recorded run from the spindle's truth model."""

from __future__ import annotations

from pathlib import Path

import typer

from twin.errors import InputError


def synth(
    out: Path = typer.Option(..., "--out", help="Recorded run to write (RUN.csv or "
                             "RUN.parquet); the truth goes to RUN.truth.csv beside it."),
    minutes: float = typer.Option(..., "--minutes", min=2.0, max=24 * 60.0,
                                  help="Run length, minutes (two 60 s windows at least)."),
    ambient: float = typer.Option(..., "--ambient", min=-30.0,
                                  help="Ambient temperature at the start, °C."),
    seed: int = typer.Option(..., "--seed", min=0,
                             help="Seed of every random choice (deterministic)."),
    speed: float | None = typer.Option(None, "--speed", min=0.0, help="Constant speed, rpm."),
    profile: Path | None = typer.Option(None, "--profile", help="Speed profile CSV "
                                        "(time_s, speed_rpm[, ambient_C])."),
    scenario: Path | None = typer.Option(None, "--scenario", help="Scenario TOML (truth "
                                         "factors, sensors, faults)."),
    rate: float = typer.Option(1.0, "--rate", min=0.1, max=10.0, help="Sample rate, Hz."),
    coolant: float | None = typer.Option(None, "--coolant", help="Coolant inlet temperature "
                                         "at the start, °C (default: the ambient, as the "
                                         "nominal model assumes)."),
    quiet: bool = typer.Option(False, "--quiet", help="No progress output."),
) -> None:
    """Emulate a recorded run: the truth model plus sensor lag, noise and faults."""
    from twin.io.destinations import check_out_file
    from twin.plant.emulator import synthesize, truth_path_for, write_synth
    from twin.plant.profile import read_speed_profile
    from twin.plant.scenario import load_scenario
    from twin.runs import check_replayable
    from twin.runs.validate import FAHRENHEIT_AIR_RANGE_C
    from twin.spindle.conditions import check_operating_point
    from twin.spindle.spec import load_spec

    if (speed is None) == (profile is None):
        raise InputError("give exactly one of --speed and --profile", column="--speed")
    # replay reads an air or coolant temperature from 45 °C up as Fahrenheit: synth must not
    # write what replay refuses
    fahrenheit = FAHRENHEIT_AIR_RANGE_C[0]
    if not ambient < fahrenheit:
        raise InputError(f"ambient must lie in -30..{fahrenheit:g} °C (replay reads warmer air "
                         f"as Fahrenheit), got {ambient:g}", column="--ambient")
    if coolant is not None and not coolant < fahrenheit:
        raise InputError(f"coolant must be below {fahrenheit:g} °C (replay reads warmer "
                         f"coolant as Fahrenheit), got {coolant:g}", column="--coolant")
    try:
        check_operating_point(load_spec(None), speed or 0.0, ambient, coolant)
    except InputError as exc:
        raise InputError(exc.reason, column=f"--{exc.column.split('_')[0]}") from None
    if out.suffix.lower() not in (".csv", ".parquet"):
        raise InputError("the run must be written as .csv or .parquet", file=str(out),
                         column="--out")
    if not out.parent.is_dir():
        raise InputError("output folder does not exist", file=str(out.parent), column="--out")
    check_out_file(out, inputs=[profile, scenario], also=[truth_path_for(out)])
    run = synthesize(
        speed_rpm=speed,
        profile=None if profile is None else read_speed_profile(profile),
        minutes=minutes, ambient_C=ambient, seed=seed,
        scenario=load_scenario(scenario), rate_hz=rate, coolant_C=coolant,
        scenario_name=None if scenario is None else str(scenario),
        profile_name=None if profile is None else str(profile),
    )
    source = scenario or profile
    try:
        check_replayable(run.columns, str(out), load_spec(None).spindle.max_speed_rpm)
    except InputError as exc:
        raise InputError(f"the emulated run would be refused by replay: {exc.reason}",
                         file=None if source is None else str(source),
                         column=exc.column) from None
    run_path, truth_path = write_synth(run, out)
    if not quiet:
        typer.echo(f"wrote {run_path} ({run.n_samples} samples, {run.elapsed_s:.1f} s) "
                   f"and {truth_path}")
