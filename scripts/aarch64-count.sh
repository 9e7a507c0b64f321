#!/usr/bin/env bash
# The worst-case calls of tests/data/worst_cases/ counted on a Cortex-A's instruction set:
# guest instructions of aarch64 code under qemu-aarch64 (TCG), beside the x86-64 instructions
# callgrind counts for the same calls on the host (docs/record/2026-12-02-worst-cases.md).
#
#   scripts/aarch64-count.sh [NAME...]     # names of tests/data/worst_cases/NAME.txt; default all
#
# It builds the controller's library for aarch64-unknown-linux-gnu (`--no-default-features
# --features std`, aarch64-linux-gnu-gcc as linker), the program tests/data/instruction_budgets.c
# with -DCOUNT_WITH_MARKS for aarch64 (each measured call between two calls of measured_mark())
# and for the host (callgrind's requests), and a small TCG plugin that adds each executed
# translation block's instruction count to a counter and prints the counter whenever the
# block at measured_mark's address runs. A call's count is the difference between its two
# marks less that of two marks with nothing between them (the marks' own instructions).
# The plugin is written here against QEMU's plugin API version 1 (QEMU 7.2; the Debian
# package ships qemu-aarch64 with plugin support but no plugins and no plugin header).
# Needs: cargo with the aarch64 target, aarch64-linux-gnu-gcc with its C library, qemu-user,
# gcc, valgrind. Prints one row per case: name, x86-64 count, aarch64 count, their ratio.
set -euo pipefail
cd "$(dirname "$0")/.."
out=target/aarch64-count
mkdir -p "$out"
names=("$@")
if [ ${#names[@]} -eq 0 ]; then
    names=(query_t1 query_line8 protective_t1 protective_t2 paths_t1 protective_line8)
fi
# Symbols bound at load (-z now): else the first call of a C library function inside a
# measured call counts the dynamic linker's lazy binding too.
libs=(-lgcc_s -lutil -lrt -lpthread -lm -ldl -lc -Wl,-z,now)
cflags=(-std=c99 -Wall -Wextra -Werror -pedantic -O2 -I include)

CARGO_TARGET_AARCH64_UNKNOWN_LINUX_GNU_LINKER=aarch64-linux-gnu-gcc \
    cargo build --release --lib --no-default-features --features std \
    --target aarch64-unknown-linux-gnu --target-dir "$out" 2>&1 | tail -1
cargo build --release --lib 2>&1 | tail -1
# Not position-independent: measured_mark's address in the file is the one it runs at.
aarch64-linux-gnu-gcc "${cflags[@]}" -no-pie -DCOUNT_WITH_MARKS \
    tests/data/instruction_budgets.c "$out/aarch64-unknown-linux-gnu/release/libdelta_collide.a" \
    "${libs[@]}" -o "$out/driver-aarch64"
cc "${cflags[@]}" tests/data/instruction_budgets.c target/release/libdelta_collide.a "${libs[@]}" \
    -o "$out/driver-x86_64"
mark=$(aarch64-linux-gnu-nm "$out/driver-aarch64" | awk '$3 == "measured_mark" { print "0x" $1 }')
[ -n "$mark" ] || { echo "measured_mark not found in $out/driver-aarch64" >&2; exit 1; }

cat > "$out/count_marks.c" <<'EOF'
/* A QEMU TCG plugin (API version 1): counts executed guest instructions, a translation
 * block's count added each time it runs, and prints "mark N" with the count so far each
 * time the block at address `mark=ADDR` (the plugin's argument) runs. */
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef uint64_t qemu_plugin_id_t;
typedef struct qemu_info_t qemu_info_t;
struct qemu_plugin_tb;
enum qemu_plugin_cb_flags { QEMU_PLUGIN_CB_NO_REGS };
enum qemu_plugin_op { QEMU_PLUGIN_INLINE_ADD_U64 };
typedef void (*qemu_plugin_vcpu_tb_trans_cb_t)(qemu_plugin_id_t id, struct qemu_plugin_tb *tb);
typedef void (*qemu_plugin_vcpu_udata_cb_t)(unsigned int vcpu_index, void *userdata);
void qemu_plugin_register_vcpu_tb_trans_cb(qemu_plugin_id_t id, qemu_plugin_vcpu_tb_trans_cb_t cb);
void qemu_plugin_register_vcpu_tb_exec_cb(struct qemu_plugin_tb *tb, qemu_plugin_vcpu_udata_cb_t cb,
                                          enum qemu_plugin_cb_flags flags, void *userdata);
void qemu_plugin_register_vcpu_tb_exec_inline(struct qemu_plugin_tb *tb, enum qemu_plugin_op op,
                                              void *ptr, uint64_t imm);
size_t qemu_plugin_tb_n_insns(const struct qemu_plugin_tb *tb);
uint64_t qemu_plugin_tb_vaddr(const struct qemu_plugin_tb *tb);

__attribute__((visibility("default"))) int qemu_plugin_version = 1;

static uint64_t executed;
static uint64_t mark_addr;

static void at_mark(unsigned int vcpu_index, void *userdata)
{
    (void)vcpu_index, (void)userdata;
    fprintf(stderr, "mark %" PRIu64 "\n", executed);
}

static void translated(qemu_plugin_id_t id, struct qemu_plugin_tb *tb)
{
    (void)id;
    if (qemu_plugin_tb_vaddr(tb) == mark_addr)
        qemu_plugin_register_vcpu_tb_exec_cb(tb, at_mark, QEMU_PLUGIN_CB_NO_REGS, NULL);
    qemu_plugin_register_vcpu_tb_exec_inline(tb, QEMU_PLUGIN_INLINE_ADD_U64, &executed,
                                             qemu_plugin_tb_n_insns(tb));
}

__attribute__((visibility("default"))) int qemu_plugin_install(qemu_plugin_id_t id,
                                                               const qemu_info_t *info,
                                                               int argc, char **argv)
{
    int i;
    (void)info;
    for (i = 0; i < argc; ++i)
        if (strncmp(argv[i], "mark=", 5) == 0) mark_addr = strtoull(argv[i] + 5, NULL, 0);
    if (!mark_addr) return 1;
    qemu_plugin_register_vcpu_tb_trans_cb(id, translated);
    return 0;
}
EOF
cc -std=c99 -Wall -Wextra -Werror -O2 -shared -fPIC "$out/count_marks.c" -o "$out/count_marks.so"

args=(--root .)
for name in "${names[@]}"; do
    args+=(--replay "tests/data/worst_cases/$name.txt" "$name" default)
done
qemu-aarch64 -L /usr/aarch64-linux-gnu -plugin "$out/count_marks.so,mark=$mark" \
    "$out/driver-aarch64" "${args[@]}" > "$out/aarch64.stdout" 2> "$out/aarch64.marks"
rm -f "$out"/callgrind.out.*
valgrind --tool=callgrind --collect-atstart=no --dump-line=no \
    --callgrind-out-file="$out/callgrind.out.%p" "$out/driver-x86_64" "${args[@]}" \
    > "$out/x86_64.stdout" 2> "$out/x86_64.stderr"

# The aarch64 counts: the k-th "mark NAME" line of the program goes with the k-th pair of the
# plugin's marks; the first pair is the empty region.
grep '^mark ' "$out/aarch64.stdout" | cut -d' ' -f2 > "$out/aarch64.names"
grep '^mark ' "$out/aarch64.marks" | cut -d' ' -f2 | paste - - | awk '{ print $2 - $1 }' \
    > "$out/aarch64.deltas"
paste -d' ' "$out/aarch64.names" "$out/aarch64.deltas" > "$out/aarch64.counts"
for f in "$out"/callgrind.out.*.*; do
    part=$(sed -n 's/^desc: Trigger: Client Request: //p' "$f")
    echo "$part $(sed -n 's/^summary: //p' "$f")"
done > "$out/x86_64.counts"
empty=$(awk '$1 == "empty" { print $2 }' "$out/aarch64.counts")
echo "aarch64 marks with nothing between them: $empty instructions (subtracted)"
printf '%-22s %12s %12s %7s\n' case x86-64 aarch64 ratio
awk -v empty="$empty" '
    NR == FNR { x86[$1] = $2; next }
    $1 != "empty" && ($1 in x86) {
        a = $2 - empty
        printf "%-22s %12d %12d %7.3f\n", $1, x86[$1], a, a / x86[$1]
    }' "$out/x86_64.counts" "$out/aarch64.counts"
