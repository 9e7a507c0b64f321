/*
 * coordination.c: the coordination (dc_coordinate, SPEC section 9) in the mock controller's
 * tick loop. On T1 both robots follow pick-and-place programmes the mock generates
 * (mr_pick_place_programme, COORD_CYCLES cycles): pick on the far side, place at the midpoint
 * between the bases, both at the same programmed ticks, so that executed as programmed they
 * would collide at the place point. Each robot's progress along its programme is a parameter
 * of its own (programme ticks, one per tick at override 1), its TCP the programme's there.
 * Every 1 ms tick the controller
 *   1. checks contact with the exact model (dc_query on a second handle);
 *   2. calls dc_coordinate with each robot's next set-points (one every COORD_STRIDE
 *      programme ticks from the one at or behind its progress, up to COORD_POINTS), its
 *      progress and the override it followed over the last tick;
 *   3. calls dc_protective_query_timed with the tick as its cycle and each robot's path ahead
 *      as its stop path (the robots never leave their paths);
 *   4. on STOP, or a coordination status other than OK, stops the robots: each moving robot
 *      brakes along its path at its decel_mm_s2 (never ahead of its programme at the override
 *      it had) until it stands, and the robots stand while the STOP lasts; else each robot's
 *      progress advances by its override.
 * The run ends when both programmes are done, on a deadlock (less than DEADLOCK_MM of TCP
 * travel of both robots together over DEADLOCK_TICKS ticks while a programme is unfinished,
 * SPEC section 9) or after MAX_FACTOR times the programmed ticks. The speed limits are off
 * (dc_set_speed_limits): the loop reads the verdict only.
 *
 * Checks: no contact on any tick, every dc_coordinate status OK, the programmes reachable, and
 * the C ABI's answers to bad coordination requests (each its status, every override 0.0).
 * Whether the run finishes or deadlocks, and whether the overrides keep the motion plausible
 * for the protective verdict (its statuses), are properties of the library: printed, not
 * checked. Prints
 * `coordination T1: programmed P ticks, taken N ticks, throughput kept X %, finished yes|no,
 * STOP events S (STOP ticks T, WARN ticks W), contact ticks C, deadlock yes|no, held ticks H,
 * smallest override O, smallest clearance M mm, protective statuses not OK B`. --quick and
 * --protective-quick (valgrind, qemu) run the first QUICK_TICKS ticks only and print
 * `coordination T1 quick: ...`.
 */
#include "harness.h"
#include "pou.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define COORD_CELL "T1"
#define COORD_CYCLES 3
#define COORD_STRIDE 4      /* programme ticks between two set-points passed */
#define COORD_POINTS 64     /* set-points passed per robot at most */
#define PATH_AHEAD_MM 400.0 /* stop path passed to the protective query: longer than any stop */
#define PATH_TOLERANCE_MM 0.1
#define DEADLOCK_TICKS 3000
#define DEADLOCK_MM 1.0
#define MAX_FACTOR 4 /* a run longer than this many times the programmed ticks ends */
#define QUICK_TICKS 500L
#define DT_S 1e-3

/* One robot of the loop. */
typedef struct CoordRobot {
    double progress;     /* along its programme (programme ticks) */
    double override_now; /* programme ticks it advanced over the last tick, in [0, 1] */
    double speed;        /* TCP speed over the last tick (mm/s) */
    double tcp[3];       /* TCP now (MCS) */
    int braking;         /* carrying out a STOP until it stands */
} CoordRobot;

/* Calls of one function without status OK. */
typedef struct BadCalls {
    long n, first_tick; /* first_tick -1: none */
    DcStatus first;
} BadCalls;

/* What a run saw. */
typedef struct CoordStats {
    long ticks, stop_events, stop_ticks, warn_ticks, contact_ticks, held_ticks;
    BadCalls coordination, protective;
    double least_override, least_clearance;
    int finished, deadlock;
} CoordStats;

