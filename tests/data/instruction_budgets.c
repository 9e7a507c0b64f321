/* Instructions of one call of each per-tick entry point, counted by callgrind
 * (tests/instruction_budgets.rs runs it under `valgrind --tool=callgrind --collect-atstart=no`):
 * every measured call is collected alone and dumped as a part named after its entry point.
 *
 *   instruction_budgets [--approach] [--repeat R] [--replay FILE NAME WORK --root DIR]...
 *
 * --approach: cell T1 in exact mode with the default stopping model and speed limits. Robot A
 * stands while robot B comes toward it at 1.2 m/s along x, from apart until the first STOP:
 * the proofs get harder as the robots near each other (WARN, the limits' searches, the stop
 * paths' pieces). Each tick answers dc_query, then the protective query, without paths on even
 * ticks and with them on odd ones (A's path one point, B's its next 62 mm in 32 points). The
 * first protective tick after init, after the STOP and after dc_protective_reset are parts of
 * their own.
 *
 * --replay FILE NAME WORK: the cases of FILE (tests/data/worst_cases/: a cell, a call, then
 * per case its ticks), each from a fresh state: a new handle for dc_query (its witness caches
 * empty), dc_protective_reset for the protective calls (a reset checker answers as a new one).
 * Every tick but the last is history, run and not collected; the last is the part
 * "NAME#i" (i: the case's number in the file). WORK is the dc_set_path_work cap, or
 * "default". After each part a line "part NAME#i verdict V work W spent S clearance C"
 * (dc_tick_stats's last_work, whether the call used a whole work cap) is printed; with
 * --repeat R each case runs R times more, natively timed from dc_tick_stats, and the line
 * adds the smallest, median and largest time of the measured call (ns).
 *
 * Compiled with -DCOUNT_WITH_MARKS (scripts/aarch64-count.sh, for qemu-aarch64 and its
 * counting plugin) a measured call is bracketed by calls of measured_mark() instead, and
 * "mark NAME" is printed after it: the plugin counts the guest instructions between marks.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "delta_collide.h"

#ifdef COUNT_WITH_MARKS
/* The plugin watches this function's address (nm): not inlined, not merged with another. */
__attribute__((noinline)) void measured_mark(void);
__attribute__((noinline)) void measured_mark(void) { __asm__ volatile("" ::: "memory"); }
#define MEASURED(name, call)                                                                       \
    do {                                                                                           \
        measured_mark();                                                                           \
        call;                                                                                      \
        measured_mark();                                                                           \
        printf("mark %s\n", name);                                                                 \
    } while (0)
#else
#include <valgrind/callgrind.h>
/* One call of `call`, its instructions dumped as the part `name`. */
#define MEASURED(name, call)                                                                       \
    do {                                                                                           \
        CALLGRIND_TOGGLE_COLLECT;                                                                  \
        call;                                                                                      \
        CALLGRIND_TOGGLE_COLLECT;                                                                  \
        CALLGRIND_DUMP_STATS_AT(name);                                                             \
    } while (0)
#endif

#define MAX_TICKS 8
#define MAX_REPEAT 1000

