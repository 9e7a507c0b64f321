#!/bin/sh
# The closed-loop benchmark at several caps on the work along the stop paths (programmed
# order, 10 mm, stop paths on): throughput, STOP events, and the most units one protective
# call spent / the calls that ran out (column "work max/out"). The figures of
# docs/record/2026-12-02-work-budget.md.
# Usage: scripts/path-work-sweep.sh [RUNS] [TICKS] [SEED] [CAPS...]   (after `cargo build --release`)
set -e
runs=${1:-2}
ticks=${2:-1500}
seed=${3:-1}
if [ $# -ge 3 ]; then shift 3; else shift $#; fi
caps=${*:-"100 300 600 2000 4294967295"}
bin=${BIN:-target/release/delta-collide}
for cap in $caps; do
    for cell in T1 T2 T3 cells/h80.toml cells/r60.toml cells/d380.toml; do
        echo "== path work $cap, $cell"
        $bin simulate --cell "$cell" --runs "$runs" --seed "$seed" --ticks "$ticks" --paths -q \
            --mode coordinate --right-of-way programmed --clearance-mm 10 --path-work "$cap"
    done
done
