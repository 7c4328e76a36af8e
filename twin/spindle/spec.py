"""The spindle spec: geometry, materials, bearings, motor, coolant, convection, sensors.

A TOML file (the bundled one is `meshes/reference_spindle.toml`) read into pydantic
models.  Every dimension carries its unit in its name (`_mm`, `_W`, `_rpm`, `_C`, `_N`,
`_GPa`, `_per_K`); lengths are millimetres in the spec and metres in the FEM.

The geometry is a list of axis-aligned rectangles in the (r, z) half-plane (`[[parts]]`),
each belonging to a named region; z increases towards the spindle nose.  Coolant channels
(`[[coolant_channels]]`) are voids cut out of the parts.  Regions, boundaries and the two
contact interfaces are named in the spec; boundary names are the keys of `[convection]`
(the mesher assigns every outer facet to one of `BOUNDARY_NAMES`).

`load_spec(path)` validates everything it can without meshing: positive sizes, parts that
do not overlap, regions/materials that exist, sensors inside the body, bearing regions
that fit together.  Any problem raises a `twin.errors.TomlError` naming the file, the line
and the key (e.g. `parts[3].r_outer_mm`).
"""

from __future__ import annotations

import math
import re
from pathlib import Path
from typing import Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator

from twin.contract import SENSOR_NAMES
from twin.data import bundled_path
from twin.paths import read_toml, toml_error, toml_validation_error

DEFAULT_SPEC_PATH = bundled_path("meshes", "reference_spindle.toml").resolve()
"""The bundled reference spindle (package data, `twin.data`)."""

#: every boundary facet of the mesh gets one of these names (see twin/spindle/mesher.py)
BOUNDARY_NAMES = (
    "axis",
    "coolant",
    "air_gap_rotor",
    "air_gap_stator",
    "rotor_end_front",
    "rotor_end_rear",
    "nose_face",
    "nose_outer",
    "shaft_rear",
    "shaft_internal",
    "housing_outer",
    "internal_air",
    "mount",
)
PROBE_NAMES = ("nose_axial", "nose_radial")

_TOL_MM = 1e-9


class _Strict(BaseModel):
    # as a scenario's (twin.plant.scenario): TOML has typed values, so `true` or "1.2"
    # where a number belongs is a slip lax parsing would read as 1.0 and 1.2, and `inf` or
    # `nan` is no dimension, property or coefficient (inf passed every `gt=0`)
    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False, strict=True)


class SpindleInfo(_Strict):
    name: str
    max_speed_rpm: float = Field(gt=0)
    assembly_temperature_C: float = 20.0
    rotating_regions: list[str] = Field(min_length=1)


MIN_ELEMENT_SIZE_MM = 1.4
"""Finest element size a mesh may have (`element_size_mm` times a command's size factor):
the reference spindle's 7 mm at `--size-factor` 0.2, some 25 times its elements.  A spec
without a floor meshed on without bound: `element_size_mm = 0.3` (a size typed in cm, or
0.007 in m) left `twin simulate` still meshing after minutes."""

MAX_ELEMENTS_ACROSS = 10
"""Most elements `min_elements_across` may ask for across a part's thinnest side."""


class MeshOptions(_Strict):
    element_size_mm: float = Field(ge=MIN_ELEMENT_SIZE_MM)
    #: at least this many elements across the thinnest side of every part
    min_elements_across: int = Field(default=2, ge=1, le=MAX_ELEMENTS_ACROSS)


class MaterialSpec(_Strict):
    conductivity_W_per_mK: float = Field(gt=0)
    density_kg_per_m3: float = Field(gt=0)
    specific_heat_J_per_kgK: float = Field(gt=0)
    youngs_modulus_GPa: float = Field(gt=0)
    poisson_ratio: float = Field(gt=-1.0, lt=0.5)
    expansion_per_K: float