static int approach(void)
{
    DcRobotConfig robots[2];
    DcCellConfig config;
    DcStopConfig stops[2];
    DcCollider *h = NULL;
    DcVerdict verdict = DC_VERDICT_STOP;
    DcQueryReport qr;
    DcProtectiveReport pr;
    DcVec3 tcps[2], path[2][32];
    DcStopPath paths[2];
    DcStatus s = DC_STATUS_OK;
    int t, k;

    robots[0] = robots[1] = dc_robot_config_thesis();
    robots[1].translation.x = 450.0;
    config.robots = robots;
    config.n_robots = 2;
    config.method = DC_METHOD_SAT_CACHE;
    if (dc_init(&config, &h) != DC_STATUS_OK) return 2;
    stops[0] = stops[1] = dc_stop_config_default();
    if (dc_set_stop_model(h, 1.0, 10.0, stops, 2) != DC_STATUS_OK) return 3;
    for (t = 0; t < 400; ++t) {
        tcps[0].x = -150.0, tcps[0].y = 0.0, tcps[0].z = -450.0;
        tcps[1].x = 150.0 - 1.2 * t, tcps[1].y = 0.0, tcps[1].z = -450.0;
        for (k = 0; k < 32; ++k) {
            path[0][k] = tcps[0];
            path[1][k] = tcps[1];
            path[1][k].x -= 2.0 * k;
        }
        paths[0].points = path[0], paths[0].n_points = 1, paths[0].tolerance_mm = 0.5;
        paths[1].points = path[1], paths[1].n_points = 32, paths[1].tolerance_mm = 0.5;
        MEASURED("dc_query", s |= dc_query(h, tcps, 2, &verdict, &qr));
        if (t == 0) {
            /* The first tick after init: no previous TCP, full speed assumed. */
            MEASURED("first_after_init", s |= dc_protective_query(h, tcps, 2, &verdict, &pr));
        } else if (t % 2 == 0) {
            MEASURED("dc_protective_query", s |= dc_protective_query(h, tcps, 2, &verdict, &pr));
        } else {
            MEASURED("dc_protective_query_with_paths",
                     s |= dc_protective_query_with_paths(h, tcps, 2, paths, 2, &verdict, &pr));
        }
        if (s != DC_STATUS_OK) {
            printf("status %u at tick %d\n", (unsigned)s, t);
            return 4;
        }
        if (verdict == DC_VERDICT_STOP && t > 10) break;
    }
    /* The tick after the STOP (robot B still moving while it reacts) and the first after a
     * reset. */
    tcps[1].x -= 1.2;
    MEASURED("first_after_stop", s |= dc_protective_query(h, tcps, 2, &verdict, &pr));
    dc_protective_reset(h);
    MEASURED("first_after_reset", s |= dc_protective_query(h, tcps, 2, &verdict, &pr));
    if (s != DC_STATUS_OK) {
        printf("status %u after the STOP\n", (unsigned)s);
        return 6;
    }
    {
        /* The time of the same calls (meaningful when run natively, not under valgrind). */
        DcTickStats ts;
        memset(&ts, 0, sizeof ts);
        ts.struct_size = (uint32_t)sizeof ts;
        if (dc_tick_stats(h, &ts) != DC_STATUS_OK) return 5;
        printf("ticks %d, last verdict %u; dc_query mean %.2f us, largest %.2f us; protective "
               "(both) mean %.1f us, largest %.1f us\n",
               t, (unsigned)verdict, 1e-3 * (double)ts.query.mean_ns,
               1e-3 * (double)ts.query.largest_ns,
               1e-3 * (double)ts.protective.mean_ns, 1e-3 * (double)ts.protective.largest_ns);
    }
    dc_destroy(h);
    return 0;
}

/* What a case file's "call" line names. */
enum Call { CALL_QUERY, CALL_PROTECTIVE, CALL_PATHS };

/* One case: its ticks, each with every robot's TCP and, for CALL_PATHS, its stop path. */
typedef struct Case {
    int n_ticks;
    DcVec3 tcps[MAX_TICKS][DC_MAX_ROBOTS];
    DcVec3 points[MAX_TICKS][DC_MAX_ROBOTS][DC_MAX_PATH_POINTS];
    DcStopPath paths[MAX_TICKS][DC_MAX_ROBOTS];
} Case;

/* Reads the next token of `f` into `buf`, skipping comments ('#' to the end of the line);
 * 0 at the end of the file. */
static int token(FILE *f, char *buf)
{
    for (;;) {
        if (fscanf(f, "%63s", buf) != 1) return 0;
        if (buf[0] != '#') return 1;
        if (fscanf(f, "%*[^\n]") < 0) return 0;
    }
}

static int read_vec(FILE *f, DcVec3 *v)
{
    return fscanf(f, "%lf %lf %lf", &v->x, &v->y, &v->z) == 3;
}

