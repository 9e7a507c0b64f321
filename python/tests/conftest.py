"""Shared pieces of the Python tests: the repository, the cells, seeded random
configurations, and the C ABI of the same crate loaded with ctypes (the shared library that
`cargo test` builds beside the static one; `DELTA_COLLIDE_CDYLIB` names it)."""

from __future__ import annotations

import ctypes
import os
from pathlib import Path

import numpy as np
import pytest

import delta_collide as dc

REPO = Path(os.environ.get("DELTA_COLLIDE_REPO", Path(__file__).resolve().parents[2]))
# Hypothesis's example database under target/, never beside the sources.
os.environ.setdefault("HYPOTHESIS_STORAGE_DIRECTORY", str(REPO / "target" / "py-hypothesis"))
CELL_FILES = ["cells/t1.toml", "cells/t2.toml", "cells/t3.toml", "cells/line4.toml"]


def random_tcps(rng: np.random.Generator, n: int, robots: int) -> np.ndarray:
    """`n` configurations of `robots` TCPs, each in its robot's MCS, over a box that holds the
    reachable workspace and reaches past it (so some TCPs are unreachable)."""
    t = np.empty((n, robots, 3))
    t[..., 0] = rng.uniform(-320.0, 320.0, (n, robots))
    t[..., 1] = rng.uniform(-320.0, 320.0, (n, robots))
    t[..., 2] = rng.uniform(-720.0, -220.0, (n, robots))
    return t


def toward_each_other(cell: dc.Cell, rng: np.random.Generator, n: int) -> np.ndarray:
    """Configurations of two robots whose TCPs lie near the segment between the bases (world
    frame), given in each robot's MCS: many collide, many nearly do."""
    ta = np.array(cell.robots[0]["placement"]["t"])
    tb = np.array(cell.robots[1]["placement"]["t"])
    ab = tb - ta
    out = np.empty((n, 2, 3))
    for j, base in ((0, ta), (1, tb)):
        s = rng.uniform(0.05, 0.6, n) if j == 0 else rng.uniform(0.4, 0.95, n)
        p = ta + s[:, None] * ab + rng.normal(0.0, 60.0, (n, 3)) * [1, 1, 0]
        p[:, 2] = rng.uniform(-650.0, -300.0, n)
        out[:, j] = to_mcs(cell, j, p)
    return out


def to_mcs(cell: dc.Cell, j: int, p_wcs: np.ndarray) -> np.ndarray:
    """World points into robot j's MCS (`p_wcs = Rz(alpha) p_mcs + t`)."""
    pl = cell.robots[j]["placement"]
    a = pl["alpha"]
    d = p_wcs - np.array(pl["t"])
    c, s = np.cos(a), np.sin(a)
    return np.stack([c * d[:, 0] + s * d[:, 1], -s * d[:, 0] + c * d[:, 1], d[:, 2]], axis=1)


class DcVec3(ctypes.Structure):
    _fields_ = [("x", ctypes.c_double), ("y", ctypes.c_double), ("z", ctypes.c_double)]


class DcQueryReport(ctypes.Structure):
    _fields_ = [
        (name, ctypes.c_uint32)
        for name in (
            "verdict",
            "colliding_pairs",
            "unreachable_mask",
            "first_robot_a",
            "first_robot_b",
            "first_box_a",
            "first_box_b",
        )
    ]


class DcPairResult(ctypes.Structure):
    _fields_ = [(name, ctypes.c_uint32) for name in ("robot_a", "robot_b", "collides", "box_a", "box_b")]


class DcProtectiveReport(ctypes.Structure):
    _fields_ = (
        [("verdict", ctypes.c_uint32), ("unreachable_mask", ctypes.c_uint32), ("clearance_mm", ctypes.c_double)]
        + [
            (name, ctypes.c_uint32)
            for name in (
                "closest_robot_a",
                "closest_robot_b",
                "closest_box_a",
                "closest_box_b",
                "limiting_robot_a",
                "limiting_robot_b",
                "limiting_box_a",
                "limiting_box_b",
                "n_robots",
            )
        ]
        + [("protective_mm", ctypes.c_double * 32), ("speed_limit_mm_s", ctypes.c_double * 32)]
    )


