"""Scenario TOML of the emulated spindle (shared DESIGN.md, "Emulator inputs").

Every table is a time series linearly interpolated in time; anything left out takes the
emulator's seeded default (see `twin.plant.truth`), so an evaluator can pin exactly the
truth factors a test case needs.  The first group moves the four values the twin's
corrections estimate:

    [bearing_heat.front]            # multiplier on the nominal (Palmgren) heat
    time_s = [0, 300, 1800]
    factor = [1.00, 1.12, 1.04]
    [bearing_heat.rear]             # same form
    [contact_resistance.front]      # multiplier on the nominal ring/sleeve resistance
    [contact_resistance.rear]
    [coolant]      time_s, inlet_C  # inlet temperature °C
    [ambient]      time_s, ambient_C   (overrides --ambient)
    [xy_drift]     time_s, x_um, y_um  (radial drift an axisymmetric model cannot explain)

The second group is *model-form error*: what a real spindle gets wrong that those four
values cannot express (REFERENCE.md §7).  It applies to the truth only; the twin keeps
its nominal model:

    [motor_heat]   time_s, factor   multiplier on the motor loss (rotor and stator)
    [film.coolant] time_s, factor   multiplier on the film coefficients of a surface group:
    [film.housing]                    coolant = jacket channels; housing = outer housing
    [film.air_gap]                    and mount; air_gap = rotor and stator gap faces;
    [film.rotor]                      rotor = rotor ends, shaft ends, nose, internal air
    [material]     conductivity = 0.92, expansion = 1.05
                   constant multipliers on every material's conductivity and expansion
                   coefficient (the contact resistance of Eq. 4/5 follows them)

Sensors and faults:

    [sensors]      noise_C, lag_s, noise_um,
                   placement_mm   each thermocouple sits up to this far from its nominal
                                  point (a seeded offset that stays inside the solid)
                   offset_C = {T2 = 0.3, coolant = -0.1}
                                  calibration offsets, K: added to a temperature channel's
                                  every reading (the truth keeps the metal's temperature)
    [faults]       stuck = ["T2"], dropouts = [{sensor, start_s, end_s}],
                   spikes = [{sensor, time_s, size}]   (size in °C or µm)
    [model]        size_factor     (mesh refinement of the truth model; < 1 is finer)

Unknown keys are errors naming the file, line and key (a typo must not silently fall back to
a default).  `dump_scenario` writes a `Scenario` back as TOML that parses to the same
values (the `twin synth --suite` files).
"""

from __future__ import annotations

import os
from typing import Annotated, ClassVar, Self

from pydantic import (
    AfterValidator,
    BaseModel,
    ConfigDict,
    Field,
    ValidationError,
    field_validator,
    model_validator,
)

from twin.contract import OPERATING_TEMPERATURE_C, SENSOR_NAMES
from twin.errors import TomlError
from twin.paths import parse_toml, read_toml, toml_error, toml_validation_error
from twin.plant.timetable import TimeTable

SENSOR_COLUMNS = {
    **{s: f"{s}_C" for s in SENSOR_NAMES},
    "ambient": "ambient_C", "coolant": "coolant_C",
    "disp_x": "disp_x_um", "disp_y": "disp_y_um", "disp_z": "disp_z_um",
}
_BY_COLUMN = {c: c for c in SENSOR_COLUMNS.values()}
TEMPERATURE_CHANNELS = tuple(n for n, c in SENSOR_COLUMNS.items() if c.endswith("_C"))


def sensor_column(name: str) -> str:
    """Run column of a sensor named in a scenario (`T2` or `T2_C`, `disp_z`, ...)."""
    column = SENSOR_COLUMNS.get(name) or _BY_COLUMN.get(name)
    if column is None:
        raise ValueError(f"unknown sensor {name!r}; expected one of {', '.join(SENSOR_COLUMNS)}")
    return column


class _Strict(BaseModel):
    # inf and nan are no times, factors or temperatures (TOML spells them `inf`, `nan`);
    # strict: TOML has typed values, so `true` or "1.2" where a number belongs is a slip
    # (lax parsing would read them as 1.0 and 1.2)
    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False, strict=True)


Times = Annotated[list[Annotated[float, Field(ge=0.0)]], Field(min_length=1)]


