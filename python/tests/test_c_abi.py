"""Every answer of the package equals, bit for bit, what the C ABI of the same crate answers
on the same inputs: the exact check per pair, the clearance, the protective verdict over a
run (with and without stop paths), table mode and the clearance bound."""

from __future__ import annotations

import ctypes

import numpy as np
import pytest
from conftest import (
    DcPairResult,
    DcProtectiveReport,
    DcQueryReport,
    DcStopPath,
    DcVec3,
    Handle,
    random_tcps,
    toward_each_other,
    vec3s,
)

import delta_collide as dc

DC_STATUS_OK, DC_STATUS_UNREACHABLE = 0, 3
DC_VERDICT_FREE, DC_VERDICT_COLLISION = 1, 2


def bits(a) -> np.ndarray:
    return np.asarray(a, dtype=np.float64).view(np.uint64)


def mixed_configurations(cell: dc.Cell, seed: int, n: int) -> np.ndarray:
    """Random configurations, unreachable ones among them, and (two-robot cells) many that
    collide or nearly do."""
    rng = np.random.default_rng(seed)
    parts = [random_tcps(rng, n, cell.n_robots)]
    if cell.n_robots == 2:
        parts.append(toward_each_other(cell, rng, n))
    return np.ascontiguousarray(np.concatenate(parts))


def test_check_equals_dc_query_and_pair_results(cabi, cell_file):
    cell = dc.Cell.from_file(cell_file)
    tcps = mixed_configurations(cell, 1, 1500)
    ours = dc.check(cell, tcps)
    n_pairs = len(cell.pairs)
    pairs = (DcPairResult * max(n_pairs, 1))()
    got_len = ctypes.c_size_t()
    verdict = ctypes.c_uint32()
    report = DcQueryReport()
    with Handle(cabi, cell_file) as h:
        assert cabi.dc_pair_count(h.h) == n_pairs
        for i, config in enumerate(tcps):
            status = cabi.dc_query(h.h, vec3s(config), cell.n_robots, ctypes.byref(verdict), ctypes.byref(report))
            assert status in (DC_STATUS_OK, DC_STATUS_UNREACHABLE), (i, status)
            assert ours.reachable[i] == (status == DC_STATUS_OK), i
            assert ours.collide[i] == (status == DC_STATUS_OK and verdict.value == DC_VERDICT_COLLISION), i
            # The pairs of reachable robots are decided even when another TCP is unreachable.
            if cabi.dc_pair_results(h.h, pairs, n_pairs, ctypes.byref(got_len)) == DC_STATUS_OK:
                assert got_len.value == n_pairs
                for k in range(n_pairs):
                    assert (pairs[k].robot_a, pairs[k].robot_b) == cell.pairs[k]
                    assert ours.pairs[i, k] == bool(pairs[k].collides), (i, k)
    # The inputs must exercise both answers, or the comparison shows little.
    assert ours.reachable.any() and (~ours.reachable).any()
    if cell.n_robots == 2:
        assert ours.collide.any() and (ours.reachable & ~ours.collide).any()


def test_clearance_equals_the_protective_reports_clearance(cabi, cell_file):
    """The C ABI gives the exact clearance in the protective report; a fresh handle per
    configuration, so that no earlier tick's warm start is involved."""
    cell = dc.Cell.from_file(cell_file)
    tcps = mixed_configurations(cell, 2, 150)
    ours = dc.clearance(cell, tcps)
    verdict = ctypes.c_uint32()
    report = DcProtectiveReport()
    for i, config in enumerate(tcps):
        with Handle(cabi, cell_file) as h:
            status = cabi.dc_protective_query(
                h.h, vec3s(config), cell.n_robots, ctypes.byref(verdict), ctypes.byref(report)
            )
        if status == DC_STATUS_OK:
            assert bits(ours[i]) == bits(report.clearance_mm), (i, ours[i], report.clearance_mm)
        else:
            assert status == DC_STATUS_UNREACHABLE and np.isnan(ours[i]), (i, status)
    assert np.isfinite(ours).any() and np.isnan(ours).any()
    if cell.n_robots == 2:
        assert (ours < 0).any() and (ours > 0).any()


def approach(cell: dc.Cell, ticks: int) -> np.ndarray:
    """Two robots moving toward each other and back at a plausible speed (a smooth cosine, at
    most 2.4 m/s at 1 ms ticks): FREE far apart, WARN and STOP near."""
    s = 0.5 - 0.5 * np.cos(np.linspace(0.0, 2.0 * np.pi, ticks))
    run = np.empty((ticks, cell.n_robots, 3))
    for j in range(cell.n_robots):
        sign = 1.0 if j % 2 == 0 else -1.0
        run[:, j, 0] = sign * (-150.0 + 380.0 * s)
        run[:, j, 1] = 20.0 * j
        run[:, j, 2] = -450.0 - 40.0 * s
    return run


