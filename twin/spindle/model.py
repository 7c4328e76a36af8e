"""The assembled spindle model: spec → mesh → materials → thermal and elastic problems.

`SpindleModel.load(spec_path=None, size_factor=1.0, order=1)` builds everything once:
the mesh comes from the committed `meshes/reference_spindle.msh` for the bundled spec at
size factor 1, otherwise it is generated with gmsh into a cache directory
(`$TWIN_CACHE_DIR/meshes`, default the platform's user cache folder, e.g.
`~/.cache/spindle-twin/meshes` on Linux) keyed by the spec's content and
the size factor.

Structure: u_r = 0 on the axis and u_z = 0 on the mounting-flange face ("mount"); the
front bearing is located axially through its stiff rolling band, the rear one floats (its
band is compliant, see the spec).  Displacements are reported relative to the state at the
start of a run (uniform temperature), so the nose drift is the thermal drift.
"""

from __future__ import annotations

import hashlib
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import scipy.sparse as sp

from twin.contract import SENSOR_NAMES
from twin.fem import AxiMesh, ElasticProblem, Material, ThermalProblem
from twin.spindle.conditions import SpecConstants
from twin.spindle.spec import DEFAULT_SPEC_PATH, PROBE_NAMES, SpindleSpec, load_spec

DEFAULT_MESH_PATH = DEFAULT_SPEC_PATH.with_suffix(".msh")
#: bump when twin/spindle/mesher.py changes what it produces, to invalidate cached meshes
MESHER_VERSION = "1"


def fem_material(spec: SpindleSpec, region: str) -> Material:
    """twin.fem.Material (SI) of a spec region."""
    m = spec.material_of(region)
    return Material(
        k=m.conductivity_W_per_mK,
        rho=m.density_kg_per_m3,
        c=m.specific_heat_J_per_kgK,
        E=m.youngs_modulus_GPa * 1e9,
        nu=m.poisson_ratio,
        alpha=m.expansion_per_K,
        name=spec.regions[region],
    )


def cache_dir() -> Path:
    """Generated meshes: `$TWIN_CACHE_DIR/meshes`, else the platform's user cache folder."""
    import platformdirs

    root = os.environ.get("TWIN_CACHE_DIR")
    base = Path(root) if root else platformdirs.user_cache_path("spindle-twin")
    return base / "meshes"


def mesh_path_for(spec_path: Path, size_factor: float) -> Path:
    """Where the mesh of a spec at a size factor lives (committed file or cache)."""
    if spec_path.resolve() == DEFAULT_SPEC_PATH and size_factor == 1.0:
        return DEFAULT_MESH_PATH
    digest = hashlib.sha256(spec_path.read_bytes())
    digest.update(f"|{size_factor:.9g}|{MESHER_VERSION}".encode())
    return cache_dir() / f"spindle_{digest.hexdigest()[:16]}.msh"


def ensure_mesh(spec: SpindleSpec, spec_path: Path, size_factor: float) -> Path:
    """The mesh file for (spec, size factor), generated with gmsh if not there yet."""
    path = mesh_path_for(spec_path, size_factor)
    if not path.exists():
        from twin.spindle.mesher import build_mesh, write_msh

        write_msh(build_mesh(spec, size_factor), path)
    return path


