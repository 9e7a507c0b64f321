/* Instructions of one call of each per-tick entry point, counted by callgrind
 * (tests/instruction_budgets.rs runs it under `valgrind --tool=callgrind --collect-atstart=no`):
 * every measured call is collected alone and dumped as a part named after its entry point.
 *
 * Cell T1 in exact mode with the default stopping model and speed limits. Robot A stands while
 * robot B comes toward it at 1.2 m/s along x, from apart until the first STOP: the proofs get
 * harder as the robots near each other (WARN, the limits' searches, the stop paths' pieces).
 * Each tick answers dc_query, then the protective query, without paths on even ticks and with
 * them on odd ones (A's path one point, B's its next 62 mm in 32 points). The first protective
 * tick after init, after the STOP and after dc_protective_reset are parts of their own.
 */
#include <stdio.h>
#include <string.h>
#include <valgrind/callgrind.h>

#include "delta_collide.h"

/* One call of `call`, its instructions dumped as the part `name`. */
#define MEASURED(name, call)                                                                       \
    do {                                                                                           \
        CALLGRIND_TOGGLE_COLLECT;                                                                  \
        call;                                                                                      \
        CALLGRIND_TOGGLE_COLLECT;                                                                  \
        CALLGRIND_DUMP_STATS_AT(name);                                                             \
    } while (0)

int main(void)
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
               t, (unsigned)verdict, 1e-3 * (double)ts.query.mean_ns, 1e-3 * (double)ts.query.largest_ns,
               1e-3 * (double)ts.protective.mean_ns, 1e-3 * (double)ts.protective.largest_ns);
    }
    dc_destroy(h);
    return 0;
}