def stop_paths(run: np.ndarray, points: int) -> np.ndarray:
    """Each robot's recorded run ahead as its stop path: `points` samples of the next ticks."""
    t = len(run)
    idx = np.minimum(np.arange(t)[:, None] + 3 * np.arange(points)[None, :], t - 1)
    return np.ascontiguousarray(run[idx].transpose(0, 2, 1, 3))


def c_protective(cabi, cell_file, cell, run, warn_mm, paths=None, tolerance=0.0, table_path=None):
    n = cell.n_robots
    configs = (type(cabi.dc_stop_config_default()) * n)()
    for j, r in enumerate(cell.robots):
        c = cabi.dc_stop_config_default()
        c.reaction_ms = r["stop"]["reaction_ms"]
        c.decel_mm_s2 = r["stop"]["decel_mm_s2"]
        c.max_accel_mm_s2 = r["stop"]["max_accel_mm_s2"]
        c.max_speed_mm_s = r["stop"]["max_speed_mm_s"]
        configs[j] = c
    out = {k: [] for k in ("verdict", "status", "clearance", "protective_mm", "speed_limit")}
    verdict = ctypes.c_uint32()
    report = DcProtectiveReport()
    with Handle(cabi, cell_file, table_path) as h:
        assert cabi.dc_set_stop_model(h.h, cell.tick_ms, warn_mm, configs, n) == DC_STATUS_OK
        for i, config in enumerate(run):
            if paths is None:
                status = cabi.dc_protective_query(h.h, vec3s(config), n, ctypes.byref(verdict), ctypes.byref(report))
            else:
                keep = []
                cpaths = (DcStopPath * n)()
                for j in range(n):
                    pts = vec3s(paths[i, j])
                    keep.append(pts)
                    cpaths[j] = DcStopPath(ctypes.cast(pts, ctypes.POINTER(DcVec3)), len(pts), tolerance)
                status = cabi.dc_protective_query_with_paths(
                    h.h, vec3s(config), n, cpaths, n, ctypes.byref(verdict), ctypes.byref(report)
                )
            out["verdict"].append(verdict.value)
            out["status"].append(status)
            out["clearance"].append(report.clearance_mm)
            out["protective_mm"].append(list(report.protective_mm[:n]))
            out["speed_limit"].append(list(report.speed_limit_mm_s[:n]))
    return {k: np.array(v) for k, v in out.items()}


@pytest.mark.parametrize("name", ["t1", "t3"])
@pytest.mark.parametrize("with_paths", [False, True])
def test_protective_equals_dc_protective_query(cabi, name, with_paths):
    from conftest import REPO

    cell_file = REPO / "cells" / f"{name}.toml"
    cell = dc.Cell.from_file(cell_file)
    run = approach(cell, 240)
    paths = stop_paths(run, 8) if with_paths else None
    ours = dc.protective(cell, run, paths, path_tolerance_mm=1.0, warn_mm=10.0)
    theirs = c_protective(cabi, cell_file, cell, run, 10.0, paths, 1.0)
    assert np.array_equal(ours.verdict, theirs["verdict"])
    assert np.array_equal(ours.status, theirs["status"])
    for key in ("clearance", "protective_mm", "speed_limit"):
        assert np.array_equal(bits(getattr(ours, key)), bits(theirs[key])), key
    # A run that shows all three verdicts compares something.
    assert {0, 1, 3} <= set(ours.verdict.tolist())


def test_table_mode_equals_dc_query_and_clearance_bound(cabi, tmp_path):
    from conftest import REPO

    cell_file = REPO / "cells" / "t1.toml"
    cell = dc.Cell.from_file(cell_file)
    table = dc.Table.build(cell, 16, "clearance")
    path = tmp_path / "t1c16.dct"
    table.save(path)
    loaded = dc.Table.load(path, cell)
    tcps = mixed_configurations(cell, 3, 800)
    for confirm, c_confirm in (("exact", 1), ("none", 0)):
        ours = loaded.query(tcps, confirm=confirm)
        bound = loaded.clearance_bound(tcps)
        verdict = ctypes.c_uint32()
        report = DcQueryReport()
        mm = ctypes.c_double()
        with Handle(cabi, cell_file, path) as h:
            assert cabi.dc_set_table_confirmation(h.h, c_confirm) == DC_STATUS_OK
            for i, config in enumerate(tcps):
                status = cabi.dc_query(h.h, vec3s(config), 2, ctypes.byref(verdict), ctypes.byref(report))
                assert ours.reachable[i] == (status == DC_STATUS_OK), i
                assert ours.collide[i] == (status == DC_STATUS_OK and verdict.value == DC_VERDICT_COLLISION), i
                status = cabi.dc_table_clearance_bound(h.h, vec3s(config), 2, ctypes.byref(mm))
                if status == DC_STATUS_OK:
                    assert bits(bound[i]) == bits(mm.value), (i, bound[i], mm.value)
                else:
                    assert np.isnan(bound[i]), i
        assert ours.collide.any() and (ours.reachable & ~ours.collide).any()
    assert np.isfinite(bound).any() and np.isneginf(bound).any()


