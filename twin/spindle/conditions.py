"""Nominal boundary conditions of the spindle at an operating point.

    bc = nominal_conditions(model, speed_rpm=9000, ambient_C=25.3, coolant_C=None,
                            T_bearings_C=None, T_sleeves_C=None)
    loads = bc.to_thermal_loads()                      # twin.fem.ThermalLoads
    loads = bc.to_thermal_loads(H_front=1.7e6, R_rear=2e-4)   # a correction's values

`BoundaryConditions` holds the four quantities the twin corrects every 60 s — H_front,
H_rear (bearing heat, W/m³, applied uniformly to the bearing's inner ring, rolling band and
outer ring: the "bearing volume" of Eq. 1) and R_front, R_rear (outer ring / sleeve contact
resistance, m²K/W) — plus the motor heat per region (W/m³) and a film coefficient and
bulk temperature per boundary.  Physics in `twin.physics`; the spec supplies the data.

Temperatures: `T_bearings_C` is the bearing (outer ring) temperature used for the oil
viscosity and for the thermal expansion of the fit (Eq. 5); None means the spindle is at
ambient (a cold start).  It may be one value or (front, rear).  `T_sleeves_C` likewise for
the sleeves, defaulting to the bearing temperatures.  The coolant defaults to the ambient
temperature (a chiller tracking the room).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import Protocol

from twin.contract import OPERATING_TEMPERATURE_C
from twin.errors import InputError
from twin.fem import ThermalLoads
from twin.fem.linalg import kept
from twin.physics import (
    air_gap_h,
    bearing_heat_W,
    contact_resistance_initial,
    contact_resistance_thermal,
    coolant_h,
    fit_pressure_MPa,
    motor_heat_split_W,
    motor_loss_W,
    natural_convection_h,
    radiation_h,
    rotating_cylinder_h,
    rotating_disk_h,
)
from twin.physics.contact import harmonic_mean, thermal_interference_um
from twin.spindle.spec import BearingSpec, ConvectionSpec, SpindleSpec

SIDES = ("front", "rear")
KEPT_FILM_POINTS = 64  # operating points whose film coefficients SpecConstants keeps

FILM_GROUPS: dict[str, tuple[str, ...]] = {
    "coolant": ("coolant",),
    "housing": ("housing_outer", "mount"),
    "air_gap": ("air_gap_rotor", "air_gap_stator"),
    "rotor": ("rotor_end_front", "rotor_end_rear", "nose_face", "nose_outer", "shaft_rear",
              "shaft_internal", "internal_air"),
}
"""Convection boundaries grouped by the correlation that gives their film coefficient
(DESIGN.md, "Emulator inputs"): coolant = jacket channels; housing = outer housing and
mount; air_gap = rotor and stator gap faces; rotor = rotor ends, shaft ends, nose and
internal air.  A group's film coefficients are wrong together on a real spindle (one
correlation, one flow), so a model-form factor acts on a whole group."""


def film_group(boundary: str) -> str | None:
    """The FILM_GROUPS group of a convection boundary (None: in no group)."""
    for group, members in FILM_GROUPS.items():
        if boundary in members:
            return group
    return None


@dataclass(frozen=True)
class BoundaryConditions:
    """Thermal boundary conditions of one operating point (see the module doc)."""

    speed_rpm: float
    ambient_C: float
    coolant_C: float
    H_front: float  # W/m³
    H_rear: float  # W/m³
    R_front: float  # m²K/W
    R_rear: float  # m²K/W
    motor_heat: dict[str, float]  # region → W/m³
    convection: dict[str, tuple[float, float]]  # boundary → (h W/m²K, T∞ °C)
    bearing_regions: dict[str, tuple[str, ...]]  # side → regions carrying H
    interfaces: dict[str, str]  # side → interface name
    bearing_volume_m3: dict[str, float] = field(default_factory=dict)
    motor_volume_m3: dict[str, float] = field(default_factory=dict)
    coolant_boundaries: tuple[str, ...] = ()
    """The convection boundaries whose bulk temperature is the coolant inlet (the spec's
    `fluid = "coolant"`)."""

    def heat_W(self) -> dict[str, float]:
        """Heat generated per source, W (front/rear bearing, rotor, stator)."""
        out = {"front_bearing": self.H_front * self.bearing_volume_m3.get("front", math.nan),
               "rear_bearing": self.H_rear * self.bearing_volume_m3.get("rear", math.nan)}
        for region, q in self.motor_heat.items():
            out[region] = q * self.motor_volume_m3.get(region, math.nan)
        return out

    def scaled(self, factors: Mapping[str, float]) -> BoundaryConditions:
        """A copy with model-form factors applied: `motor` multiplies the motor heat,
        `film_<group>` the film coefficients of a FILM_GROUPS group (bulk temperatures stay).
        """
        films: dict[str, float] = {}
        for name, f in factors.items():
            group = name.removeprefix("film_")
            if name != "motor" and not (name.startswith("film_") and group in FILM_GROUPS):
                raise ValueError(f"unknown model-form factor {name!r}")
            if not (math.isfinite(f) and f > 0):
                raise ValueError(f"{name} factor must be a finite positive number, got {f!r}")
            if name != "motor":
                films[group] = float(f)
        motor = float(factors.get("motor", 1.0))
        convection = {b: (h * films.get(film_group(b) or "", 1.0), t_inf)
                      for b, (h, t_inf) in self.convection.items()}
        return replace(self, motor_heat={r: q * motor for r, q in self.motor_heat.items()},
                       convection=convection)

    def with_coolant(self, coolant_C: float) -> BoundaryConditions:
        """A copy with the coolant inlet at `coolant_C` (°C): the bulk temperature of every
        coolant boundary (film coefficients stay)."""
        coolant = float(coolant_C)
        if not math.isfinite(coolant):
            raise ValueError(f"coolant_C must be a finite temperature, got {coolant_C!r}")
        convection = {b: ((h, coolant) if b in self.coolant_boundaries else (h, t_inf))
                      for b, (h, t_inf) in self.convection.items()}
        return replace(self, coolant_C=coolant, convection=convection)

    def with_values(self, **values: float) -> BoundaryConditions:
        """A copy with some of H_front, H_rear, R_front, R_rear replaced."""
        return replace(self, **_checked(values))

    def to_thermal_loads(self, H_front: float | None = None, H_rear: float | None = None,
                         R_front: float | None = None,
                         R_rear: float | None = None) -> ThermalLoads:
        """twin.fem.ThermalLoads of these conditions, with optional overrides."""
        given = {"H_front": H_front, "H_rear": H_rear, "R_front": R_front, "R_rear": R_rear}
        over = _checked({k: v for k, v in given.items() if v is not None})
        H = {"front": over.get("H_front", self.H_front), "rear": over.get("H_rear", self.H_rear)}
        R = {"front": over.get("R_front", self.R_front), "rear": over.get("R_rear", self.R_rear)}
        sources = dict(self.motor_heat)
        for side in SIDES:
            for region in self.bearing_regions[side]:
                sources[region] = sources.get(region, 0.0) + H[side]
        return ThermalLoads(
            sources=sources,
            convection=dict(self.convection),
            contact_resistance={self.interfaces[s]: R[s] for s in SIDES},
        )


def _checked(values: dict[str, float]) -> dict[str, float]:
    out = {}
    for name, value in values.items():
        if name not in ("H_front", "H_rear", "R_front", "R_rear"):
            raise ValueError(f"unknown boundary-condition value {name!r}")
        value = float(value)
        if not math.isfinite(value) or value < 0 or (name.startswith("R") and value == 0):
            kind = "positive" if name[0] == "R" else "non-negative"
            raise ValueError(f"{name} must be a finite {kind} number, got {value!r}")
        out[name] = value
    return out


def check_operating_point(spec: SpindleSpec, speed_rpm: float, ambient_C: float,
                          coolant_C: float | None = None) -> None:
    """InputError naming the field if the operating point is impossible for the spec."""
    if not math.isfinite(speed_rpm) or speed_rpm < 0:
        raise InputError(f"speed_rpm must be a non-negative number, got {speed_rpm}",
                         column="speed_rpm")
    if speed_rpm > spec.spindle.max_speed_rpm:
        raise InputError(f"speed_rpm {speed_rpm:g} exceeds the spindle's limit "
                         f"{spec.spindle.max_speed_rpm:g} rpm (spindle.max_speed_rpm)",
                         column="speed_rpm")
    for name, value in (("ambient_C", ambient_C), ("coolant_C", coolant_C)):
        if value is None:
            continue
        lo, hi = OPERATING_TEMPERATURE_C
        if not math.isfinite(value) or not lo <= value <= hi:
            raise InputError(f"{name} must be a temperature between {lo:g} and {hi:g} °C, "
                             f"got {value}", column=name)


def _pair(value: float | tuple[float, float] | None, default: float) -> dict[str, float]:
    if value is None:
        return {"front": default, "rear": default}
    if isinstance(value, (int, float)):
        return {"front": float(value), "rear": float(value)}
    front, rear = value
    return {"front": float(front), "rear": float(rear)}


def film_coefficient(conv: ConvectionSpec, spec: SpindleSpec, speed_rpm: float,
                     ambient_C: float) -> float:
    """h [W/m²K] of one boundary from its spec entry (twin.physics.convection)."""
    mm = 1e-3
    if conv.model == "coolant":
        ch = spec.coolant_channels[0]
        c = spec.coolant
        h = coolant_h(c.flow_L_min, ch.z_end_mm - ch.z_start_mm, ch.r_outer_mm - ch.r_inner_mm,
                      parallel_channels=c.parallel_channels,
                      conductivity_W_per_mK=c.conductivity_W_per_mK,
                      viscosity_m2_s=c.viscosity_m2_s, prandtl=c.prandtl)
    elif conv.model == "natural":
        surface = ambient_C + conv.delta_T_K
        h = natural_convection_h(conv.delta_T_K, conv.length_mm * mm,
                                 orientation=conv.orientation, surface_C=surface)
        h += radiation_h(surface, ambient_C, conv.emissivity) if conv.emissivity > 0 else 0.0
    elif conv.model == "air_gap":
        h = air_gap_h(speed_rpm, conv.diameter_mm * mm, conv.gap_mm * mm)
    elif conv.model == "rotating_cylinder":
        h = rotating_cylinder_h(speed_rpm, conv.diameter_mm * mm)
    elif conv.model == "rotating_disk":
        h = rotating_disk_h(speed_rpm, conv.radius_mm * mm)
    else:  # fixed
        h = float(conv.h_W_per_m2K)
    return max(h, conv.min_h_W_per_m2K)


@dataclass(frozen=True)
class BearingConstants:
    """What Eq. 1 and Eq. 4/5 take from a bearing's spec apart from the operating point:
    its volume and pitch diameter, and the fit of its outer ring in the sleeve at assembly
    (pressure P0, resistance R0, Lamé stiffness per µm of interference)."""

    spec: BearingSpec
    volume_m3: float
    pitch_diameter_mm: float
    interface_radius_mm: float  # outer ring's outer radius
    ring_expansion_per_K: float
    sleeve_expansion_per_K: float
    assembly_C: float
    p0_MPa: float
    r0_m2K_per_W: float
    stiffness_MPa_per_um: float

    @classmethod
    def of(cls, spec: SpindleSpec, side: str) -> BearingConstants:
        b = spec.bearings[side]
        ring, sleeve = spec.material_of(b.outer_ring), spec.material_of(b.sleeve)
        ring_box, sleeve_box = spec.region_box(b.outer_ring), spec.region_box(b.sleeve)
        modulus = harmonic_mean(ring.youngs_modulus_GPa, sleeve.youngs_modulus_GPa)
        conductivity = harmonic_mean(ring.conductivity_W_per_mK, sleeve.conductivity_W_per_mK)
        radii = (ring_box.r_inner_mm, ring_box.r_outer_mm, sleeve_box.r_outer_mm)
        p0 = fit_pressure_MPa(b.fit_interference_um, *radii, modulus)
        return cls(
            spec=b, volume_m3=spec.bearing_volume_m3(side),
            pitch_diameter_mm=spec.pitch_diameter_mm(side),
            interface_radius_mm=ring_box.r_outer_mm,
            ring_expansion_per_K=ring.expansion_per_K,
            sleeve_expansion_per_K=sleeve.expansion_per_K,
            assembly_C=spec.spindle.assembly_temperature_C, p0_MPa=p0,
            r0_m2K_per_W=contact_resistance_initial(b.roughness_um, conductivity, p0, modulus),
            stiffness_MPa_per_um=fit_pressure_MPa(1.0, *radii, modulus),
        )

    def contact_resistance(self, ring_C: float, sleeve_C: float) -> float:
        """R [m²K/W] of the outer ring / sleeve fit: Eq. 4 at the assembly pressure,
        corrected by Eq. 5 for the thermal expansion of ring and sleeve."""
        delta_um = thermal_interference_um(self.interface_radius_mm, ring_C - self.assembly_C,
                                           sleeve_C - self.assembly_C,
                                           self.ring_expansion_per_K,
                                           self.sleeve_expansion_per_K)
        return contact_resistance_thermal(
            self.r0_m2K_per_W, self.p0_MPa, self.stiffness_MPa_per_um * delta_um,
            min_pressure_fraction=self.spec.min_pressure_fraction)

    def heat_density(self, speed_rpm: float, temperature_C: float) -> float:
        """H [W/m³]: Palmgren power over the bearing volume (Eq. 1)."""
        b = self.spec
        power = bearing_heat_W(
            speed_rpm, temperature_C, pitch_diameter_mm=self.pitch_diameter_mm, f0=b.f0,
            nu40_mm2_s=b.lubricant_nu40_mm2_s, nu100_mm2_s=b.lubricant_nu100_mm2_s,
            preload_N=b.preload_N, radial_load_N=b.radial_load_N,
            contact_angle_deg=b.contact_angle_deg, static_load_rating_N=b.static_load_rating_N,
            static_axial_factor_Y0=b.static_axial_factor_Y0,
        )
        return power / self.volume_m3


@dataclass(frozen=True)
class SpecConstants:
    """The parts of the nominal conditions that follow from the spec alone (bearing and
    motor volumes, pitch diameters, the fits at assembly): computed once per spec
    (`SpindleModel.constants`) instead of on every solver step that re-evaluates the
    bearing values."""

    bearings: dict[str, BearingConstants]
    motor_volume_m3: dict[str, float]
    films: dict[tuple[str, str], dict[str, float]] = field(
        default_factory=dict, compare=False, repr=False)
    """The film coefficients at each (speed, film ambient) seen, by their exact bits (hex),
    at most `KEPT_FILM_POINTS` (`nominal_conditions`; the oldest dropped): they depend on
    the spec and those two only, and a replay re-evaluates the conditions every solver step
    at one speed and one film ambient for minutes."""

    @classmethod
    def of(cls, spec: SpindleSpec) -> SpecConstants:
        m = spec.motor
        return cls(bearings={s: BearingConstants.of(spec, s) for s in SIDES},
                   motor_volume_m3={m.rotor: spec.region_volume_m3(m.rotor),
                                    m.stator: spec.region_volume_m3(m.stator)})


class SpecWithConstants(Protocol):
    """What these functions read of a twin.spindle.model.SpindleModel (which imports this
    module, so it is not named here): its spec and the SpecConstants computed with it."""

    @property
    def spec(self) -> SpindleSpec: ...

    @property
    def constants(self) -> SpecConstants: ...


def _spec_and_constants(
    model: SpecWithConstants | SpindleSpec,
) -> tuple[SpindleSpec, SpecConstants]:
    """A SpindleModel's spec and its constants (computed once, with the model); a bare
    SpindleSpec's, computed now."""
    if isinstance(model, SpindleSpec):
        return model, SpecConstants.of(model)
    return model.spec, model.constants