@dataclass
class SpindleModel:
    """Everything assembled once per spindle: mesh, materials, operators, probes.

    mesh           twin.fem.AxiMesh (regions, boundaries, contact interfaces of the spec)
    thermal        ThermalProblem
    elastic        ElasticProblem (axis: u_r = 0, mount: u_z = 0, T_ref = assembly °C)
    sensor_matrix  (5 × n_thermal_dofs) sparse: T1..T5 = sensor_matrix @ T
    probe_vectors  (2 × n_thermal_dofs): nose (axial z, radial r) displacement in m is
                   probe_vectors @ (T − T_ref)
    constants      twin.spindle.conditions.SpecConstants of `spec` (bearing and motor
                   volumes, fit constants), computed with the model: the per-step bearing
                   values (`bearing_values_at`) take them from here
    """

    spec: SpindleSpec
    spec_path: Path
    mesh_path: Path
    mesh: AxiMesh
    materials: dict[str, Material]
    thermal: ThermalProblem
    elastic: ElasticProblem
    sensor_matrix: sp.csr_matrix
    probe_vectors: np.ndarray
    order: int = 1
    constants: SpecConstants = field(init=False, repr=False, compare=False)

    sensor_names = SENSOR_NAMES
    probe_names = PROBE_NAMES

    def __post_init__(self) -> None:
        self.constants = SpecConstants.of(self.spec)

    @classmethod
    def load(cls, spec_path: str | Path | None = None, size_factor: float = 1.0,
             order: int = 1) -> SpindleModel:
        """Build the model of a spec TOML (None: the bundled reference spindle)."""
        if not (np.isfinite(size_factor) and size_factor > 0):
            raise ValueError(f"size_factor must be positive, got {size_factor}")
        path = Path(spec_path) if spec_path is not None else DEFAULT_SPEC_PATH
        spec = load_spec(path)
        mesh_file = ensure_mesh(spec, path, float(size_factor))
        return cls.from_mesh_file(spec, path, mesh_file, order)

    @classmethod
    def from_mesh_file(cls, spec: SpindleSpec, spec_path: Path, mesh_file: Path,
                       order: int = 1) -> SpindleModel:
        mesh = AxiMesh.from_msh(mesh_file, interfaces=spec.interfaces())
        materials = {region: fem_material(spec, region) for region in spec.regions}
        thermal = ThermalProblem(mesh, materials, order=order)
        elastic = ElasticProblem(
            mesh, materials, constraints={"axis": "r", "mount": "z"},
            T_ref=spec.spindle.assembly_temperature_C, order=order,
        )
        mm = 1e-3
        sensors = np.array([[spec.sensors[n].r_mm * mm, spec.sensors[n].z_mm * mm]
                            for n in SENSOR_NAMES]).T
        sensor_matrix = thermal.probe(sensors)
        nose_axial = spec.probes["nose_axial"]
        nose_radial = spec.probes["nose_radial"]
        probe_vectors = np.vstack([
            elastic.displacement_probe(np.array([nose_axial.r_mm, nose_axial.z_mm]) * mm, "z"),
            elastic.displacement_probe(np.array([nose_radial.r_mm, nose_radial.z_mm]) * mm, "r"),
        ])
        return cls(spec=spec, spec_path=spec_path, mesh_path=mesh_file, mesh=mesh,
                   materials=materials, thermal=thermal, elastic=elastic,
                   sensor_matrix=sensor_matrix, probe_vectors=probe_vectors, order=order)

    # ------------------------------------------------------------ helpers
    @property
    def n_dofs(self) -> int:
        return self.thermal.n_dofs

    def region_volume_m3(self, region: str) -> float:
        return self.thermal.volume(region)

    def region_mean_C(self, T: np.ndarray) -> dict[str, float]:
        """Volume-weighted mean temperature of every region, °C."""
        return {r: float(self.thermal.source_vector(r) @ T / self.thermal.volume(r))
                for r in self.spec.regions}

    def dof_region(self, dof: int, T: np.ndarray) -> str:
        """Region of the hottest cell holding a dof (where a hot spot lies)."""
        element_dofs = self.thermal.basis.element_dofs
        cells = np.where(np.any(element_dofs == dof, axis=0))[0]
        if cells.size == 0:
            return ""
        cell = cells[int(np.argmax(T[element_dofs[:, cells]].mean(axis=0)))]
        for region, idx in self.mesh.regions.items():
            if region in self.spec.regions and np.any(idx == cell):
                return region
        return ""

    def dof_coordinates(self) -> np.ndarray:
        """(2, n_dofs) r, z in metres of every thermal dof."""
        return self.thermal.basis.doflocs
