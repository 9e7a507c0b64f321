"""Pictures with matplotlib (optional: ``pip install matplotlib``): the cell at one
configuration (``render``), a table's 2-D slices (``quilt``), a run's protective verdict or a
closed-loop run (``plot_run``). Each returns the matplotlib Figure and, given ``path``, saves
it (PNG by the suffix); the CLI's PNG pictures are drawn by its own binary (plotters), which
this package does not link."""

from __future__ import annotations

import numpy as np

# The 12 edges of a box as pairs of its 8 corners, corner c at signs ((c>>2)&1, (c>>1)&1, c&1).
_EDGES = [(a, b) for a in range(8) for b in range(8) if a < b and bin(a ^ b).count("1") == 1]


def _pyplot():
    try:
        import matplotlib

        matplotlib.use("Agg", force=False)
        import matplotlib.pyplot as plt
    except ImportError as e:  # pragma: no cover - depends on the environment
        raise ImportError("pictures need matplotlib: pip install matplotlib") from e
    return plt


def _finish(fig, path):
    if path is not None:
        fig.savefig(path, dpi=110)
    return fig


def box_corners(center: np.ndarray, axes: np.ndarray, half: np.ndarray) -> np.ndarray:
    """The 8 corners (8, 3) of the box at ``center`` with unit axes the columns of ``axes``."""
    signs = np.array([[(c >> 2) & 1, (c >> 1) & 1, c & 1] for c in range(8)], dtype=float) * 2 - 1
    return center + (signs * half) @ axes.T


def render(cell, tcps, path=None, title=None):
    """The cell's boxes at one configuration ``tcps`` (robots, 3), in the world frame, with the
    exact clearance in the title."""
    from . import boxes, clearance

    plt = _pyplot()
    tcps = np.ascontiguousarray(tcps, dtype=np.float64).reshape(1, cell.n_robots, 3)
    b = boxes(cell, tcps)
    c = clearance(cell, tcps)[0]
    fig = plt.figure(figsize=(7, 6))
    ax = fig.add_subplot(projection="3d")
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for j, n in enumerate(cell.box_counts):
        for k in range(n):
            centre = b.centers[0, j, k]
            if not np.all(np.isfinite(centre)):
                continue
            p = box_corners(centre, b.axes[0, j, k], b.half[0, j, k])
            for e0, e1 in _EDGES:
                ax.plot(*zip(p[e0], p[e1]), color=colours[j % len(colours)], lw=1)
        base = np.array(cell.robots[j]["placement"]["t"])
        ax.scatter(*base, color=colours[j % len(colours)], marker="^")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.set_zlabel("z (mm)")
    ax.set_title(title or f"{cell.name}: clearance {c:.3f} mm")
    return _finish(fig, path)


def quilt(table, tcp_b, zs=(-350.0, -450.0, -520.0), path=None, half_width=400.0, n=120):
    """A table's labels over 2-D slices: robot A's TCP over an x-y grid (its MCS) at each depth
    of ``zs``, robot B's TCP fixed at ``tcp_b`` (B's MCS). White free, black collision, light
    grey unreachable; the labels alone (no exact confirmation). Returns the figure; the images are
    ``fig.quilt_images`` (len(zs), n, n) of 0 free, 1 collision, 2 unreachable."""
    from . import query

    plt = _pyplot()
    xs = np.linspace(-half_width, half_width, n)
    images = np.empty((len(zs), n, n), dtype=np.uint8)
    for s, z in enumerate(zs):
        gx, gy = np.meshgrid(xs, xs)
        tcps = np.empty((n * n, 2, 3))
        tcps[:, 0, 0], tcps[:, 0, 1], tcps[:, 0, 2] = gx.ravel(), gy.ravel(), z
        tcps[:, 1] = tcp_b
        q = query(table, tcps, confirm="none")
        images[s] = np.where(~q.reachable, 2, q.collide.astype(np.uint8)).reshape(n, n)
    from matplotlib.colors import ListedColormap

    colours = ListedColormap(["white", "black", "lightgrey"])
    fig, axes = plt.subplots(1, len(zs), figsize=(4 * len(zs), 4), squeeze=False)
    for ax, z, img in zip(axes[0], zs, images):
        ax.imshow(img, origin="lower", extent=[-half_width, half_width] * 2, cmap=colours, vmin=0, vmax=2)
        ax.set_title(f"A at z = {z:g} mm")
        ax.set_xlabel("x (mm)")
        ax.set_ylabel("y (mm)")
    fig.suptitle(f"labels, B at {tuple(float(v) for v in tcp_b)}")
    fig.quilt_images = images
    return _finish(fig, path)


def plot_run(result, path=None, tick_ms=1.0):
    """A run's pictures: a :class:`~delta_collide.Protective` result (clearance, verdicts,
    protective distances per tick) or a :func:`~delta_collide.simulate` dict (each robot's
    progress through its programme per tick, the STOP events marked)."""
    plt = _pyplot()
    if isinstance(result, dict):
        fig, ax = plt.subplots(figsize=(9, 4))
        progress = result["progress"]
        for j in range(progress.shape[1]):
            ax.plot(progress[:, j], label=f"robot {j}")
        for s in result["stops"]:
            ax.axvline(np.argmax(progress[:, 0] >= s[0]) if len(progress) else 0, color="red", lw=0.5)
        ax.set_xlabel("tick")
        ax.set_ylabel("programme ticks done")
        ax.set_title(
            f"{result['mode']}: throughput {result['throughput']:.3f}, {result['stop_events']} STOP events"
        )
        ax.legend()
        return _finish(fig, path)
    t = np.arange(len(result.verdict)) * tick_ms
    fig, (a0, a1) = plt.subplots(2, 1, figsize=(9, 6), sharex=True)
    a0.plot(t, result.clearance, color="black", label="clearance")
    for j in range(result.protective_mm.shape[1]):
        a0.plot(t, result.protective_mm[:, j], lw=0.8, label=f"protective, robot {j}")
    a0.set_ylabel("mm")
    a0.legend()
    colour = {0: "red", 1: "green", 3: "orange"}
    a1.scatter(t, result.verdict, c=[colour.get(int(v), "grey") for v in result.verdict], s=4)
    a1.set_yticks([0, 1, 3], ["STOP", "FREE", "WARN"])
    a1.set_xlabel("ms")
    return _finish(fig, path)
