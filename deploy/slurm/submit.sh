#!/bin/bash
# Submits a delta-collide table build to Slurm: a job array of N shards
# (build-table.sbatch) and a merge job that starts when every shard has succeeded
# (merge-table.sbatch, --dependency=afterok). Prints the two job ids. docs/CLUSTER.md.
#
#   deploy/slurm/submit.sh --cell T1 --k 128 --variant shared-sub --shards 512 \
#       --dir /shared/dc-t1 --output /shared/t1.dct [--bin PATH] [--cpus-per-task C] \
#       [--mem-per-shard 6G] [--mem-merge 200G] [--build-args "..."] [-- SBATCH OPTIONS...]
#
# --dir must be on a file system every node sees; the shard files, the logs and (unless
# --output says otherwise) the table go there. Options after -- go to both sbatch calls
# (--partition, --account, --time, ...).
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
usage() { sed -n '2,13p' "$0" >&2; exit 2; }
cell="" k="" variant="6d" shards="" dir="" output="" bin="" cpus=2 mem_shard="" mem_merge="" build_args=""
while (($#)); do
    case "$1" in
        --cell) cell="$2"; shift 2 ;;
        --k) k="$2"; shift 2 ;;
        --variant) variant="$2"; shift 2 ;;
        --shards) shards="$2"; shift 2 ;;
        --dir) dir="$2"; shift 2 ;;
        --output) output="$2"; shift 2 ;;
        --bin) bin="$2"; shift 2 ;;
        --cpus-per-task) cpus="$2"; shift 2 ;;
        --mem-per-shard) mem_shard="$2"; shift 2 ;;
        --mem-merge) mem_merge="$2"; shift 2 ;;
        --build-args) build_args="$2"; shift 2 ;;
        --) shift; break ;;
        *) echo "submit.sh: unknown option $1" >&2; usage ;;
    esac
done
[[ -n "$cell" && -n "$k" && -n "$shards" && -n "$dir" ]] || usage
[[ "$shards" =~ ^[1-9][0-9]*$ ]] || { echo "submit.sh: --shards $shards is not a count from 1" >&2; exit 2; }
bin="${bin:-$(command -v delta-collide || true)}"
[[ -x "$bin" ]] || { echo "submit.sh: no delta-collide binary (give --bin PATH)" >&2; exit 2; }
bin="$(cd "$(dirname "$bin")" && pwd)/$(basename "$bin")"
# A cell file is read by every task: give it as an absolute path.
if [[ "$cell" == *.toml ]]; then cell="$(cd "$(dirname "$cell")" && pwd)/$(basename "$cell")"; fi
mkdir -p "$dir/logs"
dir="$(cd "$dir" && pwd)"
output="${output:-$dir/table.dct}"
[[ "$output" == /* ]] || output="$PWD/$output"
common=(--parsable --chdir="$dir" "$@")
array=$(sbatch "${common[@]}" --array="0-$((shards - 1))" --cpus-per-task="$cpus" \
    ${mem_shard:+--mem="$mem_shard"} --output="$dir/logs/shard-%A_%a.out" \
    --export="ALL,DC_BIN=$bin,DC_CELL=$cell,DC_K=$k,DC_VARIANT=$variant,DC_DIR=$dir,DC_BUILD_ARGS=$build_args" \
    "$here/build-table.sbatch")
array_id="${array%%;*}"
merge=$(sbatch "${common[@]}" --dependency="afterok:$array_id" ${mem_merge:+--mem="$mem_merge"} \
    --output="$dir/logs/merge-%j.out" \
    --export="ALL,DC_BIN=$bin,DC_DIR=$dir,DC_SHARDS=$shards,DC_OUTPUT=$output" \
    "$here/merge-table.sbatch")
merge_id="${merge%%;*}"
echo "array $array_id"
echo "merge $merge_id"
