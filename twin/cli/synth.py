"""`twin synth`: an emulated recorded run from the spindle's truth model."""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING

import typer

from twin.cli.inputs import MAX_SEED, RANGE_C
from twin.errors import InputError, TomlError
from twin.io.destinations import REPLACE_BUNDLED_RUNS
from twin.wording import counted

if TYPE_CHECKING:
    import numpy as np

    from twin.plant.profile import SpeedProfile
    from twin.plant.scenario import Scenario

SYNTH_HELP = """Emulate a recorded run: the truth model plus sensor lag, noise and faults.

One run: --speed RPM or --profile CSV, with --minutes, --ambient, --seed
and --out RUN.csv.  A suite: --suite N --seed S [--minutes M] --out DIR
draws N scenarios (speed steps and stops, ambient, coolant, every truth
factor below, sensor faults) and writes per run NAME.csv, NAME.truth.csv,
NAME.scenario.toml and NAME.profile.csv; each scenario's header gives the
command that reproduces its run byte for byte.  Other runs already in DIR
are refused (--overwrite removes them).

Scenario TOML (--scenario): every table is time_s plus values, linear in
time; anything left out takes a seeded default.

\b
  [bearing_heat.front|rear]        factor on the Palmgren heat
  [contact_resistance.front|rear]  factor on the ring/sleeve resistance
  [coolant] inlet_C, [ambient] ambient_C, [xy_drift] x_um, y_um
Model-form error (the truth only; the twin keeps its nominal model):
  [motor_heat]                     factor on the motor loss
  [film.coolant|housing|air_gap|rotor]  factor on that group's films
  [material] conductivity, expansion  constant multipliers
  [sensors] noise_C, lag_s, noise_um, placement_mm (thermocouple's point
            off by up to this); [sensors.offset_C] T2 = 0.3 (calibration, K)
  [faults] stuck, dropouts, spikes;  [model] size_factor

Unknown keys are errors naming the file and line.  Without a scenario the
truth still differs from the twin: motor ±15 %, films ±25 %, conductivity
±5 %, expansion ±3 %, thermocouples up to 1 mm off (twin.plant.truth)."""