class Rectangle(_Strict):
    r_inner_mm: float = Field(ge=0)
    r_outer_mm: float = Field(gt=0)
    z_start_mm: float
    z_end_mm: float

    @model_validator(mode="after")
    def _ordered(self) -> Rectangle:
        if self.r_outer_mm <= self.r_inner_mm:
            raise ValueError("r_outer_mm must be larger than r_inner_mm")
        if self.z_end_mm <= self.z_start_mm:
            raise ValueError("z_end_mm must be larger than z_start_mm")
        return self

    def overlap_area_mm2(self, other: Rectangle) -> float:
        dr = min(self.r_outer_mm, other.r_outer_mm) - max(self.r_inner_mm, other.r_inner_mm)
        dz = min(self.z_end_mm, other.z_end_mm) - max(self.z_start_mm, other.z_start_mm)
        return max(dr, 0.0) * max(dz, 0.0)

    def contains(self, r_mm: float, z_mm: float, *, closed: bool = True) -> bool:
        tol = _TOL_MM if closed else -_TOL_MM
        return (self.r_inner_mm - tol <= r_mm <= self.r_outer_mm + tol
                and self.z_start_mm - tol <= z_mm <= self.z_end_mm + tol)

    @property
    def volume_m3(self) -> float:
        return (math.pi * (self.r_outer_mm**2 - self.r_inner_mm**2)
                * (self.z_end_mm - self.z_start_mm) * 1e-9)

    def overlap_volume_m3(self, other: Rectangle) -> float:
        """Revolved volume of the intersection of two rectangles."""
        r0, r1 = max(self.r_inner_mm, other.r_inner_mm), min(self.r_outer_mm, other.r_outer_mm)
        z0, z1 = max(self.z_start_mm, other.z_start_mm), min(self.z_end_mm, other.z_end_mm)
        if r1 <= r0 or z1 <= z0:
            return 0.0
        return math.pi * (r1**2 - r0**2) * (z1 - z0) * 1e-9


class PartSpec(Rectangle):
    name: str
    region: str


class ChannelSpec(Rectangle):
    pass


class PointSpec(_Strict):
    r_mm: float = Field(ge=0)
    z_mm: float


class BearingSpec(_Strict):
    """An angular-contact bearing: its three regions, its seat and the friction data."""

    inner_ring: str
    rolling_band: str
    outer_ring: str
    sleeve: str
    interface: str
    f0: float = Field(gt=0)
    lubricant_nu40_mm2_s: float = Field(gt=0)
    lubricant_nu100_mm2_s: float = Field(gt=0)
    preload_N: float = Field(ge=0)
    radial_load_N: float = Field(ge=0)
    contact_angle_deg: float = Field(gt=0, lt=90)
    static_load_rating_N: float = Field(gt=0)
    static_axial_factor_Y0: float = Field(default=0.46, gt=0)
    #: combined RMS roughness √(r1² + r2²) of ring and seat, µm (Eq. 4)
    roughness_um: float = Field(gt=0)
    #: radial interference of the outer ring in its sleeve at assembly, µm
    fit_interference_um: float = Field(gt=0)
    min_pressure_fraction: float = Field(default=0.05, gt=0, le=1)


class MotorSpec(_Strict):
    rotor: str
    stator: str
    rated_power_W: float = Field(gt=0)
    base_speed_rpm: float = Field(gt=0)
    efficiency: float = Field(default=0.9, gt=0, le=1)
    heat_share: float = Field(default=0.88, ge=0, le=1)
    #: share of rated power drawn at the operating point (idling thermal test)
    load_fraction: float = Field(ge=0)


class CoolantSpec(_Strict):
    flow_L_min: float = Field(ge=0)
    parallel_channels: int = Field(default=1, ge=1)
    conductivity_W_per_mK: float = Field(default=0.6, gt=0)
    viscosity_m2_s: float = Field(default=0.66e-6, gt=0)
    prandtl: float = Field(default=7.0, gt=0)


ConvectionModel = Literal[
    "coolant", "natural", "air_gap", "rotating_cylinder", "rotating_disk", "fixed"
]
_CONVECTION_NEEDS = {
    "coolant": (),
    "natural": ("length_mm",),
    "air_gap": ("diameter_mm", "gap_mm"),
    "rotating_cylinder": ("diameter_mm",),
    "rotating_disk": ("radius_mm",),
    "fixed": ("h_W_per_m2K",),
}


class ConvectionSpec(_Strict):
    """How the film coefficient of one boundary is computed (twin.physics.convection)."""

    model: ConvectionModel
    #: bulk temperature the film exchanges with
    fluid: Literal["ambient", "coolant"] = "ambient"
    h_W_per_m2K: float | None = Field(default=None, ge=0)
    length_mm: float | None = Field(default=None, gt=0)
    diameter_mm: float | None = Field(default=None, gt=0)
    radius_mm: float | None = Field(default=None, gt=0)
    gap_mm: float | None = Field(default=None, gt=0)
    orientation: Literal["vertical", "horizontal_up", "horizontal_down",
                         "horizontal_cylinder"] = "horizontal_cylinder"
    #: surface-to-air temperature difference assumed for natural convection, K
    delta_T_K: float = Field(default=5.0, ge=0)
    emissivity: float = Field(default=0.0, ge=0, le=1)
    #: floor (still air, the shaft at standstill), W/m²K
    min_h_W_per_m2K: float = Field(default=0.0, ge=0)

    @model_validator(mode="after")
    def _has_parameters(self) -> ConvectionSpec:
        missing = [f for f in _CONVECTION_NEEDS[self.model] if getattr(self, f) is None]
        if missing:
            raise ValueError(f"model {self.model!r} needs {', '.join(missing)}")
        return self


