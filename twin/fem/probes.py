"""Point evaluation of finite element fields: T(points) = P @ T with a sparse P."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from skfem import Basis


def probe_matrix(basis: Basis, points: np.ndarray) -> sp.csr_matrix:
    """Point-evaluation matrix of a scalar basis at points (2, n); error outside the mesh."""
    try:
        cells = basis.mesh.element_finder()(points[0], points[1])
    except ValueError as exc:
        raise ValueError(f"probe point outside the mesh: {exc}") from None
    p = basis.mesh.p
    t = basis.mesh.t[:, cells]
    # the finder may return the closest cell for points outside: check barycentrics
    a, b, c = p[:, t[0]], p[:, t[1]], p[:, t[2]]
    det = (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1])
    l1 = ((points[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (points[1] - a[1])) / det
    l2 = ((b[0] - a[0]) * (points[1] - a[1]) - (points[0] - a[0]) * (b[1] - a[1])) / det
    tol = -1e-9
    outside = (l1 < tol) | (l2 < tol) | (1.0 - l1 - l2 < tol)
    if np.any(outside):
        bad = points[:, np.where(outside)[0][0]]
        raise ValueError(f"probe point (r={bad[0]:.6g}, z={bad[1]:.6g}) m is outside the mesh")
    return sp.csr_matrix(basis.probes(points))