def contact_resistance(spec: SpindleSpec, side: str, ring_C: float, sleeve_C: float) -> float:
    """R [m²K/W] of a bearing's outer ring / sleeve fit: Eq. 4 at the assembly pressure,
    corrected by Eq. 5 for the thermal expansion of ring and sleeve (twin.physics.contact)."""
    return BearingConstants.of(spec, side).contact_resistance(ring_C, sleeve_C)


def bearing_heat_density(spec: SpindleSpec, side: str, speed_rpm: float,
                         temperature_C: float) -> float:
    """H [W/m³] of a bearing: Palmgren power over the bearing volume (Eq. 1)."""
    return BearingConstants.of(spec, side).heat_density(speed_rpm, temperature_C)


def bearing_values(model: SpecWithConstants | SpindleSpec, speed_rpm: float,
                   T_bearings_C: float | tuple[float, float],
                   T_sleeves_C: float | tuple[float, float] | None = None) -> dict[str, float]:
    """Nominal H_front, H_rear (Eq. 1, W/m³) and R_front, R_rear (Eq. 4/5, m²K/W) at the
    given outer-ring (and sleeve; default: the ring's) temperatures, °C.  Pass the
    SpindleModel where it is called per step: its constants are computed once."""
    return _bearing_values(_spec_and_constants(model)[1], speed_rpm, T_bearings_C,
                           T_sleeves_C)


