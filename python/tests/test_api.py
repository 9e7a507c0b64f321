"""The package's contract: fields, argument checking with ValueError naming the argument,
the library's errors as exceptions with its messages, `out=` forms that allocate nothing,
the GIL released during the work, tables, the closed-loop run and the pictures."""

from __future__ import annotations

import threading
import time

import numpy as np
import pytest
from conftest import REPO, random_tcps, toward_each_other

import delta_collide as dc
from delta_collide import _native


@pytest.fixture(scope="module")
def t1():
    return dc.Cell.reference("T1")


@pytest.fixture(scope="module")
def table16(t1):
    return dc.Table.build(t1, 16, "clearance")


def test_every_field_reads_as_the_cell_file_says(tmp_path):
    text = (REPO / "cells" / "t3.toml").read_text()
    cell = dc.Cell.from_file(REPO / "cells" / "t3.toml")
    assert cell.name == "T3" and cell.n_robots == 2 and cell.pairs == [(0, 1)]
    b = cell.robots[1]
    assert b["placement"]["t"] == [430.0, 150.0, 0.0]
    assert b["placement"]["alpha"] == pytest.approx(np.pi / 6, abs=1e-15)
    assert b["geometry"]["re"] == 400.0 and b["model"]["half_depth"] == 17.5
    assert cell.fingerprint == dc.Cell.reference("T3").fingerprint
    edited = text.replace('name = "T3"', 'name = "T3b"\ntick_ms = 2.0\ntable_confirm = "none"', 1)
    edited += "\n" if not edited.endswith("\n") else ""
    changed = dc.Cell.from_toml(edited)
    assert changed.name == "T3b" and changed.tick_ms == 2.0 and changed.table_confirm == "none"
    assert cell.parameters["robot 1: placement.translation.y"] == 150.0
    assert changed.box_counts == [3, 3] and cell.method in ("sat", "sat-cache")