/* Reads one case's ticks (after its "case I ticks N" line) for `n` robots; 0 when malformed. */
static int read_case(FILE *f, enum Call call, size_t n, Case *c)
{
    char tok[64];
    int t;
    size_t j, k;
    for (t = 0; t < c->n_ticks; ++t) {
        if (!token(f, tok) || strcmp(tok, "t") != 0) return 0;
        for (j = 0; j < n; ++j)
            if (!read_vec(f, &c->tcps[t][j])) return 0;
        for (j = 0; call == CALL_PATHS && j < n; ++j) {
            DcStopPath *p = &c->paths[t][j];
            if (!token(f, tok) || strcmp(tok, "p") != 0) return 0;
            if (fscanf(f, "%zu %lf", &p->n_points, &p->tolerance_mm) != 2) return 0;
            if (p->n_points > DC_MAX_PATH_POINTS) return 0;
            for (k = 0; k < p->n_points; ++k)
                if (!read_vec(f, &c->points[t][j][k])) return 0;
            p->points = c->points[t][j];
        }
    }
    return 1;
}

/* A handle for `cell`; with `stop_model`, the default stopping model of every robot set, as a
 * controller sets its own (which builds the motor-angle tables the protective calls use). */
static DcCollider *open_cell(const char *cell, int stop_model)
{
    DcCollider *h = NULL;
    DcStopConfig stops[DC_MAX_ROBOTS];
    size_t j;
    if (dc_init_from_cell_file(cell, &h) != DC_STATUS_OK) return NULL;
    if (!stop_model) return h;
    for (j = 0; j < dc_robot_count(h); ++j) stops[j] = dc_stop_config_default();
    if (dc_set_stop_model(h, 1.0, 10.0, stops, dc_robot_count(h)) != DC_STATUS_OK) {
        dc_destroy(h);
        return NULL;
    }
    return h;
}

/* Runs tick `t` of `c` on `h`; the measured one as part `name` when `name` is not NULL. */
static DcStatus run_tick(DcCollider *h, enum Call call, const Case *c, int t, const char *name,
                         DcVerdict *verdict, double *clearance)
{
    DcStatus s = DC_STATUS_OK;
    DcQueryReport qr;
    DcProtectiveReport pr;
    size_t n = dc_robot_count(h);
    const DcVec3 *tcps = c->tcps[t];
    const DcStopPath *paths = c->paths[t];
    *clearance = NAN;
    if (call == CALL_QUERY) {
        if (name) MEASURED(name, s = dc_query(h, tcps, n, verdict, &qr));
        else s = dc_query(h, tcps, n, verdict, &qr);
    } else if (call == CALL_PROTECTIVE) {
        if (name) MEASURED(name, s = dc_protective_query(h, tcps, n, verdict, &pr));
        else s = dc_protective_query(h, tcps, n, verdict, &pr);
        *clearance = pr.clearance_mm;
    } else {
        if (name)
            MEASURED(name, s = dc_protective_query_with_paths(h, tcps, n, paths, n, verdict, &pr));
        else
            s = dc_protective_query_with_paths(h, tcps, n, paths, n, verdict, &pr);
        *clearance = pr.clearance_mm;
    }
    return s;
}

static int compare_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

