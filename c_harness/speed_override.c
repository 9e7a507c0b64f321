/*
 * speed_override.c: the speed limits of dc_protective_query applied as a speed override
 * (SPEC section 8, "What physics allows"). On the practical scenarios of T1, T2 and T3 each
 * robot follows its programmed path through the mock's override (mr_override_*): every tick
 * it asks for OVERRIDE_SHARE of the speed limit the last query reported for it, and its speed
 * cap moves toward that at OVERRIDE_RAMP of its max_accel_mm_s2 at most. The run ends when
 * every robot has completed its programmed cycle.
 *
 * Every tick the exact model (dc_query on a second handle) checks that no boxes touch. On
 * every tick the protective verdict says STOP, a stop is simulated from that state as in
 * protective.c (each robot keeps its commanded motion for its reaction time, then brakes
 * along its path at its deceleration until still, never past its next waypoint), every
 * 0.1 ms checked with the exact model; the run itself goes on, so the line reports how often
 * a controller would still have had to stop. Beside it an unscaled run of the same scenario
 * counts the STOP ticks without the override.
 *
 * Prints per scenario: `speed override CELL CASE: cycle N ticks, unscaled U ticks (+P %),
 * STOP S of N ticks (unscaled SU), WARN W, stops simulated K (M exact samples, contacts C),
 * ticks touching T, smallest clearance X mm`.
 */
#include "harness.h"

#include <math.h>
#include <stdio.h>

#define OVERRIDE_SHARE 0.9   /* share of the reported speed limit the override asks for */
#define OVERRIDE_RAMP 0.5    /* share of max_accel_mm_s2 the cap may change by: the rest is
                              * left to the path's own acceleration (its corners and profile) */
#define MAX_CYCLES 4         /* a run longer than this many unscaled cycles has stalled */

/* The last waypoint tick of the slowest robot: the programmed cycle. */
static long cycle_ticks(const MrScenario *s)
{
    long end = 0;
    size_t j;
    for (j = 0; j < s->n_robots; ++j) {
        const MrTrajectory *t = &s->robots[j];
        if (t->n_waypoints > 0 && t->tick[t->n_waypoints - 1] > end) {
            end = t->tick[t->n_waypoints - 1];
        }
    }
    return end;
}

static int cycle_done(const MrScenario *s, const MrOverride o[MR_MAX_ROBOTS])
{
    size_t j;
    for (j = 0; j < s->n_robots; ++j) {
        const MrTrajectory *t = &s->robots[j];
        if (o[j].path_tick < (double)t->tick[t->n_waypoints - 1]) {
            return 0;
        }
    }
    return 1;
}

static void tcps_of(const MrOverride o[MR_MAX_ROBOTS], size_t n, DcVec3 out[MR_MAX_ROBOTS])
{
    size_t j;
    for (j = 0; j < n; ++j) {
        out[j] = vec3(o[j].tcp[0], o[j].tcp[1], o[j].tcp[2]);
    }
}

/* A stop from the robots' state `now`: the reaction keeps each robot's commanded motion (its
 * cap frozen at its speed), then it brakes along its path; every 0.1 ms the exact handle
 * checks for contact. */
static void simulate_stop(DcCollider *exact, const MrScenario *s, const DcStopConfig stops[MR_MAX_ROBOTS],
                          const MrOverride now[MR_MAX_ROBOTS], StopStats *st)
{
    MrStop stop[MR_MAX_ROBOTS];
    double elapsed_ms = 0.0;
    size_t j;
    for (j = 0; j < s->n_robots; ++j) {
        MrOverride o = now[j];
        o.cap = o.speed;
        mr_stop_start(&o, stops[j].reaction_ms, stops[j].decel_mm_s2, &stop[j]);
    }
    st->stops++;
    while (stop_substep(exact, s, stop, st) && elapsed_ms < 10000.0) {
        elapsed_ms += 1.0 / STOP_SUBSTEPS;
    }
}

/* The unscaled run's STOP ticks (robots on their programmed timing, the verdict unheeded). */
static unsigned long unscaled_stops(DcCollider *h, const MrScenario *s, long n_ticks)
{
    unsigned long n_stop = 0;
    long tick;
    size_t j;
    dc_protective_reset(h);
    for (tick = 0; tick < n_ticks; ++tick) {
        DcVec3 tcps[MR_MAX_ROBOTS];
        DcVerdict v = DC_VERDICT_STOP;
        for (j = 0; j < s->n_robots; ++j) {
            double p[3];
            mr_trajectory_tcp(&s->robots[j], tick, p);
            tcps[j] = vec3(p[0], p[1], p[2]);
        }
        dc_protective_query(h, tcps, s->n_robots, &v, NULL);
        /* The first query has no previous TCP (full speed assumed): the robots stood still. */
        n_stop += tick > 0 && v == DC_VERDICT_STOP;
    }
    return n_stop;
}

