"""Per-window cost of the FEM core: 15 thermal steps + 15 structural solves.

A window of the twin is 15 backward-Euler steps of 4 s with new heat sources and contact
resistances (film coefficients change only with speed), and a thermo-elastic solve per
step.  `first_window_ms` includes the factorization a speed change costs;
`window_probe_ms` is a steady-speed window (low-rank contact update, no factorization)
with the nose drift from the precomputed adjoint vector (one dot product per step);
`window_full_fields_ms` adds a full displacement back-substitution per step.
"""

from __future__ import annotations

import resource
import time
from collections.abc import Callable

import numpy as np

from twin.fem import AxiMesh, ElasticProblem, Material, ThermalLoads, ThermalProblem

STEEL = Material(k=49.8, rho=7830.0, c=465.0, E=210e9, nu=0.265, alpha=12.2e-6)
BEARING = Material(k=40.1, rho=7810.0, c=553.0, E=205e9, nu=0.3, alpha=13.3e-6)


def window_mesh(n_nodes: int) -> AxiMesh:
    """Shaft in a housing with two bearing seats (25 mm contact bands), about `n_nodes`.

    Like the spindle, the contact interfaces are short compared with the body: their
    rank (the number of interface dofs) is what the low-rank window update costs.
    """
    nz = int(round(np.sqrt(n_nodes * 3.0)))
    nr = max(4, int(round(n_nodes / nz)))

    def band(z0: float) -> Callable[[np.ndarray, np.ndarray], np.ndarray]:
        return lambda r, z: (r > 0.05) & (z > z0) & (z < z0 + 0.025)

    def seat(z0: float) -> Callable[[np.ndarray, np.ndarray], np.ndarray]:
        return lambda r, z: np.isclose(r, 0.05) & (z > z0) & (z < z0 + 0.025)

    return AxiMesh.structured(
        np.linspace(0.0, 0.1, nr),
        # grid lines on the band edges, so cells and seats agree on where a band ends
        np.unique(np.r_[np.linspace(0.0, 0.3, nz), 0.03, 0.055, 0.25, 0.275]),
        regions={
            "shaft": lambda r, z: r < 0.05,
            "ring_front": band(0.25),
            "ring_rear": band(0.03),
            "housing": lambda r, z: (r > 0.05) & ~band(0.25)(r, z) & ~band(0.03)(r, z),
        },
        boundaries={
            "axis": lambda r, z: np.isclose(r, 0.0),
            "surface": lambda r, z: np.isclose(r, 0.1),
            "mount": lambda r, z: np.isclose(z, 0.0),
            "nose": lambda r, z: np.isclose(z, 0.3),
        },
        interfaces={"contact_front": seat(0.25), "contact_rear": seat(0.03)},
    )


def time_window(n_nodes: int, repeats: int = 7) -> dict:
    t0 = time.perf_counter()
    mesh = window_mesh(n_nodes)
    materials = {"shaft": STEEL, "housing": STEEL, "ring_front": BEARING, "ring_rear": BEARING}
    thermal = ThermalProblem(mesh, materials)
    elastic = ElasticProblem(mesh, materials, {"axis": "r", "mount": "z"}, T_ref=20.0)
    probe = elastic.displacement_probe(np.array([0.0, 0.3]), "z")
    setup_s = time.perf_counter() - t0

    T = np.full(thermal.n_dofs, 20.0)
    full, probe_only, factor = [], [], []
    for k in range(repeats):
        loads = ThermalLoads(
            sources={"ring_front": 1.5e6 * (1 + 0.01 * k), "ring_rear": 5e5},
            convection={"surface": (400.0, 22.0), "nose": (60.0, 22.0)},
            contact_resistance={
                "contact_front": 1e-4 * (1 + 0.02 * k),
                "contact_rear": 1.2e-4 * (1 - 0.02 * k),
            },
        )
        t = time.perf_counter()
        stepper = thermal.transient(loads, 4.0)
        t_f = time.perf_counter()
        drift = [probe @ (Tw - 20.0) for Tw in stepper.march(T, 15)]
        t_p = time.perf_counter()
        for Tw in thermal.transient(loads, 4.0).march(T, 15):
            elastic.solve_vector(Tw)
        t_full = time.perf_counter()
        factor.append(t_f - t)
        probe_only.append(t_p - t)
        full.append(t_full - t_p)
        T = Tw
    return {
        "nodes": int(mesh.thermal.p.shape[1]),
        "thermal_dofs": int(thermal.n_dofs),
        "structural_dofs": int(elastic.basis.N),
        "setup_s": setup_s,
        "first_window_ms": 1e3 * probe_only[0],
        "window_setup_ms": 1e3 * float(np.median(factor[1:])),
        "window_probe_ms": 1e3 * float(np.median(probe_only[1:])),
        "window_full_fields_ms": 1e3 * float(np.median(full[1:])),
        "last_window_nose_drift_um": 1e6 * float(drift[-1]),  # the probe work is really done
        "peak_rss_MB": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0,
    }


def run() -> dict:
    """Window cost at about 2k, 8k and 32k nodes (each size in a fresh process)."""
    import json
    import subprocess
    import sys

    results = []
    for n in (2000, 8000, 32000):
        out = subprocess.run(
            [
                sys.executable,
                "-c",
                "import json; from bench.fem import time_window; "
                f"print(json.dumps(time_window({n})))",
            ],
            check=True,
            capture_output=True,
            text=True,
            env={
                "OMP_NUM_THREADS": "1",
                "OPENBLAS_NUM_THREADS": "1",
                "MKL_NUM_THREADS": "1",
                **__import__("os").environ,
            },
        )
        results.append(json.loads(out.stdout.strip().splitlines()[-1]))
    a, b = results[0], results[-1]
    growth = np.log(b["window_probe_ms"] / a["window_probe_ms"]) / np.log(b["nodes"] / a["nodes"])
    return {
        "fem_window": results,
        "fem_window_cost_exponent": float(growth),
        "goal": "≤ 15 ms per window at ~8k nodes on one core; cost ~ linear in nodes",
    }


if __name__ == "__main__":
    import json

    print(json.dumps(run(), indent=2))
