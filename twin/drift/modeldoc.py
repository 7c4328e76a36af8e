"""The JSON of a drift model file, typed: what `load_drift_model` checks before using it.

A file written before the JSON had its own checksum loads unchecked by it, so a damaged
lag list, interval rule, reference temperature or sensor list reached the arithmetic and
ended in an internal error.  Every field the twin reads is typed here (pydantic, strict:
no number from a string, no flag from a number); what the fields must say together (a
reference temperature per sensor, an interval width per target, a validation score per
target) is checked at the field that is wrong.
"""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator

from twin.drift.data import DISPLACEMENT_SUFFIX, TEMPERATURE_SUFFIX
from twin.drift.features import GROUPS
from twin.drift.methods import METHODS

MethodName = Literal[tuple(METHODS)]  # type: ignore[valid-type]
GroupName = Literal[GROUPS]  # type: ignore[valid-type]
FiniteFloat = Annotated[float, Field(allow_inf_nan=False)]


def _each_once(names: list, suffix: str = "") -> list:
    """`names` if each is given once and ends in `suffix`, else ValueError."""
    wrong = [n for n in names if not n.endswith(suffix)]
    if wrong:
        raise ValueError(f"{wrong[0]!r} does not end in {suffix}")
    twice = [n for k, n in enumerate(names) if n in names[:k]]
    if twice:
        raise ValueError(f"{twice[0]!r} is listed twice")
    return names


class _Fixed(BaseModel):
    """A part of the file the twin writes whole: no field more or less."""

    model_config = ConfigDict(strict=True, extra="forbid")


class _Open(BaseModel):
    """A record kept for the report: the fields it reads are typed, others kept."""

    model_config = ConfigDict(strict=True, extra="allow")


class Features(_Fixed):
    """`FeatureSpec.to_json`."""

    sensors: list[str] = Field(min_length=1)
    reference_C: list[FiniteFloat]
    taus_min: list[Annotated[float, Field(gt=0, allow_inf_nan=False)]] = Field(min_length=1)
    groups: list[GroupName] = Field(min_length=1)

    @field_validator("sensors")
    @classmethod
    def _sensors(cls, names: list[str]) -> list[str]:
        return _each_once(names, TEMPERATURE_SUFFIX)

    @field_validator("groups")
    @classmethod
    def _groups(cls, names: list[str]) -> list[str]:
        return _each_once(names)

    @model_validator(mode="after")
    def _one_reference_per_sensor(self) -> Features:
        if len(self.reference_C) != len(self.sensors):
            raise ValueError(f"{len(self.reference_C)} reference temperatures (reference_C) "
                             f"for {len(self.sensors)} sensors")
        return self


WIDTHS = {"conformal": "half_width_um", "scaled_posterior": "factor"}
"""The interval kinds (`twin.drift.intervals.interval_rule`) and the list each one holds."""


class OperatingRange(_Fixed):
    """`twin.drift.extrapolation.OperatingRange.to_json`: a range per feature named."""

    features: list[str] = Field(min_length=1)
    lo: list[FiniteFloat]
    hi: list[FiniteFloat]
    stopped_lo: list[FiniteFloat] | None = None
    stopped_hi: list[FiniteFloat] | None = None
    state_features: list[str] | None = None
    stopped_state_lo: list[FiniteFloat] | None = None
    stopped_state_hi: list[FiniteFloat] | None = None
    state_span: list[Annotated[float, Field(ge=0, allow_inf_nan=False)]] | None = None

    @field_validator("features")
    @classmethod
    def _features(cls, names: list[str]) -> list[str]:
        return _each_once(names)

    @field_validator("state_features")
    @classmethod
    def _state_features(cls, names: list[str] | None) -> list[str] | None:
        return None if names is None else _each_once(names)

    @model_validator(mode="after")
    def _one_range_per_feature(self) -> OperatingRange:
        if not len(self.lo) == len(self.hi) == len(self.features):
            raise ValueError(f"{len(self.lo)} lower (lo) and {len(self.hi)} upper (hi) ends "
                             f"for {len(self.features)} features")
        if any(h < lo for lo, h in zip(self.lo, self.hi, strict=True)):
            raise ValueError("an upper end (hi) below its lower end (lo)")
        if (self.stopped_lo is None) != (self.stopped_hi is None):
            raise ValueError("the stopped rows' range needs both ends (stopped_lo, stopped_hi)")
        if self.stopped_lo is not None and self.stopped_hi is not None:
            if not len(self.stopped_lo) == len(self.stopped_hi) == len(self.features):
                raise ValueError(f"{len(self.stopped_lo)} lower (stopped_lo) and "
                                 f"{len(self.stopped_hi)} upper (stopped_hi) ends for "
                                 f"{len(self.features)} features")
            if any(h < lo for lo, h in zip(self.stopped_lo, self.stopped_hi, strict=True)):
                raise ValueError("an upper end (stopped_hi) below its lower end (stopped_lo)")
        state = (self.state_features, self.stopped_state_lo, self.stopped_state_hi)
        if any(v is None for v in state) and not all(v is None for v in state):
            raise ValueError("the stopped rows' thermal state needs its features and both "
                             "ends (state_features, stopped_state_lo, stopped_state_hi)")
        if self.state_span is not None and self.state_features is None:
            raise ValueError("spans of a thermal state (state_span) without its features "
                             "and ends (state_features, stopped_state_lo, stopped_state_hi)")
        if self.state_features is not None and self.stopped_lo is None:
            raise ValueError("a thermal state of the stopped rows (state_features) without "
                             "their range (stopped_lo, stopped_hi)")
        if (self.state_features is not None and self.stopped_state_lo is not None
                and self.stopped_state_hi is not None):
            if not (len(self.stopped_state_lo) == len(self.stopped_state_hi)
                    == len(self.state_features)):
                raise ValueError(f"{len(self.stopped_state_lo)} lower (stopped_state_lo) and "
                                 f"{len(self.stopped_state_hi)} upper (stopped_state_hi) ends "
                                 f"for {len(self.state_features)} state_features")
            if any(h < lo for lo, h in zip(self.stopped_state_lo, self.stopped_state_hi,
                                           strict=True)):
                raise ValueError("an upper end (stopped_state_hi) below its lower end "
                                 "(stopped_state_lo)")
            if self.state_span is not None and len(self.state_span) != len(self.state_features):
                raise ValueError(f"{len(self.state_span)} spans (state_span) for "
                                 f"{len(self.state_features)} state_features")
            twice = set(self.features) & set(self.state_features)
            if twice:
                raise ValueError(f"{sorted(twice)[0]!r} is both an operating and a state "
                                 "feature")
        return self


