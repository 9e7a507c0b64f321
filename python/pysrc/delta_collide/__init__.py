"""delta-collide from Python: exact checks, clearance, protective verdicts, tables and the
closed-loop benchmark of Delta packaging robots, vectorised over numpy arrays.

Units are millimetres and radians; each robot's TCP is given in its own machine coordinate
system (MCS), as the C ABI takes it. Arrays of configurations have shape ``(N, robots, 3)``,
float64, C-contiguous; anything else raises ``ValueError`` naming the argument. Every call
releases the GIL while it works. With ``out=`` a call writes into arrays the caller made and
allocates nothing (neither numpy nor the library).

>>> import numpy as np, delta_collide as dc
>>> cell = dc.Cell.reference("T1")
>>> tcps = np.array([[[0.0, 0.0, -900.0], [0.0, 0.0, -900.0]]])
>>> dc.clearance(cell, tcps).shape
(1,)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import _native
from ._native import (
    MAX_BOXES,
    MAX_PATH_POINTS,
    BuildError,
    Cell,
    CellError,
    Table,
    TableError,
    simulate,
)

__all__ = [
    "Cell",
    "Table",
    "CellError",
    "TableError",
    "BuildError",
    "Check",
    "Protective",
    "Boxes",
    "check",
    "clearance",
    "boxes",
    "protective",
    "simulate",
    "query",
    "clearance_bound",
    "MAX_BOXES",
    "MAX_PATH_POINTS",
    "VERDICT_STOP",
    "VERDICT_FREE",
    "VERDICT_WARN",
]

#: Verdict numbers of :func:`protective`, those of the C ABI (``DC_VERDICT_*``).
VERDICT_STOP, VERDICT_FREE, VERDICT_WARN = 0, 1, 3


def _rows(tcps, arg: str = "tcps", rows: str = "N") -> int:
    shape = getattr(tcps, "shape", None)
    if not isinstance(tcps, np.ndarray) or len(shape) == 0:
        raise ValueError(f"{arg} must be a numpy array of shape ({rows}, robots, 3), not {type(tcps).__name__}")
    return shape[0]


@dataclass
class Check:
    """The exact check of N configurations: ``reachable`` (N,) bool, ``collide`` (N,) bool
    (False where unreachable) and ``pairs`` (N, pairs) bool, one column per pair of
    ``cell.pairs``."""

    reachable: np.ndarray
    collide: np.ndarray
    pairs: np.ndarray


def check(cell: Cell, tcps: np.ndarray, out: Check | None = None) -> Check:
    """The exact check (every box pair, separating axis test) of each configuration."""
    if out is None:
        n = _rows(tcps)
        out = Check(
            np.empty(n, dtype=bool), np.empty(n, dtype=bool), np.empty((n, len(cell.pairs)), dtype=bool)
        )
    _native.check_into(cell, tcps, out.reachable, out.collide, out.pairs)
    return out


def clearance(cell: Cell, tcps: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
    """The exact signed clearance (mm) of each configuration, (N,) float64: the gap between
    the closest boxes of robots that can meet, minus the penetration depth when boxes
    intersect; NaN where a TCP is unreachable, inf when no pair can meet."""
    if out is None:
        out = np.empty(_rows(tcps), dtype=np.float64)
    _native.clearance_into(cell, tcps, out)
    return out


@dataclass
class Boxes:
    """The boxes of N configurations in the world frame: ``centers`` (N, robots, MAX_BOXES,
    3), ``axes`` (N, robots, MAX_BOXES, 3, 3; a box's axes are the columns), ``half`` (N,
    robots, MAX_BOXES, 3); NaN past a robot's ``cell.box_counts`` and where unreachable."""

    centers: np.ndarray
    axes: np.ndarray
    half: np.ndarray


def boxes(cell: Cell, tcps: np.ndarray, out: Boxes | None = None) -> Boxes:
    """Every robot's boxes (lower links, then upper links, platform, tool) per configuration."""
    if out is None:
        n, r = _rows(tcps), cell.n_robots
        out = Boxes(
            np.empty((n, r, MAX_BOXES, 3)), np.empty((n, r, MAX_BOXES, 3, 3)), np.empty((n, r, MAX_BOXES, 3))
        )
    _native.boxes_into(cell, tcps, out.centers, out.axes, out.half)
    return out