class _Table(_Strict):
    time_s: Times
    columns: ClassVar[tuple[str, ...]] = ()
    """The value lists given at the `time_s` times (each as long as time_s)."""

    @model_validator(mode="after")
    def _check_lengths(self) -> Self:
        if any(t1 <= t0 for t0, t1 in zip(self.time_s, self.time_s[1:], strict=False)):
            raise ValueError("time_s must be strictly increasing")
        for name in self.columns:
            if len(getattr(self, name)) != len(self.time_s):
                raise ValueError(f"{name} has {len(getattr(self, name))} values for "
                                 f"{len(self.time_s)} times")
        return self


class _Series(_Table):
    """A table of one value list, read at any time as a piecewise-linear `TimeTable`."""

    def table(self) -> TimeTable:
        (name,) = self.columns
        return TimeTable(self.time_s, getattr(self, name))


class FactorTable(_Series):
    factor: list[Annotated[float, Field(gt=0.0, le=10.0)]]
    columns: ClassVar[tuple[str, ...]] = ("factor",)


Celsius = Annotated[float, Field(ge=OPERATING_TEMPERATURE_C[0], le=OPERATING_TEMPERATURE_C[1])]


class CoolantTable(_Series):
    inlet_C: list[Celsius]
    columns: ClassVar[tuple[str, ...]] = ("inlet_C",)


class AmbientTable(_Series):
    ambient_C: list[Celsius]
    columns: ClassVar[tuple[str, ...]] = ("ambient_C",)


Microns = Annotated[float, Field(ge=-100.0, le=100.0)]


class XYDriftTable(_Table):
    x_um: list[Microns]
    y_um: list[Microns]
    columns: ClassVar[tuple[str, ...]] = ("x_um", "y_um")


class PerBearing(_Strict):
    front: FactorTable | None = None
    rear: FactorTable | None = None


class FilmGroups(_Strict):
    """Multipliers on the film coefficients of the four surface groups (`FILM_GROUPS`)."""

    coolant: FactorTable | None = None
    housing: FactorTable | None = None
    air_gap: FactorTable | None = None
    rotor: FactorTable | None = None


Multiplier = Annotated[float, Field(ge=0.5, le=2.0)]


class MaterialFactors(_Strict):
    """Constant multipliers on the truth's material data (None: the seeded default)."""

    conductivity: Multiplier | None = None
    expansion: Multiplier | None = None


MAX_SENSOR_OFFSET_C = 5.0
"""Largest calibration offset, K: a class-2 thermocouple's tolerance is ±2.5 K."""


class Sensors(_Strict):
    noise_C: Annotated[float, Field(ge=0.0, le=5.0)] = 0.05
    lag_s: Annotated[float, Field(ge=0.0, le=600.0)] = 8.0
    noise_um: Annotated[float, Field(ge=0.0, le=10.0)] = 0.1
    placement_mm: Annotated[float, Field(ge=0.0, le=10.0)] = 1.0
    offset_C: dict[str, Annotated[float, Field(ge=-MAX_SENSOR_OFFSET_C,
                                               le=MAX_SENSOR_OFFSET_C)]] = {}
    """Calibration offset per temperature channel (T1..T5, ambient, coolant), K; keyed by
    the run column (`T2_C`) once parsed."""

    @field_validator("offset_C")
    @classmethod
    def _temperature_channels(cls, offsets: dict[str, float]) -> dict[str, float]:
        # a bad name is told at its own key (its line), not at the table's header: in a
        # [sensors.offset_C] table of seven channels the header said nothing of which one
        columns: dict[str, float] = {}
        named_by: dict[str, str] = {}
        for name, value in offsets.items():
            column = SENSOR_COLUMNS.get(name) or _BY_COLUMN.get(name)
            if column is None or not column.endswith("_C"):
                raise _key_error(name, f"{name!r} is no temperature channel; calibration "
                                 f"offsets are for {', '.join(TEMPERATURE_CHANNELS)}")
            if column in columns:
                raise _key_error(name, f"{name!r} names {column} a second time (as "
                                 f"{named_by[column]!r} does)")
            columns[column], named_by[column] = value, name
        return dict(sorted(columns.items()))


def _key_error(key: str, message: str) -> ValidationError:
    """A validation error of a table located at its key `key` (pydantic locates a field
    validator's ValueError at the table)."""
    from pydantic_core import InitErrorDetails, PydanticCustomError

    return ValidationError.from_exception_data("offset_C", [InitErrorDetails(
        type=PydanticCustomError("value_error", "{message}", {"message": message}),
        loc=(key,), input=key)])


