#!/usr/bin/env bash
# Counts the instructions of one table build by two binaries of delta-collide (cachegrind,
# one worker thread each; both run at once, which does not change a count), prints both counts
# and their ratio, and whether the two tables are the same bytes. Instruction counts are not
# time (they leave out latency, cache misses and mispredicted branches), but they do not drift
# with the host: on a shared VM, where the same binary built twice at once on two cores differed
# by up to 35 % in CPU time, they show a change to the builder and its size without noise.
#
# Usage: scripts/build-instructions.sh BASE_BIN NEW_BIN CELL K [VARIANT]
#   e.g. scripts/build-instructions.sh /tmp/base target/release/delta-collide cells/t1.toml 16
# Needs valgrind. Exit code 1 when the tables differ. T1 at k = 16 takes about a minute.
set -euo pipefail
[ $# -ge 4 ] || { sed -n "9,11p" "$0" >&2; exit 2; }
base=$1 new=$2 cell=$3 k=$4 variant=${5:-shared-sub}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
for side in base new; do
  bin=$base; [ "$side" = new ] && bin=$new
  RAYON_NUM_THREADS=1 valgrind --tool=cachegrind --cache-sim=no --cachegrind-out-file="$dir/$side.cg" \
    "$bin" -q build --cell "$cell" --k "$k" --variant "$variant" --output "$dir/$side.dct" >/dev/null 2>&1 &
done
wait
count() { awk '/^summary:/ { print $2 }' "$dir/$1.cg"; }
b=$(count base) n=$(count new)
awk -v b="$b" -v n="$n" 'BEGIN { printf "instructions: base %.0f, new %.0f, new / base %.4f\n", b, n, n / b }'
if cmp -s "$dir/base.dct" "$dir/new.dct"; then echo "tables: same bytes"; else echo "tables: DIFFER"; exit 1; fi
