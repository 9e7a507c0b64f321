/*
 * protective.c: the protective verdict end to end (SPEC section 8). Each trajectory scenario
 * runs with dc_protective_query once per tick (with the stiff model also through
 * dc_protective_query_with_paths, each robot's programmed path ahead as its stop path, which
 * the simulated stop follows); at the first STOP every simulated robot keeps
 * its commanded motion for its reaction time, then brakes along its own path at its
 * configured deceleration until still (a path-maintaining stop that ends at the path's next
 * waypoint at the latest). Every 0.1 ms of that stop the exact model (dc_query on a second
 * handle) must find no contact. Prints per scenario the first WARN and STOP ticks, the STOP
 * and WARN counts, the smallest clearance and the stop's length. --quick (valgrind) runs the
 * first 200 ticks of T1 collision with the default model, which hold its whole stop, with and
 * without paths. With a clearance table for a cell (--clearance-table), its scenarios run
 * once more with the protective handle in table mode, where a tick the table's certified
 * bound proves FREE is answered by one lookup: the same simulated stops must not touch, and
 * the share of ticks answered by the lookup alone is printed.
 */
#include "harness.h"

#include <math.h>
#include <stdio.h>

#define PATH_AHEAD_MM 400.0 /* longer than any stop of the models here */

/* The verdict of one tick: with each robot's programmed path ahead as its stop path
 * (dc_protective_query_with_paths, the mock's commanded TCPs lie on it: 0.1 mm tolerance),
 * or without paths. */
static DcStatus query_tick(DcCollider *h, const MrScenario *s, const MrStop stop[MR_MAX_ROBOTS], int with_paths,
                           DcVerdict *v, DcProtectiveReport *rep)
{
    DcVec3 tcps[MR_MAX_ROBOTS], points[MR_MAX_ROBOTS][DC_MAX_PATH_POINTS];
    DcStopPath paths[MR_MAX_ROBOTS];
    double ahead[DC_MAX_PATH_POINTS][3];
    size_t j, k;
    for (j = 0; j < s->n_robots; ++j) {
        tcps[j] = vec3(stop[j].o.tcp[0], stop[j].o.tcp[1], stop[j].o.tcp[2]);
        paths[j].n_points = mr_path_ahead(&s->robots[j], stop[j].o.path_tick, PATH_AHEAD_MM, ahead, DC_MAX_PATH_POINTS);
        /* The path starts at the TCP itself (the stop moves on from there). */
        points[j][0] = tcps[j];
        for (k = 1; k < paths[j].n_points; ++k) {
            points[j][k] = vec3(ahead[k][0], ahead[k][1], ahead[k][2]);
        }
        paths[j].points = points[j];
        paths[j].tolerance_mm = 0.1;
    }
    if (!with_paths) {
        return dc_protective_query(h, tcps, s->n_robots, v, rep);
    }
    return dc_protective_query_with_paths(h, tcps, s->n_robots, paths, s->n_robots, v, rep);
}

