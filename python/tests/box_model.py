"""The robots' boxes rebuilt in numpy from a Cell's fields alone (SPEC section 2: elbow-out
inverse kinematics with motor limits; section 3: one box per lower link, centre (G + E) / 2,
x = (E - G) / |E - G|, z = x cross t normalised, y = z cross x, half-extents re / 2, H, D
plus the margin; section 1: p_wcs = Rz(alpha) p_mcs + t), so that the oracles below measure
boxes that the library did not make. Lower links only: the reference cells have no other."""

from __future__ import annotations

import numpy as np

RADIAL = np.array([[1.0, 0.0], [-0.5, np.sqrt(3.0) / 2.0], [-0.5, -np.sqrt(3.0) / 2.0]])


def robot_boxes(robot: dict, tcps: np.ndarray):
    """Robot `robot` (a ``Cell.robots`` entry) at TCPs (N, 3) of its MCS: ``reachable`` (N,),
    ``centers`` (N, 3, 3), ``axes`` (N, 3, 3, 3) (columns), ``half`` (3,) in the WCS."""
    g, m = robot["geometry"], robot["model"]
    if m["upper_links"] is not None or m["platform"] is not None or m["tool"] is not None:
        raise NotImplementedError("the oracle models lower links only")
    f, rf, re, e = g["f"], g["rf"], g["re"], g["e"]
    x, y, z = tcps[:, 0], tcps[:, 1], tcps[:, 2]
    n = len(tcps)
    reachable = z < 0.0
    centers = np.empty((n, 3, 3))
    axes = np.empty((n, 3, 3, 3))
    for arm, (ux, uy) in enumerate(RADIAL):
        a = x * ux + y * uy + (e - f)
        b = -x * uy + y * ux
        r2 = a * a + z * z
        k = (r2 + rf * rf - (re * re - b * b)) / (2.0 * rf)
        ok = (b * b <= re * re) & (k * k <= r2) & (r2 > 0)
        s = -np.sqrt(np.where(ok, r2 - k * k, 0.0))
        cos_t, sin_t = (a * k + z * s) / r2, (a * s - z * k) / r2
        theta = np.arctan2(sin_t, cos_t)
        ok &= (theta >= g["theta_min"] - 1e-12) & (theta <= g["theta_max"] + 1e-12)
        reachable &= ok
        elbow = np.stack([ux * (f + rf * cos_t), uy * (f + rf * cos_t), -rf * sin_t], axis=1)
        joint = tcps + e * np.array([ux, uy, 0.0])
        xa = (joint - elbow) / np.linalg.norm(joint - elbow, axis=1)[:, None]
        t = np.array([-uy, ux, 0.0])
        za = np.cross(xa, t)
        za /= np.linalg.norm(za, axis=1)[:, None]
        ya = np.cross(za, xa)
        centers[:, arm] = 0.5 * (elbow + joint)
        axes[:, arm] = np.stack([xa, ya, za], axis=2)
    mg = m["margin"]
    half = np.array([0.5 * re + mg, m["half_height"] + mg, m["half_depth"] + mg])
    pl = robot["placement"]
    ca, sa = np.cos(pl["alpha"]), np.sin(pl["alpha"])
    rot = np.array([[ca, -sa, 0.0], [sa, ca, 0.0], [0.0, 0.0, 1.0]])
    centers = centers @ rot.T + np.array(pl["t"])
    axes = np.einsum("ij,nbjk->nbik", rot, axes)
    return reachable, centers, axes, half