def test_bundle_mode_equals_dc_query_and_pair_results(cabi, tmp_path):
    """A line of four robots: one table per relative placement that can meet, in a bundle."""
    from conftest import REPO

    cell_file = REPO / "cells" / "line4.toml"
    cell = dc.Cell.from_file(cell_file)
    bundle = dc.Table.build(cell, 16, "clearance")
    info = bundle.inspect()
    assert info["bundle"] and len(info["pairs"]) == len(cell.pairs)
    path = tmp_path / "line4.dcb"
    bundle.save(path)
    loaded = dc.Table.load(path, cell)
    rng = np.random.default_rng(9)
    # Neighbours reaching toward each other, so that pairs of the line collide.
    tcps = random_tcps(rng, 1500, 4)
    tcps[:, :, 0] = rng.uniform(-250.0, 250.0, (1500, 4))
    tcps[:, :, 2] = rng.uniform(-520.0, -380.0, (1500, 4))
    tcps = np.ascontiguousarray(tcps)
    n_pairs = len(cell.pairs)
    pairs = (DcPairResult * n_pairs)()
    got_len = ctypes.c_size_t()
    for confirm, c_confirm in (("exact", 1), ("none", 0)):
        ours = loaded.query(tcps, confirm=confirm)
        verdict = ctypes.c_uint32()
        report = DcQueryReport()
        with Handle(cabi, cell_file, path) as h:
            assert cabi.dc_set_table_confirmation(h.h, c_confirm) == DC_STATUS_OK
            for i, config in enumerate(tcps):
                status = cabi.dc_query(h.h, vec3s(config), 4, ctypes.byref(verdict), ctypes.byref(report))
                assert ours.reachable[i] == (status == DC_STATUS_OK), i
                assert ours.collide[i] == (status == DC_STATUS_OK and verdict.value == DC_VERDICT_COLLISION), i
                assert cabi.dc_pair_results(h.h, pairs, n_pairs, ctypes.byref(got_len)) == DC_STATUS_OK
                assert [bool(pairs[k].collides) for k in range(n_pairs)] == ours.pairs[i].tolist(), i
        assert ours.collide.any() and (ours.reachable & ~ours.collide).any()
    # The bundle's bound (the least of its pairs') never exceeds the exact clearance.
    bound, exact = loaded.clearance_bound(tcps), dc.clearance(cell, tcps)
    proved = np.isfinite(bound)
    assert proved.any() and (bound[proved] <= exact[proved]).all()


def test_protective_in_table_mode_equals_dc_protective_query(cabi, tmp_path):
    """With a clearance table the protective verdict may answer a tick from the table's bound
    alone (table mode's `dc_protective_query`): the same answers, tick by tick."""
    from conftest import REPO

    cell_file = REPO / "cells" / "t1.toml"
    cell = dc.Cell.from_file(cell_file)
    table = dc.Table.build(cell, 16, "clearance")
    path = tmp_path / "t1c16.dct"
    table.save(path)
    # Apart and slow most of the time, so that the bound proves ticks; near at the middle.
    run = approach(cell, 400)
    ours = dc.protective(cell, run, table=table)
    plain = dc.protective(cell, run)
    theirs = c_protective(cabi, cell_file, cell, run, 10.0, table_path=path)
    assert np.array_equal(ours.verdict, theirs["verdict"])
    assert np.array_equal(ours.status, theirs["status"])
    for key in ("clearance", "protective_mm", "speed_limit"):
        assert np.array_equal(bits(getattr(ours, key)), bits(theirs[key])), key
    # The table changes what is proved, never the exact clearance.
    assert np.array_equal(bits(ours.clearance), bits(plain.clearance))
    with pytest.raises(ValueError, match="table was built for cell"):
        dc.protective(dc.Cell.reference("T2"), run, table=table)