class Interval(_Fixed):
    """`interval_rule`: conformal half-widths (µm) or the posterior σ's factor, per target,
    and (files written since the band widens beyond the training range) the gain and the
    training rows' operating range (since stopped rows are held against their thermal
    state too, with the stopped rows' range of the temperature features, and since then
    with the features' span over every training row, the unit of a stop's excess).
    One model, not a union tagged by `kind`: pydantic would put the tag in the field's path
    (`interval.conformal.half_width_um`), which names no key of the file."""

    kind: Literal[tuple(WIDTHS)]  # type: ignore[valid-type]
    half_width_um: list[Annotated[float, Field(ge=0, allow_inf_nan=False)]] | None = None
    factor: list[Annotated[float, Field(ge=1, allow_inf_nan=False)]] | None = None
    extrapolation_gain: Annotated[float, Field(ge=0, allow_inf_nan=False)] | None = None
    operating_range: OperatingRange | None = None

    @model_validator(mode="after")
    def _widths_of_its_kind(self) -> Interval:
        if getattr(self, WIDTHS[self.kind]) is None:
            raise ValueError(f"kind {self.kind!r} needs {WIDTHS[self.kind]}")
        other = [n for n in WIDTHS.values() if n != WIDTHS[self.kind] and getattr(self, n)
                 is not None]
        if other:
            raise ValueError(f"kind {self.kind!r} takes no {other[0]}")
        return self

    @property
    def widths(self) -> tuple[str, list[float]]:
        """(field, the per-target list)."""
        name = WIDTHS[self.kind]
        return f"interval.{name}", getattr(self, name)


class MethodScore(_Open):
    """One method's time-blocked validation (NaN allowed: a score may be undefined)."""

    rmse_um: dict[str, float]
    mean_rmse_um: float
    coverage_90_pct: dict[str, float]


class Validation(_Open):
    blocks: int = Field(ge=1)
    chosen: MethodName
    methods: dict[MethodName, MethodScore]


class RankedSensor(_Open):
    sensor: str
    mean_grade: float
    cluster: int
    representative: bool


class Ranking(_Open):
    sensors: list[RankedSensor]


class Metadata(_Open):
    """What the fit recorded; the report reads the ranking and the validation."""

    ranking: Ranking | None = None
    validation: Validation | None = None


class ModelDocument(_Fixed):
    """The model file's JSON (`save_drift_model`)."""

    format: Literal["spindle-twin-drift"]
    version: Literal[1]
    method: MethodName
    targets: list[str] = Field(min_length=1)
    features: Features
    interval: Interval
    metadata: Metadata = Metadata()
    sha256: str
    metadata_sha256: str | None = None

    @field_validator("targets")
    @classmethod
    def _targets(cls, names: list[str]) -> list[str]:
        return _each_once(names, DISPLACEMENT_SUFFIX)

    def per_target_problem(self) -> tuple[str, str] | None:
        """(field, what is wrong) where a per-target list does not match `targets`."""
        p = len(self.targets)
        name, widths = self.interval.widths
        if len(widths) != p:
            return name, f"{len(widths)} value{'s' * (len(widths) != 1)} for {p} targets"
        methods = self.metadata.validation.methods if self.metadata.validation else {}
        for method, score in methods.items():
            for table in ("rmse_um", "coverage_90_pct"):
                missing = [t for t in self.targets if t not in getattr(score, table)]
                if missing:
                    return (f"metadata.validation.methods.{method}.{table}",
                            f"no value for target {missing[0]!r}")
        return None