def _bearing_values(constants: SpecConstants, speed_rpm: float,
                    T_bearings_C: float | tuple[float, float],
                    T_sleeves_C: float | tuple[float, float] | None) -> dict[str, float]:
    T_b = _pair(T_bearings_C, math.nan)
    T_s = _pair(T_sleeves_C, math.nan)
    T_s = {k: (T_b[k] if math.isnan(v) else v) for k, v in T_s.items()}
    bearings = constants.bearings
    out = {f"H_{s}": bearings[s].heat_density(speed_rpm, T_b[s]) for s in SIDES}
    out.update({f"R_{s}": bearings[s].contact_resistance(T_b[s], T_s[s]) for s in SIDES})
    return out


def bearing_values_at(model: SpecWithConstants | SpindleSpec, speed_rpm: float,
                      sensors_C: Sequence[float]) -> dict[str, float]:
    """`bearing_values` at a spindle's own readings T1..T4 (SENSOR_NAMES order: T1 front
    outer ring, T2 its sleeve, T3 rear outer ring, T4 its sleeve): the nominal bearing heat
    and contact resistance as they follow the rings, re-evaluated every solver step by the
    open-loop run (`twin.spindle.simulate`) and the emulated spindle (`twin.plant`)."""
    return bearing_values(model, speed_rpm, (float(sensors_C[0]), float(sensors_C[2])),
                          (float(sensors_C[1]), float(sensors_C[3])))


