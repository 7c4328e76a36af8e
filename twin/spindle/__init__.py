"""The reference motorized spindle: spec → mesh → model → nominal loads → open-loop run.

    from twin.spindle import SpindleModel, nominal_conditions, simulate

    model = SpindleModel.load()                      # bundled spec and committed mesh
    bc = nominal_conditions(model, speed_rpm=9000, ambient_C=25.3)
    loads = bc.to_thermal_loads(H_front=1.7e6)       # what a correction method does
    result = simulate(model, 9000, minutes=30, ambient_C=25.3)

spec        SpindleSpec, load_spec (TOML → validated pydantic models, InputError)
mesher      build_mesh, write_msh: spec → gmsh mesh with named regions and boundaries
model       SpindleModel (mesh, thermal, elastic, sensor_matrix, probe_vectors)
conditions  BoundaryConditions, nominal_conditions, check_operating_point
simulate    simulate → SimulationResult (key points, nose drift, energy balance)
fields      field_arrays, field_mesh: a temperature state as the field-file arrays
output      write_simulation (keypoints.csv, fields.pvd + .vtu, summary.json)
"""

from twin.spindle.conditions import (
    BoundaryConditions,
    check_operating_point,
    nominal_conditions,
)
from twin.spindle.model import SpindleModel
from twin.spindle.output import write_simulation
from twin.spindle.simulate import SimulationResult, simulate
from twin.spindle.spec import SpindleSpec, load_spec

__all__ = [
    "BoundaryConditions",
    "SimulationResult",
    "SpindleModel",
    "SpindleSpec",
    "check_operating_point",
    "load_spec",
    "nominal_conditions",
    "simulate",
    "write_simulation",
]
