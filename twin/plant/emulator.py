"""The emulated spindle: a truth FEM run on a finer mesh, seen through real sensors.

    run = synthesize(speed_rpm=9000, minutes=30, ambient_C=25.3, seed=1)
    run_path, truth_path = write_synth(run, Path("out/run.csv"))

The truth differs from the twin's nominal model the way a real spindle does (see
`twin.plant.truth`): a finer mesh (`Scenario.model.size_factor`), shorter steps (2 s
instead of 4 s), bearing heat and contact resistance multiplied by time-varying truth
factors, coolant inlet and ambient drifting, X/Y drift the axisymmetric model cannot
produce, and model-form error the twin's corrections cannot express: motor loss and
film-group factors, scaled material conductivity and expansion, thermocouples a little
off their nominal points.  A stop (speed 0) has no bearing or motor heat and the
standstill film coefficients; the truth simply cools down.

The nominal bearing heat and contact resistance follow the truth's own ring and sleeve
temperatures (oil viscosity, Eq. 5 fit) every 2 s step, as a real spindle's do
continuously: held over 20 s from the cold start (oil at ambient, too much heat), they
dropped T1 by up to 0.23 K per second after 20 s at 15 000 rpm.  The drifting ambient and
coolant and the motor and film factors are held over `UPDATE_S`.  The sensors then add
thermocouple lag, calibration offsets, noise and faults.

Displacement probes are zeroed at the start of the run (as on a test stand), so
`disp_z_um` is the thermal drift of the nose from the cold start.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from twin.contract import OPERATING_TEMPERATURE_C, SENSOR_NAMES
from twin.lag import first_order_lag
from twin.plant.profile import SpeedProfile
from twin.plant.scenario import Scenario
from twin.plant.sensors import add_noise, apply_faults, calibrated_reading
from twin.plant.timetable import StepTable
from twin.plant.truth import (
    FILM_GROUPS,
    ModelForm,
    TruthTables,
    default_model_form,
    default_tables,
    sensor_offsets_mm,
    truth_tables,
    xy_drift_um,
)
from twin.runs.validate import check_speed_limit

if TYPE_CHECKING:
    from twin.spindle.model import SpindleModel

DT_S = 2.0
"""Truth time step, s (the twin uses 4 s)."""
UPDATE_S = 20.0
"""The truth's ambient, coolant, motor and film factors are held this long, s; its bearing
heat and contact resistance follow its rings every step (`run_truth`)."""



def truth_model(nominal: SpindleModel, form: ModelForm | None = None) -> SpindleModel:
    """The truth's spindle model: the nominal one (`nominal`, a SpindleModel) with the
    material factors and sensor offsets of `form` (None or all neutral: `nominal` itself).

    Conductivity and expansion multiply every material's value, so the contact resistance
    of Eq. 4/5 (harmonic-mean conductivity, ring and sleeve expansion) follows them too.
    The mesh is the nominal one; only the operators are assembled again (about 0.5 s).
    """
    if form is None or (form.conductivity == 1.0 and form.expansion == 1.0
                        and not any(any(o) for o in form.sensor_offsets_mm.values())):
        return nominal
    spec = nominal.spec
    materials = {
        name: m.model_copy(update={
            "conductivity_W_per_mK": m.conductivity_W_per_mK * form.conductivity,
            "expansion_per_K": m.expansion_per_K * form.expansion})
        for name, m in spec.materials.items()}
    sensors = dict(spec.sensors)
    for name, (dr, dz) in form.sensor_offsets_mm.items():
        p = sensors[name]
        sensors[name] = p.model_copy(update={"r_mm": p.r_mm + dr, "z_mm": p.z_mm + dz})
    truth_spec = spec.model_copy(update={"materials": materials, "sensors": sensors})
    return type(nominal).from_mesh_file(truth_spec, nominal.spec_path, nominal.mesh_path,
                                        nominal.order)


@dataclass
class TruthRun:
    """The truth at the solver steps: metal temperatures, nose drift, applied loads."""

    time_s: np.ndarray  # (n+1,)
    sensors_C: np.ndarray  # (n+1, 5) metal temperature at T1..T5 (no lag, no noise)
    disp_z_um: np.ndarray  # (n+1,) axial nose drift from the start
    loads: dict[str, np.ndarray]  # per step (n+1,): H/R nominal and true, speed, ...
    heat_in_W: np.ndarray  # (n,)
    residual_W: np.ndarray  # (n,) energy balance of each step
    final_field_C: np.ndarray | None = None  # (n_dofs,) the temperature field at the end


@dataclass
class SynthRun:
    """An emulated recorded run and its truth, ready to be written."""

    columns: dict[str, np.ndarray]
    metadata: dict[str, str]
    truth: dict[str, np.ndarray]
    elapsed_s: float = 0.0
    max_relative_residual: float = 0.0
    extra: dict = field(default_factory=dict)

    @property
    def n_samples(self) -> int:
        return int(self.columns["time_s"].size)


def run_truth(model: SpindleModel, duration_s: float, speed: StepTable, tables: TruthTables,
              dt: float = DT_S, update_s: float = UPDATE_S) -> TruthRun:
    """Backward-Euler transient of the truth from a uniform start at the ambient.

    Every step takes the bearing heat and contact resistance at the truth's own ring and
    sleeve temperatures at its start (`bearing_values_at`: Palmgren with the oil at the
    ring, Eq. 4/5 with the fit) times the truth factors at its start, as a real spindle's
    follow its rings, continuously.  The rest (ambient and coolant inlet at the interval's
    mean, motor and film-group factors) is held over intervals of `update_s` that also
    break at every speed change: a new set of film coefficients costs a factorization.
    """
    from twin.spindle import nominal_conditions
    from twin.spindle.conditions import bearing_values_at

    n = int(math.ceil(duration_s / dt - 1e-9))
    t = np.arange(n + 1) * dt
    steps_per_update = max(1, int(round(update_s / dt)))
    # an interval at every regular update and at the first step after a speed change
    starts = set(range(0, n, steps_per_update))
    starts.update(int(math.ceil(c / dt - 1e-9)) for c in speed.changes_in(0.0, duration_s))
    starts = sorted(s for s in starts if s < n)

    thermal = model.thermal
    S, W = model.sensor_matrix, model.probe_vectors[0]
    T0 = np.full(model.n_dofs, float(tables.ambient_C(0.0)))
    T = T0.copy()
    sensors = np.empty((n + 1, S.shape[0]))
    disp = np.zeros(n + 1)
    sensors[0] = S @ T
    form = tables.form
    names = ("speed_rpm", "H_front_nominal", "H_rear_nominal", "R_front_nominal",
             "R_rear_nominal", "H_front", "H_rear", "R_front", "R_rear", "coolant_C",
             "ambient_C", "factor_H_front", "factor_H_rear", "factor_R_front", "factor_R_rear",
             "factor_motor", *(f"factor_film_{g}" for g in FILM_GROUPS))
    loads_log = {k: np.empty(n + 1) for k in names}
    heat_in, residual = np.empty(n), np.empty(n)
    films_at_speed: dict[float, dict[str, float]] = {}
    bearing_tables = {"H_front": tables.H_front, "H_rear": tables.H_rear,
                      "R_front": tables.R_front, "R_rear": tables.R_rear}
    for a, b in zip(starts, [*starts[1:], n], strict=True):
        mid = 0.5 * (t[a] + t[b])  # drifting temperatures: the interval's mean value
        base = nominal_conditions(model, float(speed(t[a])), float(tables.ambient_C(mid)),
                                  float(tables.coolant_C(mid)))
        # Film coefficients depend on speed, and on the ambient only through air properties
        # (≪ 1 % per K): hold them per speed so that the drift of the ambient and coolant
        # moves only the bulk temperatures, and the step matrix factorization is reused.
        h = films_at_speed.setdefault(base.speed_rpm,
                                      {k: v[0] for k, v in base.convection.items()})
        # model-form error: film groups and motor loss off their correlations/catalogue
        base = replace(base, convection={k: (h[k] * form.film_factor(k, t[a]), v[1])
                                         for k, v in base.convection.items()},
                       motor_heat={r: q * float(form.motor_heat(t[a]))
                                   for r, q in base.motor_heat.items()})
        held = {"speed_rpm": base.speed_rpm, "coolant_C": base.coolant_C,
                "ambient_C": base.ambient_C, "factor_motor": float(form.motor_heat(t[a])),
                **{f"factor_film_{g}": float(form.film[g](t[a])) for g in FILM_GROUPS}}
        for key, v in held.items():
            loads_log[key][a:b] = v
        for k in range(a, b):
            # the bearing values follow the rings every step (Palmgren's oil viscosity,
            # the fit of Eq. 5), each times its truth factor at the step's start
            nominal = bearing_values_at(model, base.speed_rpm, sensors[k])
            for key, v in nominal.items():
                factor = float(bearing_tables[key](t[k]))
                loads_log[f"{key}_nominal"][k] = v
                loads_log[f"factor_{key}"][k] = factor
                loads_log[key][k] = v * factor
            stepper = thermal.transient(
                base.to_thermal_loads(**{key: loads_log[key][k] for key in nominal}),
                dt=dt, theta=1.0)
            T_new = stepper.step(T)
            eb = stepper.energy_balance(T, T_new)
            heat_in[k], residual[k] = eb["heat_in_W"], eb["residual_W"]
            T = T_new
            sensors[k + 1] = S @ T
            disp[k + 1] = W @ (T - T0)
    for k in names:
        loads_log[k][n] = loads_log[k][n - 1]
    return TruthRun(time_s=t, sensors_C=sensors, disp_z_um=disp * 1e6, loads=loads_log,
                    heat_in_W=heat_in, residual_W=residual, final_field_C=T)


SYNTH_SOURCE = "twin synth (emulated spindle)"
"""The `source` metadata of every run `twin synth` writes (what `--suite --overwrite` may
remove)."""


def written_by_synth(path: Path) -> bool:
    """Whether the run file `path` says `twin synth` wrote it (its `source` metadata); a
    file that cannot be read as a run does not."""
    from twin.errors import InputError
    from twin.runs import read_table

    try:
        return read_table(path).metadata.get("source") == SYNTH_SOURCE
    except InputError:
        return False


def synthesize(*, minutes: float, ambient_C: float, seed: int, speed_rpm: float | None = None,
               profile: SpeedProfile | None = None, scenario: Scenario | None = None,
               rate_hz: float = 1.0, coolant_C: float | None = None,
               scenario_name: str | None = None, profile_name: str | None = None,
               model: SpindleModel | None = None, record_from_s: float = 0.0) -> SynthRun:
    """An emulated recorded run (see the module doc).  Deterministic given the inputs.

    Exactly one of `speed_rpm` (constant) and `profile` is given.  `coolant_C` is the
    coolant inlet at the start (default: the ambient, like the nominal model).  `model`
    is the truth's nominal SpindleModel, loaded once by a caller that synthesizes many
    runs (default: the reference spindle at the scenario's size factor, loaded here); the
    run's material factors and sensor offsets are applied on top (`truth_model`).
    `record_from_s`: the logger starts this long into the run (a warm start): the spindle
    follows the profile and scenario from 0 s, the files hold the samples from there on,
    their time and the probes zeroed there (the readings then keep their noise).
    """
    start = time.perf_counter()
    if (speed_rpm is None) == (profile is None):
        raise ValueError("give exactly one of speed_rpm and profile")
    if not 0.0 <= record_from_s <= 60.0 * float(minutes) - 120.0:
        raise ValueError("the recording starts at 0 s or later and holds two 60 s windows")
    scenario = scenario or Scenario()
    duration = float(minutes) * 60.0
    if profile is not None:
        speed = profile.speed_rpm
        ambient_base = profile.ambient_C  # a StepTable, or None: then --ambient holds
    else:
        speed = StepTable.constant(float(speed_rpm))
        ambient_base = None
    if ambient_base is None:
        ambient_base = StepTable.constant(float(ambient_C))
    if model is None:
        from twin.spindle import SpindleModel

        model = SpindleModel.load(size_factor=scenario.model.size_factor)
    spec = model.spec
    limit = spec.spindle.max_speed_rpm
    rows = profile.rows if profile is not None and profile.rows else None
    check_speed_limit(profile_name, rows, speed.values, limit,
                      row_unit=profile.row_unit if profile is not None else "row")

    # the first two streams are those of the runs before model-form error existed
    truth_seed, noise_seed, form_seed, place_seed = np.random.SeedSequence(seed).spawn(4)
    coolant0 = float(ambient_base(0.0)) if coolant_C is None else float(coolant_C)
    defaults = default_tables(np.random.default_rng(truth_seed), duration, speed,
                              ambient_base, coolant0)
    nominal_points = {n: (p.r_mm, p.z_mm) for n, p in spec.sensors.items()}
    offsets = sensor_offsets_mm(np.random.default_rng(place_seed),
                                scenario.sensors.placement_mm, nominal_points, spec.inside_body)
    form = replace(default_model_form(np.random.default_rng(form_seed)),
                   sensor_offsets_mm=offsets)
    tables = truth_tables(scenario, replace(defaults, form=form))
    truth = run_truth(truth_model(model, tables.form), duration, speed, tables)

    # --- what the test stand records -------------------------------------------------
    rng = np.random.default_rng(noise_seed)
    sensors = scenario.sensors
    t_out = np.arange(0.0, duration + 1e-9, 1.0 / rate_hz)
    lagged = first_order_lag(truth.sensors_C, truth.time_s, sensors.lag_s)
    T_meas = np.stack([np.interp(t_out, truth.time_s, lagged[:, j]) for j in range(5)], axis=1)
    disp_z = np.interp(t_out, truth.time_s, truth.disp_z_um)
    if tables.x_um is None or tables.y_um is None:  # the spindle's own X/Y response
        xy = xy_drift_um(truth.time_s, truth.sensors_C, tables.xy_gain_scale)
        x_true, y_true = (np.interp(t_out, truth.time_s, axis) for axis in xy)
    else:  # a scenario's prescribed [xy_drift]
        x_true, y_true = tables.x_um(t_out), tables.y_um(t_out)
    read = calibrated_reading(sensors.offset_C)

    def boundary_reading(column: str, true_C: np.ndarray) -> np.ndarray:
        # the air and inlet readings' noise stays in the range every reader accepts: at
        # --ambient 45 (a bound) it crossed it, and the run emulated was refused by replay.
        # A calibration offset that takes the reading itself out is kept (`twin synth`
        # refuses the run, naming the offset): clipped, a +0.5 K ambient offset at 44.8 °C
        # read a flat 45 °C while the truth file told 0.5 K
        reading = read(column, true_C)
        lo, hi = OPERATING_TEMPERATURE_C
        return np.clip(add_noise(rng, reading, sensors.noise_C), np.minimum(reading, lo),
                       np.maximum(reading, hi))

    columns = {
        "time_s": t_out,
        "speed_rpm": speed(t_out).astype(float),
        "ambient_C": boundary_reading("ambient_C", tables.ambient_C(t_out)),
        **{f"{s}_C": add_noise(rng, read(f"{s}_C", T_meas[:, j]), sensors.noise_C)
           for j, s in enumerate(SENSOR_NAMES)},
        "coolant_C": boundary_reading("coolant_C", tables.coolant_C(t_out)),
        "disp_x_um": add_noise(rng, x_true, sensors.noise_um),
        "disp_y_um": add_noise(rng, y_true, sensors.noise_um),
        "disp_z_um": add_noise(rng, disp_z, sensors.noise_um),
    }
    columns = apply_faults(t_out, columns, scenario.faults)

    step_index = np.clip(np.searchsorted(truth.time_s, t_out, side="right") - 1, 0,
                         truth.time_s.size - 1)
    truth_cols = {"time_s": t_out}
    for k, v in truth.loads.items():
        truth_cols[k] = v[step_index]  # the values of the truth step the sample falls in
    for j, s in enumerate(SENSOR_NAMES):
        truth_cols[f"{s}_true_C"] = np.interp(t_out, truth.time_s, truth.sensors_C[:, j])
    truth_cols.update(disp_z_true_um=disp_z, disp_x_true_um=x_true, disp_y_true_um=y_true)

    if speed_rpm is not None:
        label = f"{speed_rpm:g}rpm"
    else:
        label = Path(profile_name).stem if profile_name else "profile"
    metadata = {
        "name": f"synth_{label}_{minutes:g}min_seed{seed}",
        "source": SYNTH_SOURCE,
        "speed_rpm": f"{speed_rpm:g}" if speed_rpm is not None else "profile",
        # file names only: the run must not depend on the folder it was made from
        "profile": Path(profile_name).name if profile_name else "",
        "minutes": f"{minutes:g}",
        "ambient_C": f"{float(tables.ambient_C(0.0)):g}",
        "coolant_C": f"{float(tables.coolant_C(0.0)):g}",
        "seed": str(seed),
        "rate_hz": f"{rate_hz:g}",
        "scenario": Path(scenario_name).name if scenario_name else "",
        "truth_mesh_size_factor": f"{scenario.model.size_factor:g}",
        "thermocouple_lag_s": f"{sensors.lag_s:g}",
        "noise_C": f"{sensors.noise_C:g}",
        "noise_um": f"{sensors.noise_um:g}",
        "displacement_reference": "probes zeroed at t = 0 (cold start)",
    }
    truth_metadata = {
        "conductivity_factor": f"{tables.form.conductivity:.6g}",
        "expansion_factor": f"{tables.form.expansion:.6g}",
        **{f"{n}_offset_mm": f"{dr + 0.0:.4f} {dz + 0.0:.4f}"  # + 0.0: no "-0.0000"
           for n, (dr, dz) in sorted(tables.form.sensor_offsets_mm.items())},
        **{f"{column.removesuffix('_C')}_calibration_offset_C": f"{value + 0.0:.12g}"
           for column, value in sensors.offset_C.items()},
    }
    if record_from_s > 0.0:
        columns, truth_cols = _recorded_from(record_from_s, columns, truth_cols)
        metadata["record_from_s"] = f"{record_from_s:g}"
        metadata["displacement_reference"] = (f"probes zeroed at t = 0, {record_from_s:g} s "
                                              "into the run (warm start)")
    metadata = {k: v for k, v in metadata.items() if v != ""}
    # relative to the run's peak heat input: a stop has no heat input to compare with
    rel = np.abs(truth.residual_W) / max(float(np.abs(truth.heat_in_W).max()), 1e-12)
    return SynthRun(columns=columns, metadata=metadata, truth=truth_cols,
                    elapsed_s=time.perf_counter() - start,
                    max_relative_residual=float(rel.max()),
                    extra={"truth_run": truth, "tables": tables,
                           "truth_metadata": truth_metadata})


def _recorded_from(start_s: float, columns: dict[str, np.ndarray],
                   truth: dict[str, np.ndarray]
                   ) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
    """The run's and the truth's columns from `start_s` on, time zeroed there, each
    displacement less its true value there (the probes zeroed as the logger starts)."""
    keep = columns["time_s"] >= start_s - 1e-9
    at = int(np.argmax(keep))
    zero = {f"disp_{axis}_um": truth[f"disp_{axis}_true_um"][at] for axis in "xyz"}

    def cut(table: dict[str, np.ndarray], true_suffix: bool) -> dict[str, np.ndarray]:
        out = {}
        for name, values in table.items():
            values = values[keep]
            if name == "time_s":
                values = values - columns["time_s"][at]
            key = name.replace("_true_um", "_um") if true_suffix else name
            if key in zero:
                values = values - zero[key]
            out[name] = values
        return out

    return cut(columns, False), cut(truth, True)


def truth_path_for(run_path: Path) -> Path:
    """RUN.csv → RUN.truth.csv (also for .parquet runs: the truth is always CSV)."""
    # `parent /`: with_name refused '.' (--out '') with a ValueError, not bad input
    return run_path.parent / (run_path.stem + ".truth.csv")


def write_synth(run: SynthRun, out: Path) -> tuple[Path, Path]:
    """Write RUN (CSV or Parquet) and RUN.truth.csv beside it, each atomically.

    The run's `name` metadata becomes the file stem.  RUN.truth.csv holds, per sample,
    the applied loads (`H_*`, `R_*`), their nominal values *of the truth* (its own
    materials: with a conductivity factor c the truth's Eq. 4 resistance is the twin's
    divided by c), every truth factor (`factor_H_*`, `factor_R_*`, `factor_motor`,
    `factor_film_<group>`), the metal temperatures and drifts; its `#` lines give the
    material factors and each thermocouple's offset (Δr Δz, mm).
    """
    from twin.runs import write_run
    from twin.runs.csv_format import write_csv_table

    out = Path(out)
    truth_path = truth_path_for(out)
    formats = {k: "%.6g" for k in run.truth if k.startswith(("H_", "R_"))}
    formats.update({k: "%.5f" for k in run.truth if k.startswith("factor_")})
    write_csv_table(truth_path, run.truth,
                    {"run": out.name, "note": "evaluation only: the twin never reads this file",
                     **run.extra.get("truth_metadata", {})},
                    formats)
    # the run is named after its file, as every command names its outputs
    write_run(out, run.columns, {**run.metadata, "name": out.stem})
    return out, truth_path