class DcStopConfig(ctypes.Structure):
    _fields_ = [
        ("struct_size", ctypes.c_size_t),
        ("reaction_ms", ctypes.c_double),
        ("decel_mm_s2", ctypes.c_double),
        ("max_accel_mm_s2", ctypes.c_double),
        ("max_speed_mm_s", ctypes.c_double),
    ]


class DcStopPath(ctypes.Structure):
    _fields_ = [
        ("points", ctypes.POINTER(DcVec3)),
        ("n_points", ctypes.c_size_t),
        ("tolerance_mm", ctypes.c_double),
    ]


def _cdylib_path() -> Path:
    named = os.environ.get("DELTA_COLLIDE_CDYLIB")
    if named:
        return Path(named)
    return REPO / "target" / "release" / "libdelta_collide.so"


@pytest.fixture(scope="session")
def cabi():
    """The C ABI with the signatures of include/delta_collide.h."""
    path = _cdylib_path()
    if not path.is_file():
        if os.environ.get("CI"):
            pytest.fail(f"{path} is missing: build it with cargo build --release --lib")
        pytest.skip(f"{path} is missing (cargo build --release --lib makes it)")
    lib = ctypes.CDLL(str(path))
    handle = ctypes.c_void_p
    out_handle = ctypes.POINTER(ctypes.c_void_p)
    u32, size_t, dbl = ctypes.c_uint32, ctypes.c_size_t, ctypes.c_double
    sigs = {
        "dc_init_from_cell_file": ([ctypes.c_char_p, out_handle], u32),
        "dc_init_from_files": ([ctypes.c_char_p, ctypes.c_char_p, out_handle], u32),
        "dc_destroy": ([handle], None),
        "dc_query": (
            [handle, ctypes.POINTER(DcVec3), size_t, ctypes.POINTER(u32), ctypes.POINTER(DcQueryReport)],
            u32,
        ),
        "dc_pair_results": ([handle, ctypes.POINTER(DcPairResult), size_t, ctypes.POINTER(size_t)], u32),
        "dc_pair_count": ([handle], size_t),
        "dc_protective_query": (
            [handle, ctypes.POINTER(DcVec3), size_t, ctypes.POINTER(u32), ctypes.POINTER(DcProtectiveReport)],
            u32,
        ),
        "dc_protective_query_with_paths": (
            [
                handle,
                ctypes.POINTER(DcVec3),
                size_t,
                ctypes.POINTER(DcStopPath),
                size_t,
                ctypes.POINTER(u32),
                ctypes.POINTER(DcProtectiveReport),
            ],
            u32,
        ),
        "dc_protective_reset": ([handle], None),
        "dc_set_stop_model": ([handle, dbl, dbl, ctypes.POINTER(DcStopConfig), size_t], u32),
        "dc_set_speed_limits": ([handle, u32], u32),
        "dc_stop_config_default": ([], DcStopConfig),
        "dc_table_clearance_bound": ([handle, ctypes.POINTER(DcVec3), size_t, ctypes.POINTER(dbl)], u32),
        "dc_set_table_confirmation": ([handle, u32], u32),
        "dc_last_init_error": ([ctypes.c_char_p, size_t], size_t),
    }
    for name, (args, res) in sigs.items():
        f = getattr(lib, name)
        f.argtypes, f.restype = args, res
    return lib


def vec3s(tcps: np.ndarray):
    """One configuration (robots, 3) as a C array of DcVec3."""
    arr = (DcVec3 * len(tcps))()
    for j, t in enumerate(tcps):
        arr[j] = DcVec3(*map(float, t))
    return arr


class Handle:
    """A C handle from a cell file (and a table file), destroyed on exit."""

    def __init__(self, lib, cell_path, table_path=None):
        self.lib = lib
        self.h = ctypes.c_void_p()
        if table_path is None:
            status = lib.dc_init_from_cell_file(str(cell_path).encode(), ctypes.byref(self.h))
        else:
            status = lib.dc_init_from_files(str(cell_path).encode(), str(table_path).encode(), ctypes.byref(self.h))
        if status != 0:
            buf = ctypes.create_string_buffer(1024)
            lib.dc_last_init_error(buf, len(buf))
            raise RuntimeError(f"init failed with status {status}: {buf.value.decode()}")

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.lib.dc_destroy(self.h)
        self.h = None


@pytest.fixture(params=CELL_FILES)
def cell_file(request) -> Path:
    return REPO / request.param
