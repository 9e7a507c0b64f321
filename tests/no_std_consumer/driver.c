/*
 * driver.c: runs the no_std consumer (consumer.rs) on the host; see tests/portability.rs.
 * Usage: driver TABLE SEED N. Prints
 * `status free collision unreachable fallbacks hash query_allocs` and exits 0.
 */
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>

typedef struct Summary {
    uint32_t status, free, collision, unreachable, fallbacks;
    uint64_t hash;
    uint32_t query_allocs;
} Summary;

Summary dc_nostd_run(uint32_t table, uint64_t seed, uint32_t n);

int main(int argc, char **argv)
{
    Summary s;
    if (argc != 4) {
        fprintf(stderr, "usage: driver TABLE SEED N\n");
        return 2;
    }
    s = dc_nostd_run((uint32_t)strtoul(argv[1], NULL, 10), strtoull(argv[2], NULL, 10),
                     (uint32_t)strtoul(argv[3], NULL, 10));
    printf("%" PRIu32 " %" PRIu32 " %" PRIu32 " %" PRIu32 " %" PRIu32 " %" PRIu64 " %" PRIu32 "\n", s.status, s.free,
           s.collision, s.unreachable, s.fallbacks, s.hash, s.query_allocs);
    return 0;
}