class StructureSpec(_Strict):
    """Structural supports: u_r = 0 on the axis, u_z = 0 on the mount face."""

    mount_z_mm: float
    mount_r_min_mm: float = Field(ge=0)
    mount_r_max_mm: float = Field(gt=0)


class SpindleSpec(_Strict):
    spindle: SpindleInfo
    mesh: MeshOptions
    materials: dict[str, MaterialSpec] = Field(min_length=1)
    regions: dict[str, str] = Field(min_length=1)
    parts: list[PartSpec] = Field(min_length=1)
    coolant_channels: list[ChannelSpec] = Field(default_factory=list)
    bearings: dict[Literal["front", "rear"], BearingSpec]
    motor: MotorSpec
    coolant: CoolantSpec
    convection: dict[str, ConvectionSpec]
    structure: StructureSpec
    sensors: dict[str, PointSpec]
    probes: dict[str, PointSpec]

    # ------------------------------------------------------------ derived data
    def region_parts(self, region: str) -> list[PartSpec]:
        return [p for p in self.parts if p.region == region]

    def region_volume_m3(self, region: str) -> float:
        """Revolved volume of a region: its rectangles minus the coolant channels cut out
        of them (exact for the linear mesh too)."""
        return sum(p.volume_m3 - sum(p.overlap_volume_m3(c) for c in self.coolant_channels)
                   for p in self.region_parts(region))

    def region_box(self, region: str) -> Rectangle:
        parts = self.region_parts(region)
        return Rectangle(
            r_inner_mm=min(p.r_inner_mm for p in parts),
            r_outer_mm=max(p.r_outer_mm for p in parts),
            z_start_mm=min(p.z_start_mm for p in parts),
            z_end_mm=max(p.z_end_mm for p in parts),
        )

    def bearing_regions(self, side: str) -> tuple[str, str, str]:
        b = self.bearings[side]
        return (b.inner_ring, b.rolling_band, b.outer_ring)

    def bearing_volume_m3(self, side: str) -> float:
        return sum(self.region_volume_m3(r) for r in self.bearing_regions(side))

    def pitch_diameter_mm(self, side: str) -> float:
        band = self.region_box(self.bearings[side].rolling_band)
        return band.r_inner_mm + band.r_outer_mm

    def material_of(self, region: str) -> MaterialSpec:
        return self.materials[self.regions[region]]

    def interfaces(self) -> tuple[str, ...]:
        return tuple(self.bearings[s].interface for s in ("front", "rear"))

    def inside_body(self, r_mm: float, z_mm: float) -> bool:
        """True if the point lies in a part (boundary included) and not in a channel."""
        in_part = any(p.contains(r_mm, z_mm) for p in self.parts)
        in_void = any(c.contains(r_mm, z_mm, closed=False) for c in self.coolant_channels)
        return in_part and not in_void

    # --------------------------------------------------------------- checks
    @model_validator(mode="after")
    def _consistent(self) -> SpindleSpec:
        errors: list[tuple[str, str]] = []
        for region, material in self.regions.items():
            if material not in self.materials:
                errors.append((f"regions.{region}", f"unknown material {material!r}"))
        for i, part in enumerate(self.parts):
            if part.region not in self.regions:
                errors.append((f"parts[{i}].region", f"unknown region {part.region!r}"))
        for region in self.regions:
            if not self.region_parts(region):
                errors.append((f"regions.{region}", "no part belongs to this region"))
        for i, a in enumerate(self.parts):
            for j in range(i + 1, len(self.parts)):
                if a.overlap_area_mm2(self.parts[j]) > 1e-6:
                    errors.append((f"parts[{j}]", f"part {self.parts[j].name!r} overlaps part "
                                   f"{a.name!r} (parts[{i}])"))
        for i, ch in enumerate(self.coolant_channels):
            corners = [(ch.r_inner_mm, ch.z_start_mm), (ch.r_outer_mm, ch.z_end_mm),
                       (ch.r_inner_mm, ch.z_end_mm), (ch.r_outer_mm, ch.z_start_mm)]
            if not all(any(p.contains(r, z) for p in self.parts) for r, z in corners):
                errors.append((f"coolant_channels[{i}]", "channel is not inside the parts"))
        for name in self.spindle.rotating_regions:
            if name not in self.regions:
                errors.append(("spindle.rotating_regions", f"unknown region {name!r}"))
        for side, b in self.bearings.items():
            for field_name in ("inner_ring", "rolling_band", "outer_ring", "sleeve"):
                region = getattr(b, field_name)
                if region not in self.regions:
                    errors.append((f"bearings.{side}.{field_name}", f"unknown region {region!r}"))
            if b.lubricant_nu100_mm2_s >= b.lubricant_nu40_mm2_s:
                errors.append((f"bearings.{side}.lubricant_nu100_mm2_s",
                               "must be below lubricant_nu40_mm2_s (oil thins when hot)"))
        for name in ("front", "rear"):
            if name not in self.bearings:
                errors.append(("bearings", f"missing bearing {name!r}"))
        if ("front" in self.bearings and "rear" in self.bearings
                and self.bearings["front"].interface == self.bearings["rear"].interface):
            errors.append(("bearings.rear.interface", "front and rear need distinct interfaces"))
        for field_name in ("rotor", "stator"):
            if getattr(self.motor, field_name) not in self.regions:
                errors.append((f"motor.{field_name}", "unknown region "
                               f"{getattr(self.motor, field_name)!r}"))
        for name in BOUNDARY_NAMES:
            if name != "axis" and name not in self.convection:
                errors.append((f"convection.{name}", "missing film model for this boundary"))
        for name in self.convection:
            if name not in BOUNDARY_NAMES or name == "axis":
                errors.append((f"convection.{name}", "unknown boundary; known: "
                               + ", ".join(BOUNDARY_NAMES[1:])))
        for group, names in (("sensors", SENSOR_NAMES), ("probes", PROBE_NAMES)):
            table = getattr(self, group)
            for name in names:
                if name not in table:
                    errors.append((f"{group}.{name}", "missing"))
            for name, pt in table.items():
                if name not in names:
                    errors.append((f"{group}.{name}", f"unknown; expected {', '.join(names)}"))
                elif not self.inside_body(pt.r_mm, pt.z_mm):
                    errors.append((f"{group}.{name}", f"point (r={pt.r_mm}, z={pt.z_mm}) mm "
                                   "is outside the body"))
        if self.structure.mount_r_max_mm <= self.structure.mount_r_min_mm:
            errors.append(("structure.mount_r_max_mm", "must exceed mount_r_min_mm"))
        if errors:
            raise _SpecErrors(errors)
        self._check_bearings()
        return self

    def _check_bearings(self) -> None:
        errors = []
        for side, b in self.bearings.items():
            boxes = [self.region_box(r) for r in (b.inner_ring, b.rolling_band, b.outer_ring)]
            for outer, inner, label in ((boxes[1], boxes[0], "rolling_band"),
                                        (boxes[2], boxes[1], "outer_ring")):
                if abs(outer.r_inner_mm - inner.r_outer_mm) > 1e-6:
                    errors.append((f"bearings.{side}.{label}",
                                   "must sit directly on the ring inside it"))
            sleeve = self.region_box(b.sleeve)
            if abs(sleeve.r_inner_mm - boxes[2].r_outer_mm) > 1e-6:
                errors.append((f"bearings.{side}.sleeve",
                               "sleeve bore must equal the outer-ring diameter"))
        if errors:
            raise _SpecErrors(errors)