def test_the_librarys_errors_carry_its_messages(tmp_path):
    with pytest.raises(dc.CellError, match="cannot read cell file: .*nope.toml"):
        dc.Cell.from_file(tmp_path / "nope.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text('name = "x"\n[[robot]]\nname = "A"\nmodel = { margin = -1.0 }\n')
    with pytest.raises(dc.CellError, match=r"invalid cell: robot 0 \(A\): model.margin = -1"):
        dc.Cell.from_file(bad)
    with pytest.raises(ValueError, match="no reference cell"):
        dc.Cell.reference("T9")
    garbage = tmp_path / "garbage.dct"
    garbage.write_bytes(b"not a table at all, just bytes")
    with pytest.raises(dc.TableError, match="garbage.dct"):
        dc.Table.load(garbage, dc.Cell.reference("T1"))
    with pytest.raises(dc.BuildError, match="power of two|k"):
        dc.Table.build(dc.Cell.reference("T1"), 12, "shared")
    t2 = dc.Table.build(dc.Cell.reference("T2"), 16, "shared")
    t2.save(tmp_path / "t2.dct")
    with pytest.raises(dc.TableError, match="cell"):
        dc.Table.load(tmp_path / "t2.dct", dc.Cell.reference("T1"))


@pytest.mark.parametrize(
    "make, why",
    [
        (lambda t: t.astype(np.float32), "dtype float64"),
        (lambda t: t.tolist(), "numpy array"),
        (lambda t: t[:, :1], r"shape \(N, 2, 3\)"),
        (lambda t: t[..., :2].copy(), r"shape \(N, 2, 3\)"),
        (lambda t: np.asfortranarray(t), "C-contiguous"),
        (lambda t: t[::2], "C-contiguous"),
    ],
)
def test_wrong_input_names_the_argument(t1, make, why):
    tcps = random_tcps(np.random.default_rng(0), 8, 2)
    bad = make(tcps)
    for call in (dc.clearance, dc.check, dc.boxes):
        with pytest.raises(ValueError, match="tcps.*" + why if "shape" in why else "tcps"):
            call(t1, bad)
    with pytest.raises(ValueError, match="run"):
        dc.protective(t1, bad)


def test_non_finite_input_names_the_element(t1, table16):
    tcps = random_tcps(np.random.default_rng(0), 8, 2)
    tcps[5, 1, 2] = np.inf
    for call in (dc.clearance, dc.check, table16.query, table16.clearance_bound):
        with pytest.raises(ValueError, match=r"tcps\[5, 1, 2\] = inf"):
            call(t1, tcps) if call in (dc.clearance, dc.check) else call(tcps)
    with pytest.raises(ValueError, match=r"run\[5, 1, 2\] = inf"):
        dc.protective(t1, tcps)


def test_wrong_outputs_name_the_argument(t1):
    tcps = random_tcps(np.random.default_rng(0), 8, 2)
    with pytest.raises(ValueError, match="out has shape"):
        dc.clearance(t1, tcps, out=np.empty(7))
    with pytest.raises(ValueError, match="out must be a numpy array of dtype float64"):
        dc.clearance(t1, tcps, out=np.empty(8, dtype=np.float32))
    ro = np.empty(8)
    ro.flags.writeable = False
    with pytest.raises(ValueError, match="out must be writeable"):
        dc.clearance(t1, tcps, out=ro)
    out = dc.check(t1, tcps)
    out.pairs = np.empty((8, 2), dtype=bool)
    with pytest.raises(ValueError, match="pairs has shape"):
        dc.check(t1, tcps, out=out)


def work_allocations(call) -> tuple[int, int]:
    before = _native._alloc_counts()
    call()
    after = _native._alloc_counts()
    return after[0] - before[0], after[1] - before[1]


def test_out_forms_allocate_nothing_in_the_library(t1, table16):
    """Counted by the extension's global allocator: nothing while the library works, and at
    most numpy's borrow bookkeeping around it."""
    rng = np.random.default_rng(4)
    tcps = np.ascontiguousarray(np.concatenate([random_tcps(rng, 3000, 2), toward_each_other(t1, rng, 3000)]))
    run = np.ascontiguousarray(np.repeat(tcps[:1], 50, axis=0))
    c, k = dc.clearance(t1, tcps), dc.check(t1, tcps)
    q, b = table16.query(tcps), table16.clearance_bound(tcps)
    bx = dc.boxes(t1, tcps[:100])
    p = dc.protective(t1, run)
    calls = {
        "clearance": lambda: dc.clearance(t1, tcps, out=c),
        "check": lambda: dc.check(t1, tcps, out=k),
        "query": lambda: table16.query(tcps, out=q),
        "clearance_bound": lambda: table16.clearance_bound(tcps, out=b),
        "boxes": lambda: dc.boxes(t1, tcps[:100], out=bx),
    }
    for name, call in calls.items():
        total, in_work = work_allocations(call)
        assert in_work == 0, f"{name}: {in_work} allocations in the library's work"
        # A handful per array for numpy's borrow flags, never per configuration.
        assert total <= 16, f"{name}: {total} allocations in the call"
    # The protective verdict: nothing in the library's work, for any length of run (the
    # checker is reset, not copied, before each run).
    long_run = np.ascontiguousarray(np.repeat(tcps[:1], 500, axis=0))
    p_long = dc.protective(t1, long_run)
    short = work_allocations(lambda: dc.protective(t1, run, out=p))
    long = work_allocations(lambda: dc.protective(t1, long_run, out=p_long))
    assert short[1] == 0 and long[1] == 0
    assert short[0] == long[0] <= 16, (short, long)
    # The counter counts: a build allocates in the library.
    total, in_work = work_allocations(lambda: dc.Table.build(t1, 16, "shared"))
    assert total > 100


def test_out_forms_write_the_same_answers(t1):
    tcps = toward_each_other(t1, np.random.default_rng(5), 500)
    fresh = dc.clearance(t1, tcps)
    out = np.full(500, 7.0)
    assert dc.clearance(t1, tcps, out=out) is out
    assert np.array_equal(out.view(np.uint64), fresh.view(np.uint64))


def test_the_gil_is_released_during_the_work(t1):
    """A Python thread keeps counting while clearance runs on the main thread."""
    tcps = toward_each_other(t1, np.random.default_rng(6), 300_000)
    ticks = []
    stop = threading.Event()

    def count():
        while not stop.is_set():
            ticks.append(time.perf_counter())

    thread = threading.Thread(target=count)
    thread.start()
    time.sleep(0.02)
    start = time.perf_counter()
    dc.clearance(t1, tcps)
    end = time.perf_counter()
    stop.set()
    thread.join()
    during = [t for t in ticks if start < t < end]
    assert end - start > 0.05, "too short a call to tell"
    # With the GIL held the other thread would not run at all during the call.
    assert len(during) > 1000


def test_table_inspect_and_round_trip(tmp_path, t1, table16):
    info = table16.inspect()
    assert info["variant"] == "clearance" and info["k"] == 16 and info["levels"] == 4
    assert info["cell_fingerprint"] == t1.fingerprint
    assert info["clearance_levels_mm"] == [0.0, 5.0, 10.0, 20.0, 40.0, 80.0, 160.0]
    path = tmp_path / "t.dct"
    table16.save(path)
    assert path.read_bytes() == table16.to_bytes() and info["file_bytes"] == len(table16.to_bytes())
    again = dc.Table.load(path)  # no cell: found among the reference cells by fingerprint
    assert again.cell.name == "T1"
    tcps = toward_each_other(t1, np.random.default_rng(7), 2000)
    assert np.array_equal(again.clearance_bound(tcps), table16.clearance_bound(tcps), equal_nan=True)


def test_table_build_reports_progress_and_levels(t1):
    seen = []
    table = dc.Table.build(t1, 16, "clearance", levels=[0.0, 20.0], progress=lambda d, n: seen.append((d, n)))
    assert seen and all(0 <= d <= n for d, n in seen) and max(d for d, _ in seen) == seen[0][1]
    assert table.inspect()["clearance_levels_mm"] == [0.0, 20.0]
    tcps = toward_each_other(t1, np.random.default_rng(8), 3000)
    bound = table.clearance_bound(tcps)
    assert set(np.unique(bound[np.isfinite(bound)])) <= {0.0, 20.0}
    with pytest.raises(ValueError, match="variant"):
        dc.Table.build(t1, 16, "7d")
    with pytest.raises(ValueError, match="levels"):
        dc.Table.build(t1, 16, "shared", levels=[0.0])


def test_simulate_returns_metrics_and_traces(t1):
    r = dc.simulate(t1, mode="coordinate", seed=3, ticks=1500)
    assert r["programmed_ticks"] > 0 and r["ticks"] >= r["programmed_ticks"] or not r["finished"]
    # A row per tick the robots moved on; a STOP event's simulated stop takes ticks of its own.
    rows = len(r["progress"])
    assert r["progress"].shape == (rows, 2) and rows <= r["ticks"]
    assert r["stops"].shape == (r["stop_events"], 2)
    assert sum(r["verdicts"].values()) == rows + r["stop_events"]
    assert r["programmes"].shape[0] == 2 and r["programmes"].shape[2] == 3
    assert r["contact_ticks"] == 0
    # The progress of each robot never goes back.
    assert (np.diff(r["progress"], axis=0) >= -1e-9).all()
    with pytest.raises(ValueError, match="mode"):
        dc.simulate(t1, mode="fast")


def test_pictures_are_drawn_and_saved(tmp_path, t1, table16):
    pytest.importorskip("matplotlib")
    fig = dc.render(t1, [[100.0, 0.0, -450.0], [-100.0, 0.0, -450.0]], path=tmp_path / "r.png")
    assert (tmp_path / "r.png").stat().st_size > 1000 and fig is not None
    fig = dc.quilt(table16, [-100.0, 0.0, -450.0], zs=(-450.0, -550.0), path=tmp_path / "q.png", n=40)
    images = fig.quilt_images
    # A slice through B's place collides, far from it is free, the rim is unreachable.
    assert {0, 1, 2} <= set(np.unique(images).tolist())
    run = np.ascontiguousarray(np.repeat([[[0.0, 0.0, -450.0], [0.0, 0.0, -450.0]]], 20, axis=0))
    dc.plot_run(dc.protective(t1, run), path=tmp_path / "p.png")
    dc.plot_run(dc.simulate(t1, seed=1, ticks=600), path=tmp_path / "s.png")
    assert (tmp_path / "p.png").stat().st_size > 1000 and (tmp_path / "s.png").stat().st_size > 1000


def test_stop_paths_are_checked(t1):
    run = np.ascontiguousarray(np.repeat([[[0.0, 0.0, -450.0], [0.0, 0.0, -450.0]]], 4, axis=0))
    with pytest.raises(ValueError, match="paths has 33 points"):
        dc.protective(t1, run, np.zeros((4, 2, 33, 3)))
    with pytest.raises(ValueError, match=r"paths has shape \[3, 2, 2, 3\]"):
        dc.protective(t1, run, np.zeros((3, 2, 2, 3)))
    with pytest.raises(ValueError, match="path_tolerance_mm"):
        dc.protective(t1, run, np.zeros((4, 2, 2, 3)), path_tolerance_mm=-1.0)
    # A TCP farther from its path than the tolerance: STOP with DC_STATUS_INVALID_ARGUMENT (9).
    far = np.zeros((4, 2, 2, 3))
    far[..., 2] = -300.0
    p = dc.protective(t1, run, far, path_tolerance_mm=1.0)
    assert (p.verdict == dc.VERDICT_STOP).all() and (p.status == 9).all()


def test_a_run_answers_the_same_whatever_ran_before(t1):
    """Each run starts from the checker as made (no previous TCPs, no warm starts)."""
    rng = np.random.default_rng(10)
    a = toward_each_other(t1, rng, 1)
    steps = np.linspace(0.0, 1.0, 120)[:, None, None]
    run_a = np.ascontiguousarray(a + steps * np.array([[60.0, 0.0, 0.0], [-60.0, 0.0, 0.0]]))
    run_b = np.ascontiguousarray(run_a[::-1])
    first = dc.protective(t1, run_a)
    dc.protective(t1, run_b)
    again = dc.protective(t1, run_a)
    for key in ("verdict", "status", "clearance", "protective_mm", "speed_limit"):
        x, y = getattr(first, key), getattr(again, key)
        assert np.array_equal(x.view(np.uint8), y.view(np.uint8)), key
