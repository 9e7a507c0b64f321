"""How fast `check` and `clearance` run over 1,000,000 configurations from Python, beside
the same loop in Rust (python/examples/rust_loop.rs) and beside Coal called per
configuration from Python, all in one run on the same configurations.

    python python/bench/speed.py [--n 1000000] [--reps 5] [--coal-n 10000] [--cell T1]

Rust and Python repetitions alternate, so that both see the same load; the figures are
medians. Coal gets the robots' boxes precomputed (not timed) and is timed on `--coal-n`
configurations, scaled to `--n`; its answers are checked against `clearance` as it goes.
Prints the CPU, the load and a Markdown table of the medians and ratios.
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import delta_collide as dc

HERE = Path(__file__).resolve().parent
CRATE = HERE.parent


def configurations(cell: dc.Cell, n: int, seed: int) -> np.ndarray:
    """Drawn half uniform over a box around the workspace, half near the segment between the
    bases (colliding and nearly colliding); 95 % reachable ones kept, 5 % unreachable."""
    sys.path.insert(0, str(CRATE / "tests"))
    from conftest import random_tcps, toward_each_other

    rng = np.random.default_rng(seed)
    m = 4 * n
    t = np.concatenate([random_tcps(rng, m, 2), toward_each_other(cell, rng, m)])
    t = np.ascontiguousarray(t[rng.permutation(len(t))])
    # Mostly reachable, so that both loops do the whole work on most configurations.
    reach = dc.check(cell, t).reachable
    keep = np.concatenate([np.flatnonzero(reach)[: n - n // 20], np.flatnonzero(~reach)[: n // 20]])
    return np.ascontiguousarray(t[np.sort(keep)])


def cpu() -> str:
    info = Path("/proc/cpuinfo").read_text() if Path("/proc/cpuinfo").exists() else ""
    get = lambda key: next((l.split(":", 1)[1].strip() for l in info.splitlines() if l.startswith(key)), "?")
    return f"{get('model name')} (family {get('cpu family')}, model {get('model')}), {os.cpu_count()} cores"


def rust_loop() -> Path:
    subprocess.run(
        ["cargo", "build", "--release", "--quiet", "--example", "rust_loop"],
        cwd=CRATE,
        check=True,
        env={**os.environ, "CARGO_TARGET_DIR": str(CRATE / "target")},
    )
    return CRATE / "target" / "release" / "examples" / "rust_loop"


def timed(call) -> float:
    start = time.perf_counter()
    call()
    return time.perf_counter() - start


def coal_clearance(coal, centers, axes, half, i) -> float:
    """The cell's clearance of configuration i by Coal: every lower-link box pair."""
    req = coal.DistanceRequest()
    best = np.inf
    for a in range(3):
        for b in range(3):
            res = coal.DistanceResult()
            d = coal.distance(
                coal.Box(*(2 * half[i, 0, a])),
                coal.Transform3s(axes[i, 0, a], centers[i, 0, a]),
                coal.Box(*(2 * half[i, 1, b])),
                coal.Transform3s(axes[i, 1, b], centers[i, 1, b]),
                req,
                res,
            )
            best = min(best, d)
    return best


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=1_000_000)
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument("--coal-n", type=int, default=10_000)
    ap.add_argument("--cell", default="T1")
    args = ap.parse_args()
    cell = dc.Cell.reference(args.cell)
    tcps = configurations(cell, args.n, 1)
    binary = rust_loop()
    reach = dc.check(cell, tcps).reachable
    print(f"cell {cell.name}, {args.n} configurations ({reach.mean() * 100:.1f} % reachable), {args.reps} repetitions")
    print(f"CPU: {cpu()}; Python {platform.python_version()}, numpy {np.__version__}")
    print(f"load before: {os.getloadavg()}")

    out_check = dc.check(cell, tcps)
    out_clear = dc.clearance(cell, tcps)
    times = {k: [] for k in ("rust check", "rust clearance", "py check", "py clearance", "py check new", "py clearance new")}
    with tempfile.NamedTemporaryFile(suffix=".f64") as f:
        f.write(tcps.astype("<f8").tobytes())
        f.flush()
        for _ in range(args.reps):
            line = subprocess.run([str(binary), args.cell, f.name, "1"], capture_output=True, text=True, check=True)
            check_s, clear_s, collisions, total = line.stdout.split()
            times["rust check"].append(float(check_s))
            times["rust clearance"].append(float(clear_s))
            times["py check"].append(timed(lambda: dc.check(cell, tcps, out=out_check)))
            times["py clearance"].append(timed(lambda: dc.clearance(cell, tcps, out=out_clear)))
            times["py check new"].append(timed(lambda: dc.check(cell, tcps)))
            times["py clearance new"].append(timed(lambda: dc.clearance(cell, tcps)))
            # Both sides computed the same answers (the sums are of the same doubles in order).
            assert int(collisions) == int(out_check.collide.sum())
            assert float(total) == sum(out_clear[np.isfinite(out_clear)].tolist())

    import coal

    sub = np.flatnonzero(np.isfinite(out_clear))[: args.coal_n]
    b = dc.boxes(cell, np.ascontiguousarray(tcps[sub]))
    coal_reps = []
    for _ in range(3):
        start = time.perf_counter()
        for k in range(len(sub)):
            d = coal_clearance(coal, b.centers, b.axes, b.half, k)
            assert abs(d - out_clear[sub[k]]) < 1e-6, (k, d, out_clear[sub[k]])
        coal_reps.append((time.perf_counter() - start) * args.n / len(sub))
    print(f"load after: {os.getloadavg()}")

    times["coal clearance (scaled)"] = coal_reps
    med = {k: statistics.median(v) for k, v in times.items()}
    best = {k: min(v) for k, v in times.items()}
    print()
    print(f"| what, {args.n} configurations | median s | ns per configuration | fastest s |")
    print("|---|---:|---:|---:|")
    for k, v in med.items():
        print(f"| {k} | {v:.4f} | {v / args.n * 1e9:.1f} | {best[k]:.4f} |")
    print()
    print(f"check: Python (out=) / Rust = {med['py check'] / med['rust check']:.3f}")
    print(f"clearance: Python (out=) / Rust = {med['py clearance'] / med['rust clearance']:.3f}")
    print(f"check, new outputs: Python / Rust = {med['py check new'] / med['rust check']:.3f}")
    print(f"clearance, new outputs: Python / Rust = {med['py clearance new'] / med['rust clearance']:.3f}")
    print(f"Coal per configuration / Python clearance = {med['coal clearance (scaled)'] / med['py clearance']:.1f}")
    print(f"fastest: check {best['py check'] / best['rust check']:.3f}, "
          f"clearance {best['py clearance'] / best['rust clearance']:.3f}")
    print("all repetitions:", {k: [round(x, 4) for x in v] for k, v in times.items()})


if __name__ == "__main__":
    sys.exit(main())
