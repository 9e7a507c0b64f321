#!/usr/bin/env python3
"""How many cores a run kept busy, second by second, and where: reads `perf script` output of a
run recorded at a known sampling frequency and prints, per bucket of time, the cores used
(samples / (bucket x frequency)) and the two functions most sampled (the first of this crate
in each call chain, else the leaf).

Usage:
  perf record -F 49 -g -o run.data target/release/delta-collide build --cell T1 --k 64 \
      --variant shared-sub --output t.dct
  perf script -i run.data -F tid,time,ip,sym | scripts/cpu-timeline.py 49 [bucket seconds]
"""
import collections
import re
import sys


def samples(lines):
    """(time, call chain) of each sample: a header line `tid time:` then one frame per line."""
    current = None
    for line in lines:
        header = re.match(r"\s*\d+\s+([\d.]+):\s*$", line)
        if header:
            if current:
                yield current
            current = (float(header.group(1)), [])
        elif current and line.strip():
            frame = line.strip().split(None, 1)
            current[1].append(frame[-1])
    if current:
        yield current


def main():
    hz = float(sys.argv[1])
    width = float(sys.argv[2]) if len(sys.argv) > 2 else 1.0
    runs = list(samples(sys.stdin))
    if not runs:
        sys.exit("no samples")
    start = runs[0][0]
    buckets = collections.defaultdict(collections.Counter)
    counts = collections.Counter()
    for t, chain in runs:
        b = int((t - start) / width)
        ours = [f for f in chain if "delta_collide" in f and "call_once" not in f]
        buckets[b][(ours or chain or ["?"])[0][:70]] += 1
        counts[b] += 1
    for b in sorted(buckets):
        top = ", ".join(f"{n} {name}" for name, n in buckets[b].most_common(2))
        print(f"{b * width:7.0f} s  cores {counts[b] / (width * hz):4.2f}  {top}")


if __name__ == "__main__":
    main()
