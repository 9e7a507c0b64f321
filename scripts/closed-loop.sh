#!/bin/sh
# The closed-loop benchmark on the reference cells and the cells of our own, every mode,
# with and without stop paths: the figures of docs/record/2026-12-02-closed-loop-benchmark.md.
# Usage: scripts/closed-loop.sh [RUNS] [TICKS] [SIMULATE FLAGS...]   (after `cargo build
# --release`), e.g. `scripts/closed-loop.sh 2 3000 --mode coordinate --right-of-way programmed`
set -e
runs=${1:-2}
ticks=${2:-3000}
if [ $# -ge 2 ]; then shift 2; else shift $#; fi
bin=${BIN:-target/release/delta-collide}
for cell in T1 T2 T3 cells/r60.toml cells/h80.toml cells/d380.toml cells/line4.toml cells/line8.toml; do
    for paths in --paths ""; do
        $bin simulate --cell "$cell" --runs "$runs" --ticks "$ticks" $paths "$@"
    done
done
