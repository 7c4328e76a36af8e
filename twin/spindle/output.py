"""Files of an open-loop run: keypoints.csv, fields.pvd + fields/*.vtu, summary.json.

Every file is written atomically (`twin.io.atomic`); what an earlier run wrote there goes
first, and summary.json comes last, so an interrupted run leaves no summary.
keypoints.csv has the columns of a recorded run (time_s, speed_rpm, ambient_C,
T1_C..T5_C, disp_z_um, disp_r_um), so a simulated run can be replayed like a measured one.
The .vtu files are those of every field file (`twin.io.vtk`): temperature_C,
displacement_um (u_r, u_z, 0; relative to the start of the run) and von_mises_MPa on the
thermal mesh vertices, and the region number per cell.
"""

from __future__ import annotations

import csv
import io
import shutil
from pathlib import Path

import numpy as np

from twin.contract import SENSOR_NAMES
from twin.io.atomic import write_json, write_text
from twin.io.vtk import write_field_series
from twin.spindle.fields import field_mesh
from twin.spindle.model import SpindleModel
from twin.spindle.simulate import SimulationResult


def keypoints_csv(result: SimulationResult) -> str:
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    kp = result.keypoints()
    cols = list(kp)
    writer.writerow([cols[0], "speed_rpm", "ambient_C", *cols[1:]])
    for i in range(result.time_s.size):
        writer.writerow([f"{kp['time_s'][i]:.6g}", f"{result.speed_rpm:.6g}",
                         f"{result.ambient_C:.6g}", *(f"{kp[c][i]:.6f}" for c in cols[1:])])
    return buf.getvalue()


def summary(model: SpindleModel, result: SimulationResult) -> dict:
    """The JSON summary of a run (max temperature and where, drift, energy balance)."""
    last = result.conditions[-1]
    rel = result.relative_residual
    return {
        "speed_rpm": result.speed_rpm,
        "minutes": float(result.time_s[-1] / 60.0),
        "ambient_C": result.ambient_C,
        "coolant_C": result.coolant_C,
        "dt_s": result.dt_s,
        "max_temperature_C": result.max_temperature_C,
        "max_temperature_at": {"r_m": result.max_temperature_at_m[0],
                               "z_m": result.max_temperature_at_m[1],
                               "region": result.max_temperature_region},
        "region_max_C": result.region_max_C,
        "region_mean_C": result.region_mean_C,
        "final_keypoints_C": {s: float(v) for s, v in zip(SENSOR_NAMES, result.sensors_C[-1],
                                                          strict=True)},
        "nose_drift_um": {"axial": float(result.disp_z_um[-1]),
                          "radial": float(result.disp_r_um[-1]),
                          "axial_max_abs": float(np.abs(result.disp_z_um).max())},
        "energy_balance": {
            "max_relative_residual": float(rel.max()),
            "final_step_W": {"heat_in": float(result.heat_in_W[-1]),
                             "heat_out": float(result.heat_out_W[-1]),
                             "stored": float(result.stored_W[-1]),
                             "residual": float(result.residual_W[-1])},
        },
        "final_boundary_conditions": {
            "H_front_W_m3": last.H_front, "H_rear_W_m3": last.H_rear,
            "R_front_m2K_W": last.R_front, "R_rear_m2K_W": last.R_rear,
            "heat_W": last.heat_W(),
            "convection": {k: {"h_W_m2K": h, "T_inf_C": t}
                           for k, (h, t) in last.convection.items()},
        },
        "mesh": {"file": str(model.mesh_path), "nodes": int(model.mesh.glued.p.shape[1]),
                 "cells": int(model.mesh.n_cells), "order": model.order},
        "wall_time_s": result.wall_time_s,
    }


def write_fields(model: SpindleModel, result: SimulationResult, out_dir: Path) -> Path:
    """fields/step_NNNNN.vtu per kept snapshot and a ParaView collection fields.pvd."""
    if not result.fields:
        raise ValueError("the run kept no field snapshots (simulate(field_every_s=...))")
    # simulate starts from a uniform field at the ambient: the drift is relative to it
    return write_field_series(out_dir, (
        (t, f"fields/step_{int(round(t / result.dt_s)):05d}.vtu",
         field_mesh(model, T, result.ambient_C))
        for t, T in result.fields))


def is_simulation_folder(folder: str | Path) -> bool:
    """True for a `twin simulate` output folder: keypoints.csv and summary.json at its top
    (a replay keeps them in its run folders and writes a summary.json of its own)."""
    folder = Path(folder)
    return (folder / "keypoints.csv").is_file() and (folder / "summary.json").is_file()


def write_simulation(model: SpindleModel, result: SimulationResult, out_dir: str | Path,
                     fields: bool = True) -> dict:
    """Write keypoints.csv, fields (if kept and `fields`) and summary.json; return summary."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    # an earlier run's files go first: its later field steps would stand beside this run's,
    # and summary.json, written last, would look current beside a run interrupted here
    (out_dir / "summary.json").unlink(missing_ok=True)
    (out_dir / "fields.pvd").unlink(missing_ok=True)
    fields_dir = out_dir / "fields"
    if fields_dir.is_symlink() or fields_dir.is_file():
        fields_dir.unlink()
    elif fields_dir.is_dir():
        shutil.rmtree(fields_dir)
    write_text(out_dir / "keypoints.csv", keypoints_csv(result))
    if fields and result.fields:
        write_fields(model, result, out_dir)
    info = summary(model, result)
    write_json(out_dir / "summary.json", info)
    return info
