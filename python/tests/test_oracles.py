"""`clearance` against two independent oracles on a few thousand random configurations per
reference cell: Coal's signed distance (GJK, EPA when boxes intersect) and python-fcl's
distance and collision test, both on boxes rebuilt from the Cell's fields (box_model.py)."""

from __future__ import annotations

import os

import numpy as np
import pytest
from box_model import robot_boxes
from conftest import random_tcps, toward_each_other

import delta_collide as dc

if os.environ.get("CI"):
    # Under CI the oracles are installed by tests/python.rs: missing is a failure.
    import coal
    import fcl
else:
    coal = pytest.importorskip("coal")
    fcl = pytest.importorskip("fcl")

# Coal's GJK and EPA stop at a tolerance far below 1e-6 mm here (4e-8 seen); the
# library's clearance is exact to rounding (1e-13 mm), so agreement within this says both
# measure the same boxes.
TOLERANCE_MM = 1e-6
# Inside this band around touching the separating axis test's tolerances decide (SPEC 3);
# outside it the collision test of FCL must agree with the sign of the clearance.
TOUCH_BAND_MM = 1e-6


def oracle_boxes(cell: dc.Cell, tcps: np.ndarray):
    per_robot = [robot_boxes(cell.robots[j], tcps[:, j]) for j in range(2)]
    reachable = per_robot[0][0] & per_robot[1][0]
    return reachable, per_robot


def configurations(cell: dc.Cell, seed: int, n: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return np.ascontiguousarray(np.concatenate([random_tcps(rng, n, 2), toward_each_other(cell, rng, n)]))


@pytest.mark.parametrize("name", ["T1", "T2", "T3"])
def test_boxes_rebuilt_from_the_fields_are_the_librarys(name):
    """The oracle's boxes are the library's (to rounding), so the oracles test the
    clearance, not a different model."""
    cell = dc.Cell.reference(name)
    tcps = configurations(cell, 11, 500)
    lib = dc.boxes(cell, tcps)
    reachable, per_robot = oracle_boxes(cell, tcps)
    ours = dc.check(cell, tcps).reachable
    assert np.array_equal(reachable, ours)
    for j, (_, centers, axes, half) in enumerate(per_robot):
        np.testing.assert_allclose(lib.centers[reachable, j, :3], centers[reachable], atol=1e-9)
        np.testing.assert_allclose(lib.axes[reachable, j, :3], axes[reachable], atol=1e-12)
        np.testing.assert_allclose(lib.half[reachable, j, :3], np.broadcast_to(half, (reachable.sum(), 3, 3)))


def coal_signed(ca, aa, ha, cb, ab, hb) -> float:
    req = coal.DistanceRequest()
    best = np.inf
    for i in range(3):
        for k in range(3):
            res = coal.DistanceResult()
            d = coal.distance(
                coal.Box(*(2 * ha)),
                coal.Transform3s(aa[i], ca[i]),
                coal.Box(*(2 * hb)),
                coal.Transform3s(ab[k], cb[k]),
                req,
                res,
            )
            best = min(best, d)
    return best


def fcl_pair(ca, aa, ha, cb, ab, hb):
    """FCL's smallest distance over the box pairs (0 when some intersect) and whether any
    intersect."""
    dist, hit = np.inf, False
    for i in range(3):
        for k in range(3):
            o1 = fcl.CollisionObject(fcl.Box(*(2 * ha)), fcl.Transform(aa[i], ca[i]))
            o2 = fcl.CollisionObject(fcl.Box(*(2 * hb)), fcl.Transform(ab[k], cb[k]))
            hit |= fcl.collide(o1, o2, fcl.CollisionRequest(), fcl.CollisionResult()) > 0
            dist = min(dist, max(0.0, fcl.distance(o1, o2, fcl.DistanceRequest(), fcl.DistanceResult())))
    return dist, hit


@pytest.mark.parametrize("name", ["T1", "T2", "T3"])
def test_clearance_agrees_with_coal_and_fcl(name):
    cell = dc.Cell.reference(name)
    tcps = configurations(cell, 12, 6000)
    tcps = np.ascontiguousarray(tcps[dc.check(cell, tcps).reachable][:2500])
    ours = dc.clearance(cell, tcps)
    reachable, per_robot = oracle_boxes(cell, tcps)
    assert np.array_equal(np.isfinite(ours), reachable)
    (_, ca, aa, ha), (_, cb, ab, hb) = per_robot
    idx = np.flatnonzero(reachable)
    assert len(idx) >= 2000, "too few reachable configurations to say much"
    worst_coal = worst_fcl = 0.0
    signs = 0
    for i in idx:
        c = coal_signed(ca[i], aa[i], ha, cb[i], ab[i], hb)
        worst_coal = max(worst_coal, abs(c - ours[i]))
        assert abs(c - ours[i]) <= TOLERANCE_MM, (name, i, tcps[i].tolist(), ours[i], c)
        d, hit = fcl_pair(ca[i], aa[i], ha, cb[i], ab[i], hb)
        if abs(ours[i]) > TOUCH_BAND_MM:
            assert hit == (ours[i] < 0), (name, i, tcps[i].tolist(), ours[i])
            signs += 1
        if ours[i] > 0:
            worst_fcl = max(worst_fcl, abs(d - ours[i]))
            assert abs(d - ours[i]) <= TOLERANCE_MM, (name, i, tcps[i].tolist(), ours[i], d)
    print(f"{name}: {len(idx)} configurations, largest difference Coal {worst_coal:.2e} mm, FCL {worst_fcl:.2e} mm")
    assert signs > 0.99 * len(idx)
    # Both signs were seen, so penetration depths were compared too.
    assert (ours[idx] < 0).sum() > 50 and (ours[idx] > 0).sum() > 50