class _SensorRef(_Strict):
    sensor: str

    @field_validator("sensor")
    @classmethod
    def _known(cls, name: str) -> str:
        return sensor_column(name)


class Dropout(_SensorRef):
    start_s: Annotated[float, Field(ge=0.0)]
    end_s: Annotated[float, Field(ge=0.0)]

    @model_validator(mode="after")
    def _order(self) -> Dropout:
        if self.end_s <= self.start_s:
            raise ValueError("end_s must be after start_s")
        return self


class Spike(_SensorRef):
    time_s: Annotated[float, Field(ge=0.0)]
    size: Annotated[float, Field(ge=-MAX_SPIKE, le=MAX_SPIKE)] = 5.0


MAX_SPIKE = 100.0
"""Largest spike (°C or µm): a glitch a logger writes, still a short number in the file."""


SensorName = Annotated[str, AfterValidator(sensor_column)]
"""A sensor as a scenario names it, read as its run column (`T2` → `T2_C`)."""


class Faults(_Strict):
    stuck: list[SensorName] = []  # an item's error names its index, hence its line
    dropouts: list[Dropout] = []
    spikes: list[Spike] = []


class ModelOptions(_Strict):
    size_factor: Annotated[float, Field(gt=0.2, le=2.0)] = 0.7


class Scenario(_Strict):
    """A parsed scenario; `None` tables take the emulator's seeded defaults."""

    bearing_heat: PerBearing = PerBearing()
    contact_resistance: PerBearing = PerBearing()
    coolant: CoolantTable | None = None
    ambient: AmbientTable | None = None
    xy_drift: XYDriftTable | None = None
    motor_heat: FactorTable | None = None
    film: FilmGroups = FilmGroups()
    material: MaterialFactors = MaterialFactors()
    sensors: Sensors = Sensors()
    faults: Faults = Faults()
    model: ModelOptions = ModelOptions()


def parse_scenario(text: str, file: str = "<scenario>") -> Scenario:
    """Parse scenario TOML text; errors name the file, line and key."""
    return _validated(text, parse_toml(text, file), file)


def _validated(text: str, data: dict, file: str) -> Scenario:
    try:
        return Scenario.model_validate(data)
    except ValidationError as exc:
        raise toml_validation_error(exc, text, file) from None


def dump_scenario(scenario: Scenario, header: str = "") -> str:
    """TOML text of a scenario (tables left at their default are left out).

    Floats are written with `repr`, so `parse_scenario(dump_scenario(s)) == s` exactly;
    `header` becomes leading `#` comment lines.
    """
    import tomli_w

    data = scenario.model_dump(exclude_none=True, exclude_defaults=True)
    comments = "".join(f"# {line}\n" if line else "#\n" for line in header.splitlines())
    return comments + tomli_w.dumps(data)


def load_scenario(path: str | os.PathLike[str] | None,
                  duration_s: float | None = None) -> Scenario:
    """Read a scenario file (None: every default); with `duration_s`, a spike or dropout
    the run never reaches is an error (a spike was put on the last sample)."""
    if path is None:
        return Scenario()
    text, data = read_toml(path, column="--scenario")
    scenario = _validated(text, data, str(path))
    if duration_s is not None:
        _check_fault_times(scenario.faults, duration_s, text, str(path))
    return scenario


def offset_error(path: str | os.PathLike[str], column: str, message: str) -> TomlError:
    """TomlError at the calibration offset of the run column `column` in the scenario file
    `path`, at its key as the file spells it (`ambient` or `ambient_C`)."""
    text, data = read_toml(path, column="--scenario")
    named = (data.get("sensors") or {}).get("offset_C") or {}
    key = next((k for k in named if k in (column, column.removesuffix("_C"))),
               column.removesuffix("_C"))
    return toml_error(text, str(path), ("sensors", "offset_C", key), message)


def _check_fault_times(faults: Faults, duration_s: float, text: str, file: str) -> None:
    """TomlError naming the first spike or dropout that starts after the run's end."""
    late = [(("faults", "spikes", k, "time_s"), f"spike at {spike.time_s:g} s")
            for k, spike in enumerate(faults.spikes) if spike.time_s > duration_s]
    late += [(("faults", "dropouts", k, "start_s"), f"dropout from {drop.start_s:g} s")
             for k, drop in enumerate(faults.dropouts) if drop.start_s > duration_s]
    if late:
        loc, what = late[0]
        raise toml_error(text, file, loc, f"{what} is after the run's end ({duration_s:g} s)")