def synth(
    out: Path = typer.Option(..., "--out", metavar="RUN.csv|DIR",
                             help="Recorded run to write (RUN.csv or "
                             "RUN.parquet; the truth goes to RUN.truth.csv beside it), or "
                             "with --suite the folder of the suite's files."),
    seed: int = typer.Option(..., "--seed", metavar="N", min=0, max=MAX_SEED,
                             help="Seed of every random choice (deterministic)."),
    minutes: float | None = typer.Option(None, "--minutes", metavar="M", min=2.0, max=24 * 60.0,
                                         help="Run length, minutes (two 60 s windows at "
                                         "least; --suite: default 40)."),
    ambient: float | None = typer.Option(None, "--ambient", metavar="C",
                                         help="Ambient temperature at the "
                                         f"start, °C ({RANGE_C}; not with --suite; a "
                                         "scenario's [ambient] or the profile's ambient_C "
                                         "overrides it, with a warning)."),
    speed: float | None = typer.Option(None, "--speed", metavar="RPM", min=0.0,
                                       help="Constant speed, rpm."),
    profile: Path | None = typer.Option(None, "--profile", metavar="CSV", help="Speed profile CSV "
                                        "(time_s, speed_rpm[, ambient_C]) from 0 s, each "
                                        "row held until the next; 0 rpm is a stop; steps after "
                                        "the run's end are left out, with a warning)."),
    scenario: Path | None = typer.Option(None, "--scenario", metavar="TOML",
                                         help="Scenario TOML (truth "
                                         "factors, model-form error, sensors, faults; "
                                         "see above)."),
    suite: int | None = typer.Option(None, "--suite", metavar="N", min=1, max=10000,
                                     help="Draw this many runs from the seeded scenario "
                                     "distribution (twin.plant.suite) into the --out folder."),
    rate: float = typer.Option(1.0, "--rate", metavar="HZ", min=0.1, max=10.0,
                               help="Sample rate, Hz."),
    coolant: float | None = typer.Option(None, "--coolant", metavar="C",
                                         help="Coolant inlet temperature "
                                         f"at the start, °C ({RANGE_C}; default: the "
                                         "ambient, as the nominal model assumes; a "
                                         "scenario's [coolant] overrides it, with a "
                                         "warning)."),
    record_from: float | None = typer.Option(
        None, "--record-from", metavar="M", min=0.0,
        help="The logger starts M minutes into the run (a recording begun on a warm "
        "spindle): the spindle follows the profile and scenario from 0 s, the file holds "
        "the samples from M on, time and probes zeroed there; at least 2 minutes before "
        "--minutes.  Not with --suite."),
    overwrite: bool = typer.Option(False, "--overwrite", help="With --suite: remove the "
                                   "runs twin synth wrote already in the --out folder that "
                                   "this suite does not write (without it they are an "
                                   "error; another run file there is one in any case)."),
    replace_bundled: bool = typer.Option(
        False, REPLACE_BUNDLED_RUNS,
        help="Let --out lie in the bundled runs (twin/data/runs, examples/runs/ in the "
        "repository, which every replay without RUN reads); refused without it. `make "
        "examples` passes it."),
    quiet: bool = typer.Option(False, "--quiet", help="No progress output."),
) -> None:
    from twin.cli.inputs import COMPANION_SUFFIXES, check_operating_options
    from twin.io.destinations import check_out_file
    from twin.plant.emulator import synthesize, truth_path_for, write_synth
    from twin.plant.profile import read_speed_profile
    from twin.plant.scenario import load_scenario, offset_error
    from twin.runs import check_replayable
    from twin.spindle.spec import load_spec

    if suite is not None:
        _synth_suite(suite, seed, 40.0 if minutes is None else minutes, rate, out,
                     given={"--speed": speed, "--profile": profile, "--scenario": scenario,
                            "--ambient": ambient, "--coolant": coolant,
                            "--record-from": record_from},
                     overwrite=overwrite, quiet=quiet, replace_bundled=replace_bundled)
        return
    if (speed is None) == (profile is None):
        raise InputError("give exactly one of --speed and --profile (or --suite)",
                         column="--speed")
    for name, value in (("--minutes", minutes), ("--ambient", ambient)):
        if value is None:
            raise InputError("missing: a single run needs it", column=name)
    if record_from is not None and record_from > minutes - 2.0:
        raise InputError(f"{record_from:g} min leaves less than two 60 s windows of the "
                         f"{minutes:g}-min run (--minutes) to record", column="--record-from")
    # the range replay reads (twin.contract.OPERATING_TEMPERATURE_C; NaN too): synth must
    # not write what replay refuses
    check_operating_options(load_spec(None), speed or 0.0, ambient, coolant)
    if out.name.endswith(COMPANION_SUFFIXES):
        raise InputError(f"a run may not be named *{'/*'.join(COMPANION_SUFFIXES)}: those are "
                         "the files synth writes beside a run, which 'twin replay FOLDER' "
                         "leaves out", file=str(out), column="--out")
    check_out_file(out, inputs=[profile, scenario], also=[truth_path_for(out)],
                   suffixes=(".csv", ".parquet"), replace_bundled_runs=replace_bundled)
    speed_profile = None if profile is None else read_speed_profile(profile)
    if speed_profile is not None and speed_profile.ignored:
        # a warning, shown under --quiet too (which silences progress): a misspelt
        # ambient column means a run emulated at another ambient than the file gave
        typer.echo(f"warning: {profile}: column(s) {', '.join(speed_profile.ignored)} ignored: a "
                   "speed profile sets time_s, speed_rpm and ambient_C only (the coolant: a "
                   "scenario's [coolant])", err=True)
    if speed_profile is not None:
        _tell_steps_after_the_end(speed_profile, profile, minutes)
    truth = load_scenario(scenario, duration_s=60.0 * minutes)
    profile_ambient = speed_profile is not None and speed_profile.ambient_C is not None
    if profile_ambient and truth.ambient is not None:
        # the scenario's table won and the profile's column was read for nothing
        raise TomlError(f"[ambient] and the profile's ambient_C column ({profile}) both give "
                        "the ambient: keep one of them", file=str(scenario), key="ambient")
    for warning in _overridden_options(ambient, coolant, truth, speed_profile,
                                       scenario, profile):
        # shown under --quiet too, as the ignored profile columns are: the run is emulated
        # at another temperature than the command line says
        typer.echo(f"warning: {warning}", err=True)
    run = synthesize(
        speed_rpm=speed, profile=speed_profile,
        minutes=minutes, ambient_C=ambient, seed=seed, scenario=truth, rate_hz=rate,
        coolant_C=coolant,
        scenario_name=None if scenario is None else str(scenario),
        profile_name=None if profile is None else str(profile),
        record_from_s=0.0 if record_from is None else 60.0 * record_from,
    )
    source = scenario or profile
    max_speed = load_spec(None).spindle.max_speed_rpm
    try:
        check_replayable(run.columns, str(out), max_speed)
    except InputError as exc:
        offsets = truth.sensors.offset_C
        if (scenario is not None and exc.column in offsets and _replayable(
                {**run.columns, **{c: run.columns[c] - v for c, v in offsets.items()}},
                max_speed)):
            # the offsets alone took the readings out (not a fault on the same channel)
            raise offset_error(scenario, exc.column, "with this calibration offset the "
                               f"emulated run's {exc.column} would be refused by replay "
                               f"({exc.reason})") from None
        raise InputError(f"the emulated run would be refused by replay: {exc.reason}",
                         file=None if source is None else str(source),
                         column=exc.column) from None
    run_path, truth_path = write_synth(run, out)
    if not quiet:
        # the run's length and the time the emulation took, each said as what it is
        recorded = minutes if record_from is None else minutes - record_from
        since = "" if not record_from else f" from {record_from:g} min into the run"
        typer.echo(f"wrote {run_path} ({counted(run.n_samples, 'sample')} over {recorded:g} "
                   f"min{since}, emulated in {run.elapsed_s:.1f} s) and {truth_path}")


