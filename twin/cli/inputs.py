"""Inputs several `twin` commands share: the bundled examples, the choices and bounds
typer checks (an unknown choice or a value out of range exits 2 naming the option), and
the correction model check.  Light on purpose: `twin --help` imports it, so the choices
are spelled here and tests/test_cli.py checks them against the modules that act on them.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from enum import StrEnum
from pathlib import Path
from typing import TYPE_CHECKING

import typer

from twin.contract import OPERATING_TEMPERATURE_C
from twin.data import bundled_path
from twin.errors import InputError

if TYPE_CHECKING:
    from twin.spindle.spec import SpindleSpec


class Method(StrEnum):
    """A correction method (`twin.correction.methods.METHODS`)."""

    OPEN_LOOP = "open_loop"
    RATIO = "ratio"
    BPNN = "bpnn"
    ESTIMATOR = "estimator"


class WindowEnds(StrEnum):
    """Which window ends a replay pictures (--snapshots) or writes field files of
    (--fields): `twin.loop.runfiles.WINDOW_END_CHOICES`."""

    NONE = "none"
    END = "end"
    EVERY = "every"


class Field(StrEnum):
    """The field a snapshot shows (`twin.loop.snapshot.FIELDS`)."""

    TEMPERATURE = "temperature"
    DISPLACEMENT = "displacement"


MIN_SIZE_FACTOR = 0.2
"""Finest mesh element size multiplier: 25 times the default elements (minutes to mesh);
finer, the work grows without a useful bound."""
MAX_SIZE_FACTOR = 100.0
"""Mesh element size multiplier: above this the spindle is no longer resolved at all."""

MAX_SEED = 2**32 - 1
"""Largest --seed of every command.  k-means takes seeds below 2**32 and torch below
2**64: beyond, `train` and `drift fit` ended in an internal error after their work, where
typer can refuse the option before any.  numpy's generators behind `synth` take any seed
≥ 0, but a suite's runs get seeds below 2**32 (`twin.plant.suite`, the seeds their
scenarios reproduce them with), and a longer suite seed, in every file name, made names
the file system refused once the suite was drawn."""


def bundled_runs_dir() -> Path:
    """Where the example recorded runs shipped with the twin are (package data)."""
    return bundled_path("runs").resolve()


RUN_SUFFIXES = (".csv", ".parquet", ".pq")
"""What a recorded run's file ends in, in any case (the readers of `twin.runs.run`): a
folder's RUN.CSV was passed over while the same file named alone was replayed."""

COMPANION_SUFFIXES = (".truth.csv", ".profile.csv")
"""Files `twin synth` writes beside a run (its truth and speed profile): not runs."""


def runs_in(folder: Path) -> list[Path]:
    """The recorded runs in `folder` (CSV or Parquet, sorted by name), leaving out the
    truth and profile files `twin synth` writes beside each run, so a synth suite's
    folder replays as it is, and hidden files: a Mac's `._RUN.csv` beside each run
    copied to a stick, a killed writer's temporary file (each failed the batch as a run
    that a leading dot cannot name)."""
    runs = sorted(p for p in folder.iterdir() if p.suffix.lower() in RUN_SUFFIXES
                  and not p.name.startswith(".") and p.is_file())
    return [r for r in runs if not r.name.endswith(COMPANION_SUFFIXES)]


RANGE_C = "{:g}..{:g}".format(*OPERATING_TEMPERATURE_C)
"""The plausible ambient and coolant range as the options' help gives it (°C)."""


def check_operating_options(spec: SpindleSpec, speed: float, ambient: float,
                            coolant: float | None) -> None:
    """`check_operating_point` for a command's options: its errors name the option the
    user typed (`--speed`), not the run column (`speed_rpm`)."""
    from twin.spindle.conditions import check_operating_point

    try:
        check_operating_point(spec, speed, ambient, coolant)
    except InputError as exc:
        option = f"--{exc.column.split('_')[0]}" if exc.column else None
        raise InputError(exc.reason, column=option) from None


def run_files_in(folder: Path) -> list[Path]:
    """Every file of recorded runs in `folder`, sorted by name: the runs `runs_in` finds
    and the truth, profile and scenario files `twin synth` writes beside them."""
    return sorted(p for p in folder.iterdir() if p.is_file() and not p.name.startswith(".")
                  and (p.suffix.lower() in RUN_SUFFIXES or p.name.endswith(".scenario.toml")))


def expand_run_folders(paths: list[Path]) -> list[Path]:
    """Each folder among `paths` replaced by the runs in it (`runs_in`); files kept.  A
    folder without runs is an InputError (a mistyped folder would otherwise go unseen)."""
    out: list[Path] = []
    for path in paths:
        found = runs_in(path) if path.is_dir() else [path]
        if not found:
            raise InputError("no recorded runs (CSV/Parquet) found in this folder",
                             file=str(path))
        out.extend(found)
    return out


