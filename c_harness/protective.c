/*
 * protective.c: the protective verdict end to end (SPEC section 8). Each trajectory scenario
 * runs with dc_protective_query once per tick; at the first STOP every simulated robot keeps
 * its commanded motion for its reaction time, then brakes along its own path at its
 * configured deceleration until still (a path-maintaining stop that ends at the path's next
 * waypoint at the latest). Every 0.1 ms of that stop the exact model (dc_query on a second
 * handle) must find no contact. Prints per scenario the first WARN and STOP ticks, the STOP
 * and WARN counts, the smallest clearance and the stop's length. --quick (valgrind) runs the
 * first 200 ticks of T1 collision with the default model, which hold its whole stop.
 */
#include "harness.h"
#include "pou.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define SUBSTEPS 10          /* 0.1 ms steps per 1 ms tick */
#define PATH_STEP_MS 0.01    /* resolution of the walk along a path while braking */

/* The tick of the first waypoint after `tick` (the end of the current straight segment). */
static double segment_end(const MrTrajectory *t, double tick)
{
    size_t i;
    for (i = 0; i < t->n_waypoints; ++i) {
        if ((double)t->tick[i] > tick) {
            return (double)t->tick[i];
        }
    }
    return tick;
}

static double dist3(const double a[3], const double b[3])
{
    return sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

/* One robot during a stop: its place on the path (in trajectory ticks) and speed. */
typedef struct Stopping {
    double path_tick;  /* where on its path the robot is */
    double end_tick;   /* braking never passes this waypoint */
    double speed;      /* mm/s while braking */
    double elapsed_ms; /* since the STOP */
    int braking, still;
    double tcp[3];
} Stopping;

/* Advances one robot by dt_ms of its stop (reaction, then braking along its path). */
static void stop_step(const MrTrajectory *t, const DcStopConfig *m, double dt_ms, Stopping *s)
{
    if (s->still) {
        return;
    }
    s->elapsed_ms += dt_ms;
    if (s->elapsed_ms <= m->reaction_ms) {
        s->path_tick += dt_ms; /* keeps its commanded motion */
        mr_trajectory_tcp_at(t, s->path_tick, s->tcp);
        return;
    }
    if (!s->braking) {
        double a[3], b[3];
        mr_trajectory_tcp_at(t, s->path_tick - 0.05, a);
        mr_trajectory_tcp_at(t, s->path_tick, b);
        s->speed = dist3(a, b) / 0.05e-3;
        s->end_tick = segment_end(t, s->path_tick);
        s->braking = 1;
    }
    {
        double next_speed = s->speed - m->decel_mm_s2 * dt_ms * 1e-3;
        double dist = 0.5 * (s->speed + (next_speed > 0.0 ? next_speed : 0.0)) * dt_ms * 1e-3;
        double here[3];
        if (next_speed <= 0.0) {
            s->still = 1;
            next_speed = 0.0;
        }
        s->speed = next_speed;
        /* Walk along the path until `dist` is covered, never past the segment's end. */
        memcpy(here, s->tcp, sizeof here);
        while (dist > 0.0 && s->path_tick < s->end_tick) {
            double p[3], step;
            double tick = s->path_tick + PATH_STEP_MS;
            if (tick > s->end_tick) {
                tick = s->end_tick;
            }
            mr_trajectory_tcp_at(t, tick, p);
            step = dist3(here, p);
            if (step > dist) {
                /* Part of this small step, on the chord (the path is straight). */
                double f = dist / step;
                size_t k;
                for (k = 0; k < 3; ++k) {
                    here[k] += f * (p[k] - here[k]);
                }
                s->path_tick += f * (tick - s->path_tick);
                dist = 0.0;
            } else {
                memcpy(here, p, sizeof here);
                dist -= step;
                s->path_tick = tick;
            }
        }
        if (s->path_tick >= s->end_tick) {
            s->still = 1;
        }
        memcpy(s->tcp, here, sizeof here);
    }
}

/* One scenario with the protective verdict, every robot with stopping model `model`, warn_mm 10. */
static void run_protective(const char *cell_name, const char *case_name, const char *model_name,
                           const DcStopConfig *model, long n_ticks)
{
    MrCell cell;
    MrScenario scenario;
    DcRobotConfig robots[MR_MAX_ROBOTS];
    DcCellConfig config;
    DcStopConfig stops[MR_MAX_ROBOTS];
    DcCollider *h = NULL, *exact = NULL;
    Stopping st[MR_MAX_ROBOTS];
    long tick, first_warn = -1, first_stop = -1;
    unsigned long n_warn = 0, n_stop = 0, n_bad_status = 0, samples = 0, contacts = 0;
    double min_clear = INFINITY, stop_ms = 0.0;
    int stopping = 0;
    size_t j;
    DcStatus s;

    if (mr_register_cell(cell_name, &cell) != MR_OK
        || mr_load_scenario(SCENARIO_FILE, cell_name, case_name, cell.n_robots, &scenario) != MR_OK) {
        check(0, "protective %s %s: cannot load the scenario", cell_name, case_name);
        return;
    }
    pou_cell_config(&cell, DC_METHOD_SAT_CACHE, robots, &config);
    s = dc_init(&config, &h);
    check(s == DC_STATUS_OK, "protective %s: dc_init: %s", cell_name, dc_status_str(s));
    s = dc_init(&config, &exact);
    check(s == DC_STATUS_OK, "protective %s: dc_init (exact): %s", cell_name, dc_status_str(s));
    for (j = 0; j < cell.n_robots; ++j) {
        stops[j] = *model;
    }
    s = dc_set_stop_model(h, 1.0, 10.0, stops, cell.n_robots);
    check(s == DC_STATUS_OK, "protective %s: dc_set_stop_model: %s", cell_name, dc_status_str(s));
    if (h == NULL || exact == NULL) {
        dc_destroy(h);
        dc_destroy(exact);
        return;
    }
    memset(st, 0, sizeof st);
    for (j = 0; j < cell.n_robots; ++j) {
        mr_trajectory_tcp_at(&scenario.robots[j], 0.0, st[j].tcp);
    }
    {
        /* Start-up: the robots stand at their first waypoint; this primes the speeds. */
        DcVec3 tcps[MR_MAX_ROBOTS];
        DcVerdict v;
        for (j = 0; j < cell.n_robots; ++j) {
            tcps[j] = vec3(st[j].tcp[0], st[j].tcp[1], st[j].tcp[2]);
        }
        dc_protective_query(h, tcps, cell.n_robots, &v, NULL);
    }
    for (tick = 0; tick < n_ticks; ++tick) {
        DcVec3 tcps[MR_MAX_ROBOTS];
        DcVerdict v = DC_VERDICT_FREE;
        DcProtectiveReport rep;
        int sub;
        if (!stopping) {
            for (j = 0; j < cell.n_robots; ++j) {
                st[j].path_tick = (double)tick;
                mr_trajectory_tcp_at(&scenario.robots[j], (double)tick, st[j].tcp);
            }
        } else {
            /* The stop in 0.1 ms steps, each checked with the exact model. */
            for (sub = 0; sub < SUBSTEPS; ++sub) {
                DcVerdict ve = DC_VERDICT_STOP;
                int moving = 0;
                for (j = 0; j < cell.n_robots; ++j) {
                    stop_step(&scenario.robots[j], &stops[j], 1.0 / SUBSTEPS, &st[j]);
                    tcps[j] = vec3(st[j].tcp[0], st[j].tcp[1], st[j].tcp[2]);
                    moving |= !st[j].still;
                }
                if (moving) {
                    stop_ms += 1.0 / SUBSTEPS;
                }
                s = dc_query(exact, tcps, cell.n_robots, &ve, NULL);
                samples++;
                if (s != DC_STATUS_OK || ve != DC_VERDICT_FREE) {
                    contacts++;
                }
            }
        }
        for (j = 0; j < cell.n_robots; ++j) {
            tcps[j] = vec3(st[j].tcp[0], st[j].tcp[1], st[j].tcp[2]);
        }
        s = dc_protective_query(h, tcps, cell.n_robots, &v, &rep);
        if (s != DC_STATUS_OK) {
            n_bad_status++;
        }
        if (rep.clearance_mm < min_clear) {
            min_clear = rep.clearance_mm;
        }
        if (v == DC_VERDICT_WARN) {
            n_warn++;
            if (first_warn < 0) {
                first_warn = tick;
            }
        } else if (v != DC_VERDICT_FREE) {
            n_stop++;
            if (first_stop < 0) {
                first_stop = tick;
            }
            stopping = 1;
        }
    }
    check(contacts == 0, "protective %s %s: %lu of %lu samples of the stop touch", cell_name, case_name, contacts,
          samples);
    check(first_stop < 0 || samples > 0, "protective %s %s: the stop was not simulated", cell_name, case_name);
    printf("protective %s %-9s %-7s: first WARN %ld, first STOP %ld, STOP %lu WARN %lu of %ld ticks, statuses not OK %lu, "
           "smallest clearance %.1f mm, stop %.1f ms, %lu exact samples of the stop, contacts %lu\n",
           cell_name, case_name, model_name, first_warn, first_stop, n_stop, n_warn, n_ticks, n_bad_status, min_clear,
           stop_ms, samples, contacts);
    dc_destroy(h);
    dc_destroy(exact);
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
        run_protective("T1", "collision", "default", &standard, 200);
        return;
    }
    for (c = 0; c < 3; ++c) {
        for (k = 0; k < 2; ++k) {
            run_protective(cells[c], cases[k], "default", &standard, MR_TICKS_PER_RUN);
            run_protective(cells[c], cases[k], "stiff", &stiff, MR_TICKS_PER_RUN);
        }
    }
}