synth.__doc__ = SYNTH_HELP


def _replayable(columns: dict[str, np.ndarray], max_speed_rpm: float) -> bool:
    from twin.runs import check_replayable

    try:
        check_replayable(columns, "", max_speed_rpm)
    except InputError:
        return False
    return True


def _tell_steps_after_the_end(speed_profile: SpeedProfile, profile: Path | None,
                              minutes: float) -> None:
    """Warn (under --quiet too, as the other profile warnings) of the profile's steps after
    the run's end, which were dropped without a word: a profile longer than the run is a
    legitimate reuse, so a warning (`twin.plant.profile.steps_after`), not an error."""
    from twin.errors import place
    from twin.plant.profile import steps_after

    dropped = steps_after(speed_profile, 60.0 * minutes)
    if dropped:
        line, time_s = dropped[0]
        where = place(str(profile), line, "time_s", row_unit=speed_profile.row_unit)
        typer.echo(f"warning: {where}: the step at {time_s:g} s is after the run's end "
                   f"({60.0 * minutes:g} s, --minutes {minutes:g}); "
                   f"{counted(len(dropped), 'step')} of the profile from there on left "
                   "out of the run", err=True)


def _overridden_options(ambient: float | None, coolant: float | None, truth: Scenario,
                        speed_profile: SpeedProfile | None, scenario: Path | None,
                        profile: Path | None) -> list[str]:
    """What to tell where `--ambient` or `--coolant` differs from the value a scenario table
    or the profile's ambient_C column gives at 0 s: those override the option (DESIGN.md),
    and the required --ambient was else dropped without a word (`--ambient 30` with an
    [ambient] table from 24 °C emulated a run at 24 °C)."""
    import numpy as np

    given: list[tuple[str, float | None, float | None, str]] = []
    if truth.ambient is not None:
        given.append(("--ambient", ambient,
                      float(np.interp(0.0, truth.ambient.time_s, truth.ambient.ambient_C)),
                      f"{scenario}'s [ambient]"))
    elif speed_profile is not None and speed_profile.ambient_C is not None:
        given.append(("--ambient", ambient, float(speed_profile.ambient_C(0.0)),
                      f"{profile}'s ambient_C column"))
    if truth.coolant is not None:
        given.append(("--coolant", coolant,
                      float(np.interp(0.0, truth.coolant.time_s, truth.coolant.inlet_C)),
                      f"{scenario}'s [coolant]"))
    return [f"{option} {value:g} is not used: {source} sets it ({table:g} °C at 0 s)"
            for option, value, table, source in given
            if value is not None and not math.isclose(value, table, abs_tol=1e-6)]