static double distance3(const double a[3], const double b[3])
{
    return sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

static double end_tick(const MrTrajectory *t)
{
    return (double)t->tick[t->n_waypoints - 1];
}

/* Moves robot r to progress `next` (>= its progress): TCP, speed and the override followed. */
static void move_to(const MrTrajectory *t, CoordRobot *r, double next)
{
    double before[3];
    memcpy(before, r->tcp, sizeof before);
    r->override_now = next - r->progress;
    r->override_now = r->override_now < 0.0 ? 0.0 : (r->override_now > 1.0 ? 1.0 : r->override_now);
    r->progress = next;
    mr_trajectory_tcp_at(t, next, r->tcp);
    r->speed = distance3(before, r->tcp) / DT_S;
}

/* The progress `distance_mm` along the path from `tick`, across waypoints; a dwell (a waypoint
 * held) stops it there. */
static double advance_along(const MrTrajectory *t, double tick, double distance_mm)
{
    size_t n;
    for (n = 0; n < MR_MAX_WAYPOINTS && distance_mm > 1e-9; ++n) {
        double before[3], after[3], next = mr_trajectory_advance(t, tick, distance_mm);
        if (!(next > tick)) {
            break;
        }
        mr_trajectory_tcp_at(t, tick, before);
        mr_trajectory_tcp_at(t, next, after);
        distance_mm -= distance3(before, after);
        tick = next;
    }
    return tick;
}

/* One tick of a robot's stop: its speed falls by decel_mm_s2 per second along its path, and it
 * goes no further than its programme would at the override it had; it stands when it does not
 * move any more. */
static void brake_step(const MrTrajectory *t, const DcStopConfig *stop, CoordRobot *r)
{
    double v = r->speed - stop->decel_mm_s2 * DT_S;
    double next = advance_along(t, r->progress, (v > 0.0 ? v : 0.0) * DT_S);
    double cap = r->progress + r->override_now;
    if (next > cap) {
        next = cap;
    }
    if (next > end_tick(t)) {
        next = end_tick(t);
    }
    move_to(t, r, next);
    if (!(r->speed > 0.0)) {
        r->braking = 0;
        r->override_now = 0.0;
    }
}

/* Robot j's set-points ahead for dc_coordinate into points (3 per point, COORD_POINTS at most),
 * from the one at or behind its progress, up to the first at or after its programme's end. */
static DcProgramme programme_ahead(const MrTrajectory *t, const CoordRobot *r, double points[COORD_POINTS * 3])
{
    DcProgramme p;
    long first = (long)floor(r->progress / COORD_STRIDE) * COORD_STRIDE;
    uint32_t n = 0;
    while (n < COORD_POINTS) {
        long tick = first + (long)n * COORD_STRIDE;
        mr_trajectory_tcp(t, tick, &points[3 * n]);
        n++;
        if ((double)tick >= end_tick(t)) {
            break;
        }
    }
    p.first_tick = (uint64_t)first;
    p.stride_ticks = COORD_STRIDE;
    p.n_points = n;
    p.points = points;
    p.progress = r->progress;
    p.override_now = r->override_now;
    return p;
}

/* Robot j's path ahead for the protective query: from its TCP on along its programme. */
static DcStopPath path_ahead(const MrTrajectory *t, const CoordRobot *r, DcVec3 points[DC_MAX_PATH_POINTS])
{
    double ahead[DC_MAX_PATH_POINTS][3];
    DcStopPath path;
    size_t k;
    path.n_points = mr_path_ahead(t, r->progress, PATH_AHEAD_MM, ahead, DC_MAX_PATH_POINTS);
    points[0] = vec3(r->tcp[0], r->tcp[1], r->tcp[2]);
    for (k = 1; k < path.n_points; ++k) {
        points[k] = vec3(ahead[k][0], ahead[k][1], ahead[k][2]);
    }
    path.points = points;
    path.tolerance_mm = PATH_TOLERANCE_MM;
    return path;
}

/* The C ABI's answers to bad coordination requests on live handle h of a two-robot cell, with
 * valid programmes good[2]: each its status, and every override written 0.0. */
static void bad_requests(DcCollider *h, const DcProgramme good[2])
{
    DcCoordinationRequest req = dc_coordination_request_default();
    DcProgramme p[2];
    double overrides[2], nan_point[3];
    DcRobotCoordination robots[2];
    DcStatus s;
    int i;
    static const char *names[] = { "NaN point",          "stride 0",   "first tick not a multiple",
                                   "no points",          "too many points", "progress beyond the end",
                                   "override above 1",   "one robot",  "short struct_size",
                                   "NULL programmes",    "NULL handle" };
    static const DcStatus expected[] = { DC_STATUS_NON_FINITE,          DC_STATUS_INVALID_PROGRAMME,
                                         DC_STATUS_INVALID_PROGRAMME,   DC_STATUS_INVALID_PROGRAMME,
                                         DC_STATUS_INVALID_PROGRAMME,   DC_STATUS_PROGRESS_OUT_OF_RANGE,
                                         DC_STATUS_PROGRESS_OUT_OF_RANGE, DC_STATUS_WRONG_ROBOT_COUNT,
                                         DC_STATUS_INVALID_ARGUMENT,    DC_STATUS_NULL_POINTER,
                                         DC_STATUS_NULL_POINTER };
    nan_point[0] = NAN;
    nan_point[1] = nan_point[2] = 0.0;
    for (i = 0; i < (int)(sizeof expected / sizeof expected[0]); ++i) {
        DcCollider *handle = h;
        memcpy(p, good, sizeof p);
        req = dc_coordination_request_default();
        req.n_robots = 2;
        req.programmes = p;
        switch (i) {
        case 0: p[1].points = nan_point; p[1].n_points = 1; p[1].progress = (double)p[1].first_tick; break;
        case 1: p[0].stride_ticks = 0; break;
        case 2: p[1].first_tick += 2; break;
        case 3: p[0].n_points = 0; break;
        case 4: p[1].n_points = DC_MAX_PROGRAMME_POINTS + 1; break;
        case 5: p[0].progress = (double)(p[0].first_tick + (uint64_t)p[0].stride_ticks * p[0].n_points); break;
        case 6: p[1].override_now = 2.0; break;
        case 7: req.n_robots = 1; break;
        case 8: req.struct_size = (uint32_t)sizeof req - 1; break;
        case 9: req.programmes = NULL; break;
        default: handle = NULL; break;
        }
        overrides[0] = overrides[1] = 0.5;
        robots[0].held_by = robots[1].held_by = 7;
        s = dc_coordinate(handle, &req, overrides, robots);
        check(s == expected[i], "coordination bad input %s: status %u (%s), expected %u", names[i], (unsigned)s,
              dc_status_str(s), (unsigned)expected[i]);
        check(overrides[0] == 0.0 && (i == 7 || overrides[1] == 0.0) && robots[0].held_by == -1,
              "coordination bad input %s: overrides %g %g, held by %d, not 0 0 -1", names[i], overrides[0],
              overrides[1], (int)robots[0].held_by);
    }
    s = dc_coordinate(h, NULL, overrides, NULL);
    check(s == DC_STATUS_NULL_POINTER, "coordination bad input NULL request: status %u", (unsigned)s);
    req = dc_coordination_request_default();
    req.n_robots = 2;
    req.programmes = good;
    s = dc_coordinate(h, &req, overrides, NULL);
    check(s == DC_STATUS_OK && overrides[0] >= 0.0 && overrides[0] <= 1.0 && overrides[1] >= 0.0
              && overrides[1] <= 1.0,
          "coordination: a valid request after the bad ones: status %u, overrides %g %g", (unsigned)s, overrides[0],
          overrides[1]);
    check(dc_set_coordination_clearance(h, 0.0) == DC_STATUS_INVALID_ARGUMENT
              && dc_set_coordination_clearance(h, NAN) == DC_STATUS_INVALID_ARGUMENT
              && dc_set_coordination_clearance(NULL, 40.0) == DC_STATUS_NULL_POINTER
              && dc_set_coordination_clearance(h, 40.0) == DC_STATUS_OK,
          "coordination: dc_set_coordination_clearance's statuses");
    check(dc_set_coordination_right_of_way(h, 2) == DC_STATUS_INVALID_ARGUMENT
              && dc_set_coordination_right_of_way(NULL, DC_RIGHT_OF_WAY_ARRIVAL) == DC_STATUS_NULL_POINTER
              && dc_set_coordination_right_of_way(h, DC_RIGHT_OF_WAY_PROGRAMMED) == DC_STATUS_OK
              && dc_set_coordination_right_of_way(h, DC_RIGHT_OF_WAY_ARRIVAL) == DC_STATUS_OK,
          "coordination: dc_set_coordination_right_of_way's statuses");
    check(dc_coordination_horizon() >= 1, "coordination: dc_coordination_horizon() is 0");
    check(strcmp(dc_status_str(DC_STATUS_INVALID_PROGRAMME), "unknown status") != 0
              && strcmp(dc_status_str(DC_STATUS_PROGRESS_OUT_OF_RANGE), "unknown status") != 0,
          "coordination: the new statuses have a text");
    dc_coordination_reset(NULL);
    dc_coordination_reset(h);
}

static void tally_status(BadCalls *bad, long tick, DcStatus s)
{
    if (s != DC_STATUS_OK) {
        if (bad->n++ == 0) {
            bad->first_tick = tick;
            bad->first = s;
        }
    }
}

/* The loop (file comment) for at most max_ticks ticks. */
static void run_loop(DcCollider *h, DcCollider *exact, const MrScenario *sc, const DcStopConfig stops[2],
                     long max_ticks, CoordStats *st)
{
    static double travel[DEADLOCK_TICKS]; /* TCP travel of both robots per tick, a ring */
    double travel_sum = 0.0;
    CoordRobot r[2];
    long tick;
    size_t j;
    memset(travel, 0, sizeof travel);
    for (j = 0; j < 2; ++j) {
        memset(&r[j], 0, sizeof r[j]);
        mr_trajectory_tcp_at(&sc->robots[j], 0.0, r[j].tcp);
    }
    for (tick = 0; tick < max_ticks; ++tick) {
        double points[2][COORD_POINTS * 3], overrides[2] = { 0.0, 0.0 }, moved = 0.0;
        DcVec3 tcps[2], path_points[2][DC_MAX_PATH_POINTS];
        DcProgramme programmes[2];
        DcStopPath paths[2];
        DcRobotCoordination robots[2];
        DcCoordinationRequest creq = dc_coordination_request_default();
        DcProtectiveRequest preq = dc_protective_request_default();
        DcProtectiveReport rep;
        DcVerdict v = DC_VERDICT_STOP, ve = DC_VERDICT_STOP;
        DcStatus sc_status, sp_status, se_status;
        int halt, new_stop = 0;
        if (r[0].progress >= end_tick(&sc->robots[0]) && r[1].progress >= end_tick(&sc->robots[1])) {
            st->finished = 1;
            break;
        }
        for (j = 0; j < 2; ++j) {
            tcps[j] = vec3(r[j].tcp[0], r[j].tcp[1], r[j].tcp[2]);
        }
        se_status = dc_query(exact, tcps, 2, &ve, NULL);
        st->contact_ticks += se_status != DC_STATUS_OK || ve != DC_VERDICT_FREE;

        for (j = 0; j < 2; ++j) {
            programmes[j] = programme_ahead(&sc->robots[j], &r[j], points[j]);
        }
        creq.n_robots = 2;
        creq.programmes = programmes;
        sc_status = dc_coordinate(h, &creq, overrides, robots);
        tally_status(&st->coordination, tick, sc_status);
        st->held_ticks += robots[0].held_by >= 0 || robots[1].held_by >= 0;
        for (j = 0; j < 2; ++j) {
            st->least_override = fmin(st->least_override, overrides[j]);
            paths[j] = path_ahead(&sc->robots[j], &r[j], path_points[j]);
        }

        preq.time = (uint64_t)tick;
        preq.tcps_mcs = tcps;
        preq.n_tcps = 2;
        preq.paths = paths;
        preq.n_paths = 2;
        sp_status = dc_protective_query_timed(h, &preq, &v, &rep);
        tally_status(&st->protective, tick, sp_status);
        if (sp_status == DC_STATUS_OK) {
            st->least_clearance = fmin(st->least_clearance, rep.clearance_mm);
        }
        st->stop_ticks += v == DC_VERDICT_STOP;
        st->warn_ticks += v == DC_VERDICT_WARN;

        /* The controller: a STOP (or no coordination) stops the robots; else the overrides. */
        halt = v == DC_VERDICT_STOP || sc_status != DC_STATUS_OK;
        for (j = 0; j < 2; ++j) {
            if (halt && r[j].speed > 0.0 && !r[j].braking) {
                r[j].braking = 1;
                new_stop = 1;
            }
        }
        st->stop_events += new_stop;
        for (j = 0; j < 2; ++j) {
            const MrTrajectory *t = &sc->robots[j];
            double before[3];
            memcpy(before, r[j].tcp, sizeof before);
            if (r[j].braking) {
                brake_step(t, &stops[j], &r[j]);
            } else if (halt) {
                move_to(t, &r[j], r[j].progress);
            } else {
                double next = r[j].progress + overrides[j];
                move_to(t, &r[j], next < end_tick(t) ? next : end_tick(t));
                if (r[j].progress >= end_tick(t)) {
                    r[j].override_now = 0.0;
                }
            }
            moved += distance3(before, r[j].tcp);
        }
        travel_sum += moved - travel[tick % DEADLOCK_TICKS];
        travel[tick % DEADLOCK_TICKS] = moved;
        if (tick + 1 >= DEADLOCK_TICKS && travel_sum < DEADLOCK_MM) {
            st->deadlock = 1;
            tick++;
            break;
        }
    }
    st->ticks = tick;
}

void coordination_scenarios(const HarnessOptions *options)
{
    MrCell cell;
    MrScenario sc;
    DcRobotConfig robots[MR_MAX_ROBOTS];
    DcCellConfig config;
    DcStopConfig stops[2];
    DcCollider *h = NULL, *exact = NULL;
    CoordStats st;
    DcStatus s;
    MrStatus ms = mr_register_cell(COORD_CELL, &cell);
    int quick = options->quick || options->protective_quick;
    long programmed, max_ticks, tick, unreachable = 0;
    size_t j;

    memset(&sc, 0, sizeof sc);
    memset(&st, 0, sizeof st);
    st.coordination.first_tick = st.protective.first_tick = -1;
    st.least_override = INFINITY;
    st.least_clearance = INFINITY;
    if (!check(ms == MR_OK && cell.n_robots == 2, "coordination: no two-robot cell %s", COORD_CELL)) {
        return;
    }
    sc.n_robots = 2;
    for (j = 0; j < 2; ++j) {
        ms = mr_pick_place_programme(&cell, j, 1 - j, COORD_CYCLES, &sc.robots[j]);
        if (!check(ms == MR_OK, "coordination: programme of robot %lu: %s", (unsigned long)j, mr_status_str(ms))) {
            return;
        }
    }
    programmed = (long)end_tick(&sc.robots[0]);
    for (tick = 0; tick <= programmed; ++tick) {
        for (j = 0; j < 2; ++j) {
            double p[3], theta[3];
            mr_trajectory_tcp(&sc.robots[j], tick, p);
            unreachable += mr_inverse_kinematics(&cell.robots[j].geometry, p, theta) != MR_OK;
        }
    }
    check(unreachable == 0, "coordination: %ld programmed set-points are unreachable", unreachable);

    /* Start-up (allocates): the handle with the default stopping models set, the speed limits
     * off, the exact handle beside it. */
    pou_cell_config(&cell, DC_METHOD_SAT_CACHE, robots, &config);
    s = dc_init(&config, &h);
    check(s == DC_STATUS_OK, "coordination: dc_init: %s", dc_status_str(s));
    s = dc_init(&config, &exact);
    check(s == DC_STATUS_OK, "coordination: dc_init (exact): %s", dc_status_str(s));
    stops[0] = stops[1] = dc_stop_config_default();
    s = h == NULL ? DC_STATUS_NULL_POINTER : dc_set_stop_model(h, 1.0, 10.0, stops, 2);
    check(s == DC_STATUS_OK, "coordination: dc_set_stop_model: %s", dc_status_str(s));
    if (s != DC_STATUS_OK || exact == NULL || !check(dc_set_speed_limits(h, 0) == DC_STATUS_OK, "coordination: dc_set_speed_limits")) {
        dc_destroy(h);
        dc_destroy(exact);
        return;
    }
    {
        static double points[2][COORD_POINTS * 3];
        CoordRobot at[2];
        DcProgramme good[2];
        memset(at, 0, sizeof at);
        at[1].progress = 40.0;
        for (j = 0; j < 2; ++j) {
            good[j] = programme_ahead(&sc.robots[j], &at[j], points[j]);
        }
        bad_requests(h, good);
    }

    max_ticks = quick ? QUICK_TICKS : MAX_FACTOR * programmed;
    run_loop(h, exact, &sc, stops, max_ticks, &st);

    check(st.contact_ticks == 0, "coordination %s: the boxes touch on %ld ticks", COORD_CELL, st.contact_ticks);
    check(st.coordination.n == 0, "coordination %s: %ld dc_coordinate calls without status OK (first at tick %ld: %s)",
          COORD_CELL, st.coordination.n, st.coordination.first_tick, dc_status_str(st.coordination.first));
    printf("coordination %s%s: programmed %ld ticks, taken %ld ticks, throughput kept %.1f %%, finished %s, STOP "
           "events %ld (STOP ticks %ld, WARN ticks %ld), contact ticks %ld, deadlock %s, held ticks %ld, smallest "
           "override %.3f, smallest clearance %.1f mm, protective statuses not OK %ld%s%s%s\n",
           COORD_CELL, quick ? " quick" : "", programmed, st.ticks,
           st.finished && st.ticks > 0 ? 100.0 * (double)programmed / (double)st.ticks : 0.0,
           st.finished ? "yes" : "no", st.stop_events, st.stop_ticks, st.warn_ticks, st.contact_ticks,
           st.deadlock ? "yes" : "no", st.held_ticks, st.least_override, st.least_clearance, st.protective.n,
           st.protective.n > 0 ? " (the first: " : "", st.protective.n > 0 ? dc_status_str(st.protective.first) : "",
           st.protective.n > 0 ? ")" : "");
    {
        /* The controller's view of its own ticks: every call counted, in the library's time. */
        DcTickStats ts;
        memset(&ts, 0, sizeof ts);
        ts.struct_size = (uint32_t)sizeof ts;
        s = dc_tick_stats(h, &ts);
        check(s == DC_STATUS_OK && ts.coordinate.calls >= (uint64_t)st.ticks / 2
                  && ts.protective.calls >= (uint64_t)st.ticks / 2 && ts.coordinate.largest_ns >= ts.coordinate.mean_ns,
              "coordination %s: dc_tick_stats (status %u) counted %llu dc_coordinate and %llu protective calls in %ld "
              "ticks",
              COORD_CELL, (unsigned)s, (unsigned long long)ts.coordinate.calls,
              (unsigned long long)ts.protective.calls, st.ticks);
        printf("coordination %s tick stats: dc_coordinate %llu calls, mean %.1f us, largest %.1f us, largest work %llu "
               "cells; protective %llu calls, mean %.1f us, largest %.1f us\n",
               COORD_CELL, (unsigned long long)ts.coordinate.calls, 1e-3 * (double)ts.coordinate.mean_ns,
               1e-3 * (double)ts.coordinate.largest_ns, (unsigned long long)ts.coordinate.largest_work,
               (unsigned long long)ts.protective.calls, 1e-3 * (double)ts.protective.mean_ns,
               1e-3 * (double)ts.protective.largest_ns);
        check(dc_tick_stats_reset(h) == DC_STATUS_OK && dc_tick_stats(h, &ts) == DC_STATUS_OK
                  && ts.coordinate.calls == 0,
              "coordination %s: dc_tick_stats_reset", COORD_CELL);
    }
    dc_destroy(h);
    dc_destroy(exact);
}