class _SpecErrors(ValueError):
    """Cross-field problems, each (field path, message); turned into TomlError."""

    def __init__(self, errors: list[tuple[str, str]]) -> None:
        self.errors = errors
        super().__init__("; ".join(f"{f}: {m}" for f, m in errors))


def _loc(path: str) -> tuple:
    """`parts[3].region` as a pydantic location, ('parts', 3, 'region')."""
    return tuple(int(index) if index else key
                 for index, key in re.findall(r"\[(\d+)\]|([^.\[\]]+)", path))


def parse_spec(data: dict, source: str = "<spec>", text: str | None = None) -> SpindleSpec:
    """Validate a spec given as a dict (e.g. parsed TOML); errors name the field, and with
    the TOML `text` its line."""
    try:
        return SpindleSpec.model_validate(data)
    except ValidationError as exc:
        cause = exc.errors()[0].get("ctx", {}).get("error")
        if not isinstance(cause, _SpecErrors):
            raise toml_validation_error(exc, text, source) from None
        field_name, message = cause.errors[0]
        raise toml_error(text, source, _loc(field_name), message,
                         len(cause.errors) - 1) from None


def load_spec(path: str | Path | None = None, *, option: str | None = None) -> SpindleSpec:
    """Read and validate a spindle spec TOML (None: the bundled reference spindle);
    `option`: the command-line option that named it (a file that cannot be read names it,
    as a scenario's names `--scenario`)."""
    path = Path(path) if path is not None else DEFAULT_SPEC_PATH
    text, data = read_toml(path, column=option)
    return parse_spec(data, str(path), text)