static void run_override(const char *cell_name, const char *case_name)
{
    MrCell cell;
    MrScenario scenario;
    DcStopConfig stops[MR_MAX_ROBOTS];
    DcCollider *h = NULL, *exact = NULL;
    MrOverride o[MR_MAX_ROBOTS];
    StopStats st = { 0, 0, 0, 0.0 };
    VerdictTally t = tally_start();
    long tick, cycle, max_ticks;
    unsigned long touching = 0, n_unscaled;
    int done = 0;
    size_t j;
    DcStatus s;

    DcStopConfig standard = dc_stop_config_default();
    if (!open_protective("speed override", cell_name, case_name, &standard, NULL, &cell, &scenario, stops, &h, &exact)) {
        return;
    }
    cycle = cycle_ticks(&scenario);
    max_ticks = MAX_CYCLES * cycle;
    n_unscaled = unscaled_stops(h, &scenario, cycle);

    dc_protective_reset(h);
    for (j = 0; j < cell.n_robots; ++j) {
        mr_override_start(&scenario.robots[j], &o[j]);
    }
    {
        /* Start-up: the robots stand at their first waypoint; this primes the speeds. */
        DcVec3 tcps[MR_MAX_ROBOTS];
        DcVerdict v;
        DcProtectiveReport rep;
        tcps_of(o, cell.n_robots, tcps);
        dc_protective_query(h, tcps, cell.n_robots, &v, NULL);
        dc_protective_query(h, tcps, cell.n_robots, &v, &rep);
        for (j = 0; j < cell.n_robots; ++j) {
            mr_override_request(&o[j], OVERRIDE_SHARE * rep.speed_limit_mm_s[j],
                                OVERRIDE_RAMP * stops[j].max_accel_mm_s2, 1e-3);
        }
    }
    for (tick = 0; tick < max_ticks && !done; ++tick) {
        DcVec3 tcps[MR_MAX_ROBOTS];
        DcVerdict v = DC_VERDICT_STOP, ve = DC_VERDICT_STOP;
        DcProtectiveReport rep;
        for (j = 0; j < cell.n_robots; ++j) {
            mr_override_step(&scenario.robots[j], &o[j], 1.0, 1e-3);
        }
        tcps_of(o, cell.n_robots, tcps);
        s = dc_query(exact, tcps, cell.n_robots, &ve, NULL);
        if (s != DC_STATUS_OK || ve != DC_VERDICT_FREE) {
            touching++;
        }
        s = dc_protective_query(h, tcps, cell.n_robots, &v, &rep);
        if (tally_verdict(&t, tick, s, v, &rep)) {
            simulate_stop(exact, &scenario, stops, o, &st);
        }
        for (j = 0; j < cell.n_robots; ++j) {
            /* No limit without an OK status (the report's is 0 then): slow down. */
            double limit = s == DC_STATUS_OK ? rep.speed_limit_mm_s[j] : 0.0;
            mr_override_request(&o[j], OVERRIDE_SHARE * limit, OVERRIDE_RAMP * stops[j].max_accel_mm_s2, 1e-3);
        }
        done = cycle_done(&scenario, o);
    }
    check(touching == 0, "speed override %s %s: the boxes touch on %lu ticks", cell_name, case_name, touching);
    check(st.contacts == 0, "speed override %s %s: %lu of %lu samples of the simulated stops touch", cell_name,
          case_name, st.contacts, st.samples);
    check(t.n_bad_status == 0, "speed override %s %s: %lu queries without status OK (implausible motion?)", cell_name,
          case_name, t.n_bad_status);
    check(done, "speed override %s %s: the cycle of %ld ticks did not complete in %ld ticks", cell_name, case_name,
          cycle, max_ticks);
    printf("speed override %s %s: cycle %s%ld ticks, unscaled %ld ticks (%+.1f %%), STOP %lu of %ld ticks (unscaled "
           "%lu), first STOP %ld, WARN %lu, stops simulated %lu (%lu exact samples, contacts %lu), ticks touching %lu, "
           "smallest clearance %.1f mm\n",
           cell_name, case_name, done ? "" : "NOT COMPLETED ", tick, cycle, 100.0 * (double)(tick - cycle) / (double)cycle,
           t.n_stop, tick, n_unscaled, t.first_stop, t.n_warn, st.stops, st.samples, st.contacts, touching, t.min_clear);
    dc_destroy(h);
    dc_destroy(exact);
}

void speed_override_scenarios(const HarnessOptions *options)
{
    static const char *cells[] = { "T1", "T2", "T3" };
    size_t c;
    if (options->quick || options->protective_quick) {
        /* Each run queries the speed limits on every tick: minutes under valgrind or qemu. */
        printf("speed override: skipped (--quick / --protective-quick)\n");
        return;
    }
    for (c = 0; c < 3; ++c) {
        run_override(cells[c], "practical");
    }
}
