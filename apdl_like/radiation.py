"""Radiation view factors between the faces of a 2-D model (/AUX12, VFQUERY).

A face is a straight element edge (ends a, b in (x, y); axisymmetric: (r, z)) with its unit
normal pointing into the enclosure.  The view factor from face i to face j is

    F_ij = 1/A_i ∫_Ai ∫_Aj cos θi cos θj / (π s²) dAj dAi          (axisymmetric: the faces
                                                                    revolved into rings)
    F_ij = 1/L_i ∫_Li ∫_Lj cos θi cos θj / (2 s) dLj dLi           (planar, unit depth)

integrated numerically: Gauss points along each face and, for rings, `n_phi` azimuths
around the axis (MAPDL's V2DOPT,1 revolves the faces the same way).  A pair of points sees
each other only if both cosines are positive and the straight ray between them crosses no
face of the enclosure (MAPDL's hidden-surface option: every face may shade).
"""

from __future__ import annotations

import numpy as np

GAUSS_POINTS = 4  # per face
AZIMUTHS = 180  # around the axis (axisymmetric)
_EPS = 1e-9  # a ray's own ends do not shade it


def view_factors(a: np.ndarray, b: np.ndarray, normal: np.ndarray, axisymmetric: bool,
                 n_gauss: int = GAUSS_POINTS,
                 n_phi: int = AZIMUTHS) -> tuple[np.ndarray, np.ndarray]:
    """(F (m, m), face areas (m,)) of m faces: a, b (m, 2) ends, normal (m, 2) unit."""
    g, w = np.polynomial.legendre.leggauss(n_gauss)
    g, w = 0.5 * (g + 1.0), 0.5 * w
    m = a.shape[0]
    length = np.hypot(*(b - a).T)
    points = a[:, None, :] + g[None, :, None] * (b - a)[:, None, :]  # (m, ng, 2)
    ds = w[None, :] * length[:, None]  # (m, ng)
    if axisymmetric:
        phi = (np.arange(n_phi) + 0.5) * 2.0 * np.pi / n_phi
        r, z = points[..., 0][..., None], points[..., 1][..., None]
        cos, sin = np.cos(phi), np.sin(phi)
        targets = np.stack(np.broadcast_arrays(r * cos, r * sin, z), axis=-1)
        nr, nz = normal[:, None, None, 0], normal[:, None, None, 1]
        t_normals = np.stack(np.broadcast_arrays(nr * cos, nr * sin, nz + 0.0 * r), axis=-1)
        t_area = np.broadcast_to((ds * points[..., 0])[..., None] * (2.0 * np.pi / n_phi),
                                 targets.shape[:-1])
        s_weight = 2.0 * np.pi * ds * points[..., 0]
        sources = np.stack([points[..., 0], np.zeros_like(points[..., 0]), points[..., 1]], -1)
        s_normals = np.stack([normal[:, 0], np.zeros(m), normal[:, 1]], -1)
    else:
        targets, t_normals = points, np.broadcast_to(normal[:, None, :], points.shape)
        t_area, s_weight = ds, ds
        sources, s_normals = points, normal
    per_face = int(np.prod(targets.shape[1:-1]))
    targets = targets.reshape(-1, targets.shape[-1])
    t_normals = t_normals.reshape(targets.shape)
    t_area = np.ascontiguousarray(t_area).ravel()
    owner = np.repeat(np.arange(m), per_face)
    area = s_weight.sum(axis=1)
    F = np.zeros((m, m))
    for i in range(m):
        for k in range(n_gauss):
            x = sources[i, k]
            d = targets - x
            s2 = np.einsum("ij,ij->i", d, d)
            seen = s2 > 0.0
            s = np.sqrt(np.where(seen, s2, 1.0))
            cos_i = d @ s_normals[i] / s
            cos_j = -np.einsum("ij,ij->i", d, t_normals) / s
            seen &= (cos_i > 0.0) & (cos_j > 0.0)
            seen[seen] = ~_shaded(x, d[seen], a, b, axisymmetric)
            kernel = cos_i * cos_j / (np.pi * s2) if axisymmetric else cos_i * cos_j / (2.0 * s)
            contrib = np.where(seen, kernel, 0.0) * t_area
            F[i] += s_weight[i, k] * np.bincount(owner, contrib, minlength=m)
        F[i] /= area[i]
    return F, area


def _shaded(x: np.ndarray, d: np.ndarray, a: np.ndarray, b: np.ndarray,
            axisymmetric: bool) -> np.ndarray:
    """Does the ray x + t d, 0 < t < 1, cross any face (ends a, b)?"""
    hit = np.zeros(d.shape[0], bool)
    lo, hi = _EPS, 1.0 - _EPS
    for (ra, za), (rb, zb) in zip(a, b, strict=True):
        if not axisymmetric:  # segment-segment crossing
            e = np.array([rb - ra, zb - za])
            denom = d[:, 0] * e[1] - d[:, 1] * e[0]
            ok = np.abs(denom) > 1e-300
            den = np.where(ok, denom, 1.0)
            wx, wy = ra - x[0], za - x[1]
            t = (wx * e[1] - wy * e[0]) / den
            u = (wx * d[:, 1] - wy * d[:, 0]) / den
            hit |= ok & (t > lo) & (t < hi) & (u >= 0.0) & (u <= 1.0)
            continue
        dz_face = zb - za
        if abs(dz_face) > 1e-12 * max(1.0, abs(za), abs(zb), abs(ra), abs(rb)):
            # the cone r = c0 + c1 t along the ray; crossing: |ray_xy(t)|² = r(t)²
            slope = (rb - ra) / dz_face
            c0 = ra + (x[2] - za) * slope
            c1 = d[:, 2] * slope
            qa = d[:, 0] ** 2 + d[:, 1] ** 2 - c1**2
            qb = 2.0 * (x[0] * d[:, 0] + x[1] * d[:, 1] - c0 * c1)
            qc = x[0] ** 2 + x[1] ** 2 - c0**2
            disc = qb * qb - 4.0 * qa * qc
            real = (disc >= 0.0) & (np.abs(qa) > 1e-300)
            root = np.sqrt(np.where(real, disc, 0.0))
            qa_safe = np.where(real, qa, 1.0)
            for t in ((-qb - root) / (2.0 * qa_safe), (-qb + root) / (2.0 * qa_safe)):
                u = (x[2] + t * d[:, 2] - za) / dz_face
                hit |= real & (t > lo) & (t < hi) & (u >= 0.0) & (u <= 1.0) & \
                    (c0 + c1 * t >= 0.0)
        else:  # a flat annulus z = za between radii ra and rb
            ok = np.abs(d[:, 2]) > 1e-300
            t = np.where(ok, (za - x[2]) / np.where(ok, d[:, 2], 1.0), -1.0)
            rr = np.hypot(x[0] + t * d[:, 0], x[1] + t * d[:, 1])
            hit |= ok & (t > lo) & (t < hi) & (rr >= min(ra, rb)) & (rr <= max(ra, rb))
    return hit


def average_view_factor(F: np.ndarray, area: np.ndarray, source: np.ndarray,
                        target: np.ndarray) -> float:
    """VFQUERY's average: Σ_i A_i Σ_j F_ij / Σ_i A_i over source faces i, target faces j."""
    if not source.any():
        return 0.0
    return float((area[source] * F[np.ix_(source, target)].sum(axis=1)).sum() /
                 area[source].sum())