@dataclass
class Protective:
    """The protective verdict of each tick of a run of T ticks: ``verdict`` (T,) uint32
    (VERDICT_STOP 0, VERDICT_FREE 1, VERDICT_WARN 3), ``status`` (T,) uint32 (the C ABI's
    ``DC_STATUS_*``: 0 OK, 3 unreachable, 17 implausible motion), ``clearance`` (T,) mm,
    ``protective_mm`` (T, robots): how far each TCP may travel until it stands after a stop
    now, ``speed_limit`` (T, robots) mm/s: the largest speed at which FREE still holds (NaN
    with ``speed_limits=False``)."""

    verdict: np.ndarray
    status: np.ndarray
    clearance: np.ndarray
    protective_mm: np.ndarray
    speed_limit: np.ndarray


def protective(
    cell: Cell,
    run: np.ndarray,
    paths: np.ndarray | None = None,
    *,
    path_tolerance_mm: float = 0.0,
    warn_mm: float = 10.0,
    speed_limits: bool = True,
    table: Table | None = None,
    out: Protective | None = None,
) -> Protective:
    """The protective verdict (SPEC section 8) tick after tick over ``run`` (T, robots, 3),
    one controller tick (``cell.tick_ms``) apart, from a checker that knows no earlier TCP;
    ``paths`` (T, robots, P, 3), P <= 32: each robot's stop path at each tick, which its TCP
    never leaves by more than ``path_tolerance_mm``. The first call on a cell (or with another
    ``warn_mm``) builds its motor-angle tables. With a clearance ``table`` of the cell, as
    table mode: a tick whose stop balls the table's bound proves apart is FREE without the
    swept-box proof (``delta-collide replay --table``)."""
    if out is None:
        t, r = _rows(run, "run", "T"), cell.n_robots
        out = Protective(
            np.empty(t, dtype=np.uint32),
            np.empty(t, dtype=np.uint32),
            np.empty(t),
            np.empty((t, r)),
            np.empty((t, r)),
        )
    _native.protective_into(
        cell,
        run,
        paths,
        path_tolerance_mm,
        warn_mm,
        speed_limits,
        out.verdict,
        out.status,
        out.clearance,
        out.protective_mm,
        out.speed_limit,
        table,
    )
    return out


def query(table: Table, tcps: np.ndarray, out: Check | None = None, confirm: str | None = None) -> Check:
    """Table mode over (N, robots, 3) configurations, as ``dc_query`` and
    ``dc_pair_results`` answer each tick: ``reachable``, ``collide``, ``pairs`` (one column
    per pair of ``table.cell.pairs``). ``confirm`` "none" answers the table's labels alone,
    "exact" confirms a COLLISION lookup with the exact check (default: the table's)."""
    if out is None:
        n = _rows(tcps)
        pairs = len(table.cell.pairs)
        out = Check(np.empty(n, dtype=bool), np.empty(n, dtype=bool), np.empty((n, pairs), dtype=bool))
    table.query_into(tcps, out.reachable, out.collide, out.pairs, confirm)
    return out


def clearance_bound(table: Table, tcps: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
    """A clearance table's certified lower bound on the clearance (mm) per configuration:
    -inf where nothing is proved, NaN where a TCP is unreachable; for a bundle the least of
    its pairs' bounds."""
    if out is None:
        out = np.empty(_rows(tcps), dtype=np.float64)
    table.clearance_bound_into(tcps, out)
    return out


# Methods of the table, as the issue writes them: table.query(tcps), table.clearance_bound(tcps).
def _table_query(self, tcps, out=None, confirm=None):
    return query(self, tcps, out=out, confirm=confirm)


def _table_clearance_bound(self, tcps, out=None):
    return clearance_bound(self, tcps, out=out)


Table.query = _table_query
Table.clearance_bound = _table_clearance_bound

from .pictures import plot_run, quilt, render  # noqa: E402  (needs the names above)

__all__ += ["render", "quilt", "plot_run"]
