#!/usr/bin/env bash
# Prints the median (ns) of every criterion benchmark measured so far, from
# target/criterion/<group>/<function>[/<input>]/new/estimates.json.
# Usage: cargo bench --bench sat --bench kinematics --bench exact_query && scripts/bench-medians.sh
set -euo pipefail
cd "$(dirname "$0")/.."
find target/criterion -path '*/new/estimates.json' | sort | while read -r f; do
  id=${f#target/criterion/}; id=${id%/new/estimates.json}
  median=$(tr -d '\n ' < "$f" | sed -E 's/.*"median":\{"confidence_interval":\{[^}]*\},"point_estimate":([0-9.eE+-]+).*/\1/')
  printf '%-60s %12.1f ns\n' "$id" "$median"
done