VerdictTally run_protective(const char *cell_name, const char *case_name, const char *model_name,
                            const DcStopConfig *model, const HarnessTable *table, int with_paths, long n_ticks)
{
    MrCell cell;
    MrScenario scenario;
    DcStopConfig stops[MR_MAX_ROBOTS];
    DcCollider *h = NULL, *exact = NULL;
    MrStop stop[MR_MAX_ROBOTS];
    StopStats st = { 0, 0, 0, 0.0 };
    VerdictTally t = tally_start();
    long tick;
    size_t j;
    DcStatus s;

    if (!open_protective("protective", cell_name, case_name, model, table, &cell, &scenario, stops, &h, &exact)) {
        return t;
    }
    for (tick = -1; tick < n_ticks; ++tick) {
        DcVerdict v = DC_VERDICT_FREE;
        DcProtectiveReport rep;
        int sub;
        if (st.stops == 0) {
            /* Tick -1, start-up: the robots stand at their first waypoint (primes the speeds). */
            for (j = 0; j < cell.n_robots; ++j) {
                stop[j].o.path_tick = tick < 0 ? 0.0 : (double)tick;
                mr_trajectory_tcp_at(&scenario.robots[j], stop[j].o.path_tick, stop[j].o.tcp);
            }
        } else {
            /* The stop in 0.1 ms steps, each checked with the exact model. */
            for (sub = 0; sub < STOP_SUBSTEPS; ++sub) {
                stop_substep(exact, &scenario, stop, &st);
            }
        }
        s = query_tick(h, &scenario, stop, with_paths, &v, &rep);
        if (tick < 0) {
            continue;
        }
        if (tally_verdict(&t, tick, s, v, &rep) && st.stops == 0) {
            /* Each robot keeps its programmed motion (no override cap) for its reaction; its
             * speed now, should braking start within the first step, over the last 0.05 ms. */
            for (j = 0; j < cell.n_robots; ++j) {
                MrOverride now = stop[j].o;
                double b[3];
                mr_trajectory_tcp_at(&scenario.robots[j], now.path_tick - 0.05, b);
                now.speed = sqrt((now.tcp[0] - b[0]) * (now.tcp[0] - b[0]) + (now.tcp[1] - b[1]) * (now.tcp[1] - b[1])
                                 + (now.tcp[2] - b[2]) * (now.tcp[2] - b[2])) / 0.05e-3;
                now.cap = INFINITY;
                mr_stop_start(&now, stops[j].reaction_ms, stops[j].decel_mm_s2, &stop[j]);
            }
            st.stops = 1;
        }
    }
    check(st.contacts == 0, "protective %s %s: %lu of %lu samples of the stop touch", cell_name, case_name,
          st.contacts, st.samples);
    check(t.first_stop < 0 || st.samples > 0, "protective %s %s: the stop was not simulated", cell_name, case_name);
    printf("protective %s %-9s %-7s%s%s: first WARN %ld, first STOP %ld", cell_name, case_name, model_name,
           with_paths ? " with paths" : "", table == NULL ? "" : " table mode", t.first_warn, t.first_stop);
    if (t.stop_robot_a != DC_BOX_NONE) {
        printf(" (robots %u-%u)", (unsigned)t.stop_robot_a, (unsigned)t.stop_robot_b);
    }
    printf(", STOP %lu WARN %lu of %ld ticks, statuses not OK %lu, smallest clearance %.1f mm, stop %.1f ms, "
           "%lu exact samples of the stop, contacts %lu\n",
           t.n_stop, t.n_warn, n_ticks, t.n_bad_status, t.min_clear, st.moving_ms, st.samples, st.contacts);
    if (table != NULL) {
        unsigned long lookups = (unsigned long)dc_table_protective_lookups(h);
        printf("protective %s %-9s %-7s%s table mode: %lu of %ld ticks (%.1f %%) answered by the lookup alone\n",
               cell_name, case_name, model_name, with_paths ? " with paths" : "", lookups, n_ticks,
               100.0 * (double)lookups / (double)n_ticks);
    } else {
        check(dc_table_protective_lookups(h) == 0, "protective %s %s: lookups in exact mode", cell_name, case_name);
    }
    dc_destroy(h);
    dc_destroy(exact);
    return t;
}

void protective_scenarios(const HarnessOptions *options)
{
    static const char *cells[] = { "T1", "T2", "T3" };
    static const char *cases[] = { "practical", "collision" };
    /* The default model, and a stiff one (short reaction, hard braking) that stops later and
     * closer, where a wrong bound would show. */
    DcStopConfig standard = dc_stop_config_default(), stiff = dc_stop_config_default();
    size_t c, k;
    stiff.reaction_ms = 2.0;
    stiff.decel_mm_s2 = 120000.0;
    if (options->quick || options->protective_quick) {
        /* Valgrind: the default model stops at about tick 60 and stands still by tick 100. */
        run_protective("T1", "collision", "default", &standard, NULL, 0, 200);
        run_protective("T1", "collision", "default", &standard, NULL, 1, 200); /* the path entry point */
        return;
    }
    for (c = 0; c < 3; ++c) {
        const HarnessTable *table = options->clearance_tables[c].path != NULL ? &options->clearance_tables[c] : NULL;
        for (k = 0; k < 2; ++k) {
            run_protective(cells[c], cases[k], "default", &standard, NULL, 0, MR_TICKS_PER_RUN);
            run_protective(cells[c], cases[k], "stiff", &stiff, NULL, 0, MR_TICKS_PER_RUN);
            /* With the default model the first STOP comes in the first 100 ticks with or
             * without paths (tests/protective_paths.rs counts every tick); with the stiff one
             * the paths decide whether the practical runs stop at all. */
            run_protective(cells[c], cases[k], "stiff", &stiff, NULL, 1, MR_TICKS_PER_RUN);
            if (table != NULL) {
                run_protective(cells[c], cases[k], "default", &standard, table, 0, MR_TICKS_PER_RUN);
                run_protective(cells[c], cases[k], "stiff", &stiff, table, 0, MR_TICKS_PER_RUN);
                run_protective(cells[c], cases[k], "stiff", &stiff, table, 1, MR_TICKS_PER_RUN);
            }
        }
    }
}
