"""Properties that hold for every configuration, searched with hypothesis: the clearance's
sign is the exact check's verdict, a common rigid motion of the cell changes neither, a
margin never turns a collision into free, a table's FREE and its clearance bound never
contradict the exact model, table mode with confirmation answers as exact mode, and a FREE
protective verdict comes only with a positive clearance."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import delta_collide as dc

# Inside this band around touching the separating axis test's own tolerances decide.
TOUCH_BAND_MM = 1e-6

SETTINGS = settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])


def tcp():
    """A TCP of a robot's MCS over its workspace and a little past it."""
    return st.tuples(
        st.floats(-300.0, 300.0), st.floats(-300.0, 300.0), st.floats(-700.0, -250.0)
    ).map(list)


def near_pair(cell_name: str):
    """Two TCPs (each robot's MCS) near the segment between the bases: where robots meet."""
    x = st.floats(50.0, 400.0)
    return st.tuples(x, st.floats(-80.0, 80.0), st.floats(-650.0, -300.0), x, st.floats(-80.0, 80.0),
                     st.floats(-650.0, -300.0)).map(
        lambda v: [[v[0], v[1], v[2]], [v[3] - 450.0, v[4], v[5]]]
    )


def configs(n=8):
    return st.lists(st.one_of(st.tuples(tcp(), tcp()).map(list), near_pair("T1")), min_size=1, max_size=n)


def cell_toml(alpha_deg: float, t: tuple[float, float], margin: float = 0.0, rot_deg: float = 0.0,
              shift=(0.0, 0.0)) -> str:
    """A two-robot cell, B placed at `alpha_deg`, `t` from A, the whole cell turned by
    `rot_deg` about z and moved by `shift` (a common rigid motion), every box grown by
    `margin`."""
    r = math.radians(rot_deg)
    c, s = math.cos(r), math.sin(r)
    a = (shift[0], shift[1])
    b = (c * t[0] - s * t[1] + shift[0], s * t[0] + c * t[1] + shift[1])
    robot = 'model = {{ margin = {m!r} }}\nplacement = {{ alpha_deg = {al!r}, t = [{x!r}, {y!r}, 0.0] }}\n'
    return (
        'name = "P"\n'
        f'[[robot]]\nname = "A"\n' + robot.format(m=margin, al=rot_deg, x=a[0], y=a[1])
        + f'[[robot]]\nname = "B"\n' + robot.format(m=margin, al=alpha_deg + rot_deg, x=b[0], y=b[1])
    )


T1 = dc.Cell.reference("T1")
T3 = dc.Cell.reference("T3")
TABLE = None


def table():
    global TABLE
    if TABLE is None:
        TABLE = dc.Table.build(T1, 16, "clearance")
    return TABLE


def arr(c) -> np.ndarray:
    return np.ascontiguousarray(np.array(c, dtype=np.float64))


@SETTINGS
@given(configs())
def test_clearance_sign_is_the_exact_verdict(c):
    for cell in (T1, T3):
        tcps = arr(c)
        k = dc.check(cell, tcps)
        d = dc.clearance(cell, tcps)
        assert np.array_equal(np.isnan(d), ~k.reachable)
        clear = k.reachable & (np.abs(d) > TOUCH_BAND_MM)
        assert np.array_equal(k.collide[clear], d[clear] < 0)


@SETTINGS
@given(configs(), st.floats(-180.0, 180.0), st.floats(-2000.0, 2000.0), st.floats(-2000.0, 2000.0))
def test_a_common_rigid_motion_changes_nothing(c, rot_deg, sx, sy):
    base = dc.Cell.from_toml(cell_toml(30.0, (430.0, 150.0)))
    moved = dc.Cell.from_toml(cell_toml(30.0, (430.0, 150.0), rot_deg=rot_deg, shift=(sx, sy)))
    tcps = arr(c)
    d0, d1 = dc.clearance(base, tcps), dc.clearance(moved, tcps)
    assert np.array_equal(np.isnan(d0), np.isnan(d1))
    ok = ~np.isnan(d0)
    # Rounding of coordinates a few metres from the origin: far below a micrometre.
    np.testing.assert_allclose(d1[ok], d0[ok], atol=1e-8)
    k0, k1 = dc.check(base, tcps), dc.check(moved, tcps)
    clear = ok & (np.abs(d0) > 1e-6)
    assert np.array_equal(k0.collide[clear], k1.collide[clear])


@SETTINGS
@given(configs(), st.floats(0.0, 30.0))
def test_a_margin_never_turns_a_collision_into_free(c, margin):
    plain = dc.Cell.from_toml(cell_toml(0.0, (450.0, 0.0)))
    grown = dc.Cell.from_toml(cell_toml(0.0, (450.0, 0.0), margin=margin))
    tcps = arr(c)
    k0, k1 = dc.check(plain, tcps), dc.check(grown, tcps)
    assert not (k0.collide & ~k1.collide).any()
    d0, d1 = dc.clearance(plain, tcps), dc.clearance(grown, tcps)
    ok = ~np.isnan(d0)
    # Each box grown by m holds the other's points within m of it: the gap shrinks by 2 m
    # at least while the boxes stay apart, and never grows.
    assert (d1[ok] <= d0[ok] + 1e-9).all()
    apart = ok & (d1 > 1e-6)
    assert (d1[apart] <= d0[apart] - 2 * margin + 1e-6).all()


@SETTINGS
@given(configs(16))
def test_a_table_never_contradicts_the_exact_model(c):
    tcps = arr(c)
    t = table()
    labels = t.query(tcps, confirm="none")
    confirmed = t.query(tcps, confirm="exact")
    exact = dc.check(T1, tcps)
    assert np.array_equal(confirmed.reachable, exact.reachable)
    assert np.array_equal(confirmed.collide, exact.collide)
    free = labels.reachable & ~labels.collide
    assert not exact.collide[free].any()
    bound = t.clearance_bound(tcps)
    d = dc.clearance(T1, tcps)
    proved = np.isfinite(bound)
    assert (bound[proved] <= d[proved]).all()


@settings(max_examples=25, deadline=None)
@given(st.lists(near_pair("T1"), min_size=1, max_size=4), st.integers(5, 30))
def test_a_free_protective_verdict_keeps_the_robots_apart(points, hold):
    # The robots stand at each point for `hold` ticks: speeds measured as zero after the first.
    run = arr(np.repeat(np.array(points), hold, axis=0))
    p = dc.protective(T1, run)
    free = p.verdict == dc.VERDICT_FREE
    assert (p.status[free] == 0).all()
    assert (p.clearance[free] > 0).all()
    warn_or_free = p.verdict != dc.VERDICT_STOP
    assert (p.clearance[warn_or_free] > 0).all()
    # Colliding boxes are always STOP.
    assert (p.verdict[p.clearance < 0] == dc.VERDICT_STOP).all()