def bundled_runs() -> list[Path]:
    """The example recorded runs shipped with the twin (their `.truth.csv` left out)."""
    return runs_in(bundled_runs_dir())


def bundled_model() -> Path | None:
    """The default correction model shipped with the twin, if any."""
    model = bundled_path("correction_model.safetensors").resolve()
    return model if model.is_file() else None


REPLACE_BUNDLED_MODEL = "--replace-bundled-model"
"""The `twin train` option that lets --out be the bundled model (`make model` passes it)."""


def check_not_bundled_model(out: Path, *, replace: bool | None = None) -> None:
    """InputError if `out` is the bundled correction model (through the package's link
    too), which every replay without --model reads: `twin train --out` of it replaced the
    default model without a word, as a drift model written there would.  `replace`: the
    value of train's REPLACE_BUNDLED_MODEL (None: a command that has none), which lets
    train write it (`make model`) and is refused for any other --out, whose writer
    may think it updates the bundled model."""
    from twin.io.destinations import same_file

    bundled = bundled_path("correction_model.safetensors").resolve()
    if not same_file(out, bundled):
        if replace:
            raise InputError(f"is for --out the bundled model ({bundled}); this --out is "
                             "another file: leave the option out", column=REPLACE_BUNDLED_MODEL)
        return
    if replace is None:
        raise InputError("is the bundled correction model, which every replay without "
                         "--model reads: write this model elsewhere", file=str(out),
                         column="--out")
    if not replace:
        raise InputError("is the bundled correction model, which every replay without "
                         "--model reads: write elsewhere and pass --model, or pass "
                         f"{REPLACE_BUNDLED_MODEL} to replace it (as `make model` does)",
                         file=str(out), column="--out")


def check_element_size(spec: SpindleSpec, size_factor: float) -> None:
    """InputError unless `size_factor` leaves the spec's elements at least
    `MIN_ELEMENT_SIZE_MM`: the floor --size-factor keeps on the reference spindle, held on
    a spec with smaller elements too (1.4 mm at 0.2 made 0.28 mm elements, 625 times the
    reference's count)."""
    from twin.spindle.spec import MIN_ELEMENT_SIZE_MM

    size = spec.mesh.element_size_mm * size_factor
    if size < MIN_ELEMENT_SIZE_MM * (1 - 1e-9):
        raise InputError(f"{size_factor:g} times the spec's element_size_mm "
                         f"{spec.mesh.element_size_mm:g} makes {size:.3g} mm elements; the "
                         f"finest allowed is {MIN_ELEMENT_SIZE_MM:g} mm", column="--size-factor")


def method_list(text: str) -> str:
    """typer callback of `--methods`: `open_loop, ratio,ratio` → `open_loop,ratio`, each
    method known (`Method`) and listed once."""
    methods = [m.strip() for m in text.split(",") if m.strip()]
    choices = ", ".join(Method)
    if not methods:
        raise typer.BadParameter(f"no method given; choose from {choices}")
    for m in methods:
        if m not in {method.value for method in Method}:
            raise typer.BadParameter(f"unknown method {m!r}; choose from {choices}")
    return ",".join(dict.fromkeys(methods))


def dask_address(address: str | None) -> str | None:
    """typer callback of `--dask`: a scheduler address distributed can connect to
    (`tcp://HOST:PORT`, `tls://...`), checked before any work instead of failing as an
    internal error once the runs are read."""
    if address is None:
        return None
    from distributed.comm import get_address_host_port

    try:
        get_address_host_port(address)
    except (ValueError, TypeError) as exc:
        raise typer.BadParameter(f"{address!r} is not a scheduler address such as "
                                 f"tcp://127.0.0.1:8786 ({exc})") from None
    return address


def between(low: float, high: float = math.inf) -> Callable[[float], float]:
    """typer callback: the value must lie strictly between `low` and `high` (typer's own
    `min`/`max` bounds are closed)."""

    def check(value: float) -> float:
        if not low < value < high:
            upper = "" if high == math.inf else f" and below {high:g}"
            # "must be above 0, got inf" read as if infinity were not above 0
            finite = "" if math.isfinite(value) else "a finite number "
            raise typer.BadParameter(f"must be {finite}above {low:g}{upper}, got {value:g}")
        return value

    return check


def checked_model(methods: list[str], model: Path | None) -> str | None:
    """The model file the methods need (the bundled one by default), loaded once to check
    it: a bad model is bad input for every run, so it fails before any work starts.  A
    model given is checked whether or not a method uses it: a mistyped --model passed with
    methods that need none was ignored without a word."""
    if "bpnn" not in methods and model is None:
        return None
    model = model or bundled_model()
    if model is None:
        raise InputError(
            "the bpnn method needs a correction model: pass --model FILE", column="--model"
        )
    from twin.correction.modelfile import load_model
    from twin.paths import check_input_file

    check_input_file(model, column="--model")  # nothing there, a folder, a fifo: say which

    load_model(model)
    return str(model)