def nominal_conditions(model: SpecWithConstants | SpindleSpec, speed_rpm: float,
                       ambient_C: float,
                       coolant_C: float | None = None,
                       T_bearings_C: float | tuple[float, float] | None = None,
                       T_sleeves_C: float | tuple[float, float] | None = None,
                       film_ambient_C: float | None = None,
                       ) -> BoundaryConditions:
    """Nominal boundary conditions at an operating point.

    `model`: a SpindleModel or a SpindleSpec (only the spec is used, and the constants a
    SpindleModel holds of it; volumes come from the spec's rectangles, which the linear
    mesh reproduces exactly).
    `film_ambient_C`: the ambient at which the natural-convection and radiation film
    coefficients are evaluated (default: `ambient_C`, which is always the sink temperature).
    """
    spec, constants = _spec_and_constants(model)
    check_operating_point(spec, speed_rpm, ambient_C, coolant_C)
    coolant = ambient_C if coolant_C is None else float(coolant_C)
    values = _bearing_values(constants, speed_rpm,
                             ambient_C if T_bearings_C is None else T_bearings_C, T_sleeves_C)

    m = spec.motor
    loss = motor_loss_W(speed_rpm, rated_power_W=m.rated_power_W,
                        base_speed_rpm=m.base_speed_rpm, load_fraction=m.load_fraction,
                        efficiency=m.efficiency, heat_share=m.heat_share)
    split = motor_heat_split_W(loss)
    volumes = dict(constants.motor_volume_m3)
    motor_heat = {m.rotor: split["rotor"] / volumes[m.rotor],
                  m.stator: split["stator"] / volumes[m.stator]}

    film_ambient = ambient_C if film_ambient_C is None else film_ambient_C
    films = kept(constants.films, (float(speed_rpm).hex(), float(film_ambient).hex()),
                 lambda: {name: film_coefficient(conv, spec, speed_rpm, film_ambient)
                          for name, conv in spec.convection.items()}, KEPT_FILM_POINTS)
    convection = {name: (films[name], coolant if conv.fluid == "coolant" else float(ambient_C))
                  for name, conv in spec.convection.items()}

    return BoundaryConditions(
        speed_rpm=float(speed_rpm), ambient_C=float(ambient_C), coolant_C=coolant, **values,
        motor_heat=motor_heat, convection=convection,
        bearing_regions={s: spec.bearing_regions(s) for s in SIDES},
        interfaces={s: spec.bearings[s].interface for s in SIDES},
        bearing_volume_m3={s: constants.bearings[s].volume_m3 for s in SIDES},
        motor_volume_m3=volumes,
        coolant_boundaries=tuple(name for name, conv in spec.convection.items()
                                 if conv.fluid == "coolant"),
    )