def _synth_suite(n: int, seed: int, minutes: float, rate: float, out: Path, *,
                 given: dict[str, object], overwrite: bool, quiet: bool,
                 replace_bundled: bool = False) -> None:
    """`--suite N`: draw N cases and write each one's four files into the folder `out`.

    Runs already in `out` that this suite does not write (an older suite's) are refused,
    or removed first with `overwrite`: a later `twin replay out` would mix them in."""
    import time

    from twin.cli.inputs import COMPANION_SUFFIXES, run_files_in
    from twin.io.destinations import check_out_dir
    from twin.plant.emulator import written_by_synth
    from twin.plant.scenario import Scenario
    from twin.plant.suite import case_files, draw_suite, write_case
    from twin.spindle import SpindleModel

    clash = next((name for name, value in given.items() if value is not None), None)
    if clash:
        raise InputError("--suite draws every run's conditions itself; leave this out",
                         column=clash)
    if out.suffix.lower() in (".csv", ".parquet") and not (out.exists() or out.is_symlink()):
        # a run file's name: made a folder of that name, which 'twin replay' of its parent
        # then passes over (it lists files)
        raise InputError("--suite writes a folder of runs, not a run file: name a folder "
                         "(or leave --suite out for one run)", file=str(out), column="--out")
    check_out_dir(out, replace_bundled_runs=replace_bundled)
    # one nominal truth model for the whole suite (each run adds its own material factors)
    model = SpindleModel.load(size_factor=Scenario().model.size_factor)
    limit = model.spec.spindle.max_speed_rpm
    cases = draw_suite(n, seed, minutes, max_speed_rpm=limit, rate_hz=rate)
    written = {name for case in cases for name in case_files(case.name).values()}
    stale = [p for p in run_files_in(out) if p.name not in written] if out.is_dir() else []
    # the truth, profile and scenario files beside the runs are synth's by their names
    foreign = [p for p in stale if not p.name.endswith((*COMPANION_SUFFIXES, ".scenario.toml"))
               and not written_by_synth(p)]
    if foreign:
        # a measured run beside the suite is data: --overwrite removed it with the old runs
        raise InputError(f"holds {counted(len(foreign), 'run file')} twin synth did not write "
                         f"({_some_names(foreign)}); --overwrite removes only runs twin "
                         "synth wrote: move them, or write the suite into another folder",
                         file=str(out), column="--out")
    if stale and not overwrite:
        raise InputError(f"holds {counted(len(stale), 'run file')} this suite does not write "
                         f"({_some_names(stale)}), which 'twin replay {out}' would mix "
                         "with the new runs; write into an empty folder or pass --overwrite "
                         "to remove them", file=str(out), column="--out")
    for path in stale:  # first: a suite stopped half-way leaves only its own runs
        path.unlink()
    out.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    for k, case in enumerate(cases, start=1):
        t0 = time.perf_counter()
        paths = write_case(case, out, model)
        if not quiet:
            typer.echo(f"[{k}/{n}] wrote {paths['run']} (emulated in "
                       f"{time.perf_counter() - t0:.1f} s)")
    if not quiet:
        per_minute = (time.perf_counter() - start) / (n * minutes)
        typer.echo(f"{counted(n, 'run')} in {out} ({per_minute:.2f} s per run-minute)")


def _some_names(paths: list[Path]) -> str:
    """The first three file names of `paths` and how many more: `a.csv, b.csv, c.csv, … and
    2 more`, as the suite's refusals list the runs in its folder."""
    return ", ".join(p.name for p in paths[:3]) + (
        f", … and {len(paths) - 3} more" if len(paths) > 3 else "")