/* Replays every case of `file` (module comment); `work` < 0: the default path work. */
static int replay(const char *root, const char *file, const char *name, long work, int repeat)
{
    static Case c;
    static uint64_t ns[MAX_REPEAT];
    char tok[64], cell[1024], part[256];
    enum Call call = CALL_QUERY;
    DcCollider *h = NULL;
    FILE *f = fopen(file, "r");
    int index, r, t, cases = 0;
    if (!f) {
        printf("cannot open %s\n", file);
        return 10;
    }
    if (!token(f, tok) || strcmp(tok, "cell") != 0 || !token(f, tok)) return 11;
    snprintf(cell, sizeof cell, "%s/%s", root, tok);
    if (!token(f, tok) || strcmp(tok, "call") != 0 || !token(f, tok)) return 11;
    if (strcmp(tok, "query") == 0) call = CALL_QUERY;
    else if (strcmp(tok, "protective") == 0) call = CALL_PROTECTIVE;
    else if (strcmp(tok, "paths") == 0) call = CALL_PATHS;
    else return 11;
    if (call != CALL_QUERY) {
        h = open_cell(cell, 1);
        if (!h) {
            printf("cannot open cell %s\n", cell);
            return 12;
        }
        if (work >= 0 && dc_set_path_work(h, (uint32_t)work) != DC_STATUS_OK) return 12;
    }
    while (token(f, tok)) {
        DcTickStats ts;
        DcVerdict verdict = DC_VERDICT_STOP;
        double clearance;
        if (strcmp(tok, "case") != 0 || fscanf(f, "%d", &index) != 1 || !token(f, tok) ||
            strcmp(tok, "ticks") != 0 || fscanf(f, "%d", &c.n_ticks) != 1 || c.n_ticks < 1 ||
            c.n_ticks > MAX_TICKS)
            return 13;
        if (call == CALL_QUERY) {
            h = open_cell(cell, 0);
            if (!h) return 12;
        }
        if (!read_case(f, call, dc_robot_count(h), &c)) {
            printf("%s: case %d is malformed\n", file, index);
            return 13;
        }
        snprintf(part, sizeof part, "%s#%d", name, index);
        for (r = 0; r <= repeat; ++r) {
            if (call == CALL_QUERY && r > 0) {
                dc_destroy(h);
                h = open_cell(cell, 0);
                if (!h) return 12;
            }
            dc_protective_reset(h);
            for (t = 0; t + 1 < c.n_ticks; ++t)
                if (run_tick(h, call, &c, t, NULL, &verdict, &clearance) != DC_STATUS_OK) {
                    printf("%s: case %d: history tick %d failed\n", file, index, t);
                    return 14;
                }
            /* The first run is the measured part; the repetitions only time it. The statistics
             * start again so that they hold the measured call alone. */
            dc_tick_stats_reset(h);
            if (run_tick(h, call, &c, t, r == 0 ? part : NULL, &verdict, &clearance) !=
                DC_STATUS_OK) {
                printf("%s: case %d: the measured tick failed\n", file, index);
                return 14;
            }
            memset(&ts, 0, sizeof ts);
            ts.struct_size = (uint32_t)sizeof ts;
            if (dc_tick_stats(h, &ts) != DC_STATUS_OK) return 15;
            ns[r] = call == CALL_QUERY ? ts.query.last_ns : ts.protective.last_ns;
            if (r == 0) {
                printf("part %s verdict %u work %llu spent %llu clearance %.3f", part,
                       (unsigned)verdict, (unsigned long long)ts.protective.last_work,
                       (unsigned long long)ts.protective.budget_spent, clearance);
            }
        }
        if (repeat > 0) {
            qsort(ns + 1, (size_t)repeat, sizeof ns[0], compare_u64);
            printf(" ns %llu %llu %llu", (unsigned long long)ns[1],
                   (unsigned long long)ns[1 + repeat / 2], (unsigned long long)ns[repeat]);
        }
        printf("\n");
        if (call == CALL_QUERY) {
            dc_destroy(h);
            h = NULL;
        }
        ++cases;
    }
    fclose(f);
    dc_destroy(h);
    printf("replayed %d cases of %s as %s\n", cases, file, name);
    return cases > 0 ? 0 : 16;
}

int main(int argc, char **argv)
{
    const char *root = ".";
    int i, rc = 0, repeat = 0, ran = 0;
#ifdef COUNT_WITH_MARKS
    /* Two marks with nothing between them: what the marks themselves count. */
    MEASURED("empty", (void)0);
#endif
    for (i = 1; i < argc && rc == 0; ++i) {
        if (strcmp(argv[i], "--approach") == 0) {
            rc = approach();
            ran = 1;
        } else if (strcmp(argv[i], "--root") == 0 && i + 1 < argc) {
            root = argv[++i];
        } else if (strcmp(argv[i], "--repeat") == 0 && i + 1 < argc) {
            repeat = atoi(argv[++i]);
            if (repeat < 0 || repeat >= MAX_REPEAT) return 1;
        } else if (strcmp(argv[i], "--replay") == 0 && i + 3 < argc) {
            long work = strcmp(argv[i + 3], "default") == 0 ? -1 : atol(argv[i + 3]);
            rc = replay(root, argv[i + 1], argv[i + 2], work, repeat);
            i += 3;
            ran = 1;
        } else {
            printf("unknown argument %s\n", argv[i]);
            return 1;
        }
    }
    /* Without arguments: the approach alone. */
    if (!ran) rc = approach();
    return rc;
}
