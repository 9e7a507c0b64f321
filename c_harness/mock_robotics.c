/*
 * mock_robotics.c: the mock robotics API (thesis appendix A.1): registry, kinematics
 * engine (SPEC section 2, written from the SPEC text, independently of src/robot/delta3.rs),
 * minimum-jerk trajectories and the tick clock. See mock_robotics.h.
 */
#include "mock_robotics.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define MR_PI 3.14159265358979323846

const char *mr_status_str(MrStatus status)
{
    switch (status) {
    case MR_OK: return "ok";
    case MR_NON_FINITE: return "non-finite input";
    case MR_OUT_OF_REACH: return "out of reach";
    case MR_MOTOR_LIMIT: return "motor limit";
    case MR_NO_SOLUTION: return "no forward solution";
    case MR_NOT_FOUND: return "not found";
    case MR_IO: return "file not readable";
    case MR_PARSE: return "malformed line";
    case MR_FULL: return "table full";
    }
    return "unknown mock status";
}

static void copy_name(char dst[MR_NAME_LEN], const char *src)
{
    size_t n = strlen(src);
    if (n >= MR_NAME_LEN) {
        n = MR_NAME_LEN - 1;
    }
    memcpy(dst, src, n);
    dst[n] = '\0';
}

/* ---------------------------------------------------------------- registry */

MrRobot mr_thesis_robot(const char *name, double alpha, double tx, double ty, double tz)
{
    MrRobot r;
    memset(&r, 0, sizeof r);
    copy_name(r.name, name);
    r.geometry.f = 100.0;
    r.geometry.rf = 150.0;
    r.geometry.re = 400.0;
    r.geometry.e = 40.0;
    r.geometry.theta_min = -MR_PI / 2.0;
    r.geometry.theta_max = 2.0 * MR_PI / 3.0;
    r.half_height = 70.0;
    r.half_depth = 17.5;
    r.margin = 0.0;
    r.alpha = alpha;
    r.translation[0] = tx;
    r.translation[1] = ty;
    r.translation[2] = tz;
    return r;
}

/* The reference cells of SPEC section 5 (same values as cells/t1.toml .. t3.toml). */
typedef struct CellRow {
    const char *name;
    double alpha_b;
    double t_b[3];
} CellRow;

static const CellRow CELL_TABLE[] = {
    { "T1", 0.0, { 450.0, 0.0, 0.0 } },
    { "T2", 0.0, { 400.0, 0.0, 0.0 } },
    { "T3", MR_PI / 6.0, { 430.0, 150.0, 0.0 } },
};

MrStatus mr_register_cell(const char *name, MrCell *out)
{
    size_t i;
    for (i = 0; i < sizeof CELL_TABLE / sizeof CELL_TABLE[0]; ++i) {
        const CellRow *row = &CELL_TABLE[i];
        if (strcmp(row->name, name) == 0) {
            memset(out, 0, sizeof *out);
            copy_name(out->name, name);
            out->n_robots = 2;
            out->robots[0] = mr_thesis_robot("A", 0.0, 0.0, 0.0, 0.0);
            out->robots[1] = mr_thesis_robot("B", row->alpha_b, row->t_b[0], row->t_b[1], row->t_b[2]);
            return MR_OK;
        }
    }
    if (strcmp(name, "line4") == 0) {
        /* The packaging line of cells/line4.toml: four robots along x, 450 mm apart as in T1. */
        static const char *names[4] = { "R1", "R2", "R3", "R4" };
        size_t j;
        memset(out, 0, sizeof *out);
        copy_name(out->name, name);
        out->n_robots = 4;
        for (j = 0; j < 4; ++j) {
            out->robots[j] = mr_thesis_robot(names[j], 0.0, 450.0 * (double)j, 0.0, 0.0);
        }
        return MR_OK;
    }
    return MR_NOT_FOUND;
}

/* ---------------------------------------------------------------- kinematics */

/* Radial unit u_i of arm i: azimuth phi_i = i 2 pi / 3. */
static void arm_radial(int arm, double *ux, double *uy)
{
    double phi = (double)arm * 2.0 * MR_PI / 3.0;
    *ux = cos(phi);
    *uy = sin(phi);
}

/* Wraps an angle to (-pi, pi]. */
static double wrap_angle(double th)
{
    while (th <= -MR_PI) {
        th += 2.0 * MR_PI;
    }
    while (th > MR_PI) {
        th -= 2.0 * MR_PI;
    }
    return th;
}

MrStatus mr_inverse_kinematics(const MrGeometry *g, const double tcp[3], double theta[3])
{
    int arm;
    if (!isfinite(tcp[0]) || !isfinite(tcp[1]) || !isfinite(tcp[2])) {
        return MR_NON_FINITE;
    }
    for (arm = 0; arm < 3; ++arm) {
        double ux, uy, ex, ey, ez, px, py, pz, a, b, c, k, r, base, delta, th1, th2, th;
        arm_radial(arm, &ux, &uy);
        /* E_i = p + e u_i, F_i = f u_i, P = E_i - F_i. */
        ex = tcp[0] + g->e * ux;
        ey = tcp[1] + g->e * uy;
        ez = tcp[2];
        px = ex - g->f * ux;
        py = ey - g->f * uy;
        pz = ez;
        /* Components along u_i, t_i = (-uy, ux, 0) and z. */
        a = px * ux + py * uy;
        b = -px * uy + py * ux;
        c = pz;
        r = sqrt(a * a + c * c);
        if (b * b > g->re * g->re || r == 0.0) {
            return MR_OUT_OF_REACH;
        }
        k = (a * a + c * c + g->rf * g->rf - (g->re * g->re - b * b)) / (2.0 * g->rf);
        if (fabs(k) > r) {
            return MR_OUT_OF_REACH;
        }
        base = -atan2(c, a);
        delta = acos(k / r);
        th1 = wrap_angle(base + delta);
        th2 = wrap_angle(base - delta);
        th = cos(th1) >= cos(th2) ? th1 : th2; /* elbow-out: the larger cos */
        if (th < g->theta_min || th > g->theta_max) {
            return MR_MOTOR_LIMIT;
        }
        theta[arm] = th;
    }
    return MR_OK;
}

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void cross3(const double a[3], const double b[3], double out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

MrStatus mr_forward_kinematics(const MrGeometry *g, const double theta[3], double tcp[3])
{
    /* Sphere centres C_i = G_i - e u_i, all of radius re. Classic trilateration in the frame
     * (ex, ey, ez) with C_0 at the origin and C_1 on ex. */
    double cen[3][3], ex[3], ey[3], ez[3], d10[3], d20[3], d, i, j, x, y, z2, z, nrm;
    int arm, k;
    for (arm = 0; arm < 3; ++arm) {
        double ux, uy, radial;
        if (!isfinite(theta[arm])) {
            return MR_NON_FINITE;
        }
        arm_radial(arm, &ux, &uy);
        radial = g->f + g->rf * cos(theta[arm]) - g->e;
        cen[arm][0] = radial * ux;
        cen[arm][1] = radial * uy;
        cen[arm][2] = -g->rf * sin(theta[arm]);
    }
    for (k = 0; k < 3; ++k) {
        d10[k] = cen[1][k] - cen[0][k];
        d20[k] = cen[2][k] - cen[0][k];
    }
    d = sqrt(dot3(d10, d10));
    if (!(d > 0.0)) {
        return MR_NO_SOLUTION;
    }
    for (k = 0; k < 3; ++k) {
        ex[k] = d10[k] / d;
    }
    i = dot3(ex, d20);
    for (k = 0; k < 3; ++k) {
        ey[k] = d20[k] - i * ex[k];
    }
    nrm = sqrt(dot3(ey, ey));
    if (!(nrm > 0.0)) {
        return MR_NO_SOLUTION;
    }
    for (k = 0; k < 3; ++k) {
        ey[k] /= nrm;
    }
    cross3(ex, ey, ez);
    j = dot3(ey, d20);
    /* Equal radii: x = d / 2, y = (i^2 + j^2 - 2 i x) / (2 j). */
    x = 0.5 * d;
    y = (i * i + j * j - 2.0 * i * x) / (2.0 * j);
    z2 = g->re * g->re - x * x - y * y;
    if (!(z2 >= 0.0)) {
        return MR_NO_SOLUTION;
    }
    z = sqrt(z2);
    /* Two candidates C_0 + x ex + y ey +/- z ez: take the lower one (smaller world z). */
    if (ez[2] > 0.0) {
        z = -z;
    }
    for (k = 0; k < 3; ++k) {
        tcp[k] = cen[0][k] + x * ex[k] + y * ey[k] + z * ez[k];
    }
    return MR_OK;
}

/* ---------------------------------------------------------------- trajectories */

double mr_min_jerk(double tau)
{
    if (tau <= 0.0) {
        return 0.0;
    }
    if (tau >= 1.0) {
        return 1.0;
    }
    return tau * tau * tau * (10.0 + tau * (-15.0 + 6.0 * tau));
}

void mr_trajectory_tcp(const MrTrajectory *traj, long tick, double out[3])
{
    size_t w, last = traj->n_waypoints - 1;
    int k;
    if (tick <= traj->tick[0]) {
        for (k = 0; k < 3; ++k) {
            out[k] = traj->tcp[0][k];
        }
        return;
    }
    for (w = 0; w < last; ++w) {
        long t0 = traj->tick[w], t1 = traj->tick[w + 1];
        if (tick <= t1) {
            double s = mr_min_jerk((double)(tick - t0) / (double)(t1 - t0));
            for (k = 0; k < 3; ++k) {
                out[k] = traj->tcp[w][k] + s * (traj->tcp[w + 1][k] - traj->tcp[w][k]);
            }
            return;
        }
    }
    for (k = 0; k < 3; ++k) {
        out[k] = traj->tcp[last][k];
    }
}

void mr_trajectory_tcp_at(const MrTrajectory *traj, double tick, double out[3])
{
    size_t i;
    int k;
    if (traj->n_waypoints == 0) {
        out[0] = out[1] = out[2] = 0.0;
        return;
    }
    for (i = 0; i + 1 < traj->n_waypoints && tick > (double)traj->tick[i]; ++i) {
        if (tick <= (double)traj->tick[i + 1]) {
            double t0 = (double)traj->tick[i], t1 = (double)traj->tick[i + 1];
            double s = mr_min_jerk((tick - t0) / (t1 - t0));
            for (k = 0; k < 3; ++k) {
                out[k] = traj->tcp[i][k] + s * (traj->tcp[i + 1][k] - traj->tcp[i][k]);
            }
            return;
        }
    }
    /* Before the first waypoint's tick the robot holds it; after the last, the last. */
    memcpy(out, traj->tcp[tick <= (double)traj->tick[0] ? 0 : traj->n_waypoints - 1], 3 * sizeof(double));
}

static double distance3(const double a[3], const double b[3])
{
    return sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

double mr_trajectory_advance(const MrTrajectory *traj, double tick, double distance_mm)
{
    size_t i;
    for (i = 0; i + 1 < traj->n_waypoints; ++i) {
        double t0 = (double)traj->tick[i], t1 = (double)traj->tick[i + 1];
        if (tick >= t0 && tick < t1) {
            double length = distance3(traj->tcp[i], traj->tcp[i + 1]);
            double lo = (tick - t0) / (t1 - t0), hi = 1.0, target;
            int n;
            if (length <= 0.0 || !(distance_mm > 0.0)) {
                return tick;
            }
            /* The segment is straight: the distance along it is length * s(tau). */
            target = mr_min_jerk(lo) + distance_mm / length;
            if (target >= 1.0) {
                return t1;
            }
            for (n = 0; n < 60; ++n) { /* s is increasing: bisect for s(tau) = target */
                double mid = 0.5 * (lo + hi);
                if (mr_min_jerk(mid) < target) {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            return t0 + lo * (t1 - t0);
        }
    }
    return tick;
}

void mr_override_start(const MrTrajectory *traj, MrOverride *o)
{
    o->path_tick = traj->n_waypoints > 0 ? (double)traj->tick[0] : 0.0;
    o->speed = o->cap = 0.0;
    mr_trajectory_tcp_at(traj, o->path_tick, o->tcp);
}

void mr_override_request(MrOverride *o, double wanted_mm_s, double ramp_mm_s2, double dt_s)
{
    double lo = o->speed - ramp_mm_s2 * dt_s, hi = o->speed + ramp_mm_s2 * dt_s;
    double cap = wanted_mm_s < lo ? lo : (wanted_mm_s > hi ? hi : wanted_mm_s);
    o->cap = cap > 0.0 ? cap : 0.0;
}

void mr_override_step(const MrTrajectory *traj, MrOverride *o, double dt_ticks, double dt_s)
{
    double programmed[3], before[3];
    memcpy(before, o->tcp, sizeof before);
    mr_trajectory_tcp_at(traj, o->path_tick + dt_ticks, programmed);
    if (distance3(before, programmed) <= o->cap * dt_s) {
        o->path_tick += dt_ticks;
        memcpy(o->tcp, programmed, sizeof programmed);
    } else {
        o->path_tick = mr_trajectory_advance(traj, o->path_tick, o->cap * dt_s);
        mr_trajectory_tcp_at(traj, o->path_tick, o->tcp);
    }
    o->speed = distance3(before, o->tcp) / dt_s;
}

/* Whether the robot holds waypoint tick `tick` exactly (the end of a braking segment). */
static int at_waypoint(const MrTrajectory *traj, double tick)
{
    size_t i;
    for (i = 0; i < traj->n_waypoints; ++i) {
        if ((double)traj->tick[i] == tick) {
            return 1;
        }
    }
    return 0;
}

size_t mr_path_ahead(const MrTrajectory *traj, double tick, double length_mm, double out[][3], size_t capacity)
{
    size_t i, n = 0;
    double length = 0.0;
    if (capacity == 0) {
        return 0;
    }
    mr_trajectory_tcp_at(traj, tick, out[n++]);
    for (i = 0; i < traj->n_waypoints && n < capacity && length < length_mm; ++i) {
        if ((double)traj->tick[i] > tick) {
            length += distance3(out[n - 1], traj->tcp[i]);
            memcpy(out[n++], traj->tcp[i], sizeof out[0]);
        }
    }
    return n;
}

void mr_stop_start(const MrOverride *now, double reaction_ms, double decel_mm_s2, MrStop *stop)
{
    stop->o = *now;
    stop->reaction_ms = reaction_ms;
    stop->decel_mm_s2 = decel_mm_s2;
    stop->elapsed_ms = 0.0;
    stop->moving = 1;
}

int mr_stop_step(const MrTrajectory *traj, MrStop *stop, double dt_ms)
{
    MrOverride *o = &stop->o;
    double next, end_tick;
    if (!stop->moving) {
        return 0;
    }
    stop->elapsed_ms += dt_ms;
    if (stop->elapsed_ms <= stop->reaction_ms) {
        mr_override_step(traj, o, dt_ms, dt_ms * 1e-3);
        return 1;
    }
    if (stop->elapsed_ms - dt_ms <= stop->reaction_ms) {
        o->cap = o->speed; /* braking starts from the speed the reaction ended at */
    }
    next = o->cap - stop->decel_mm_s2 * dt_ms * 1e-3;
    next = next > 0.0 ? next : 0.0;
    end_tick = o->cap > 0.0 ? mr_trajectory_advance(traj, o->path_tick, 0.5 * (o->cap + next) * dt_ms * 1e-3)
                            : o->path_tick;
    /* Holding a waypoint, or at the segment's end: the path-maintaining stop is over. */
    if (end_tick == o->path_tick || at_waypoint(traj, end_tick)) {
        next = 0.0;
    }
    o->path_tick = end_tick;
    mr_trajectory_tcp_at(traj, end_tick, o->tcp);
    o->cap = o->speed = next;
    stop->moving = next > 0.0;
    return stop->moving;
}

MrStatus mr_pick_place_programme(const MrCell *cell, size_t robot, size_t other, int cycles, MrTrajectory *out)
{
    /* One cycle: (tick within the cycle, at the place point?, z). */
    static const struct {
        long tick;
        int at_place;
        double z;
    } legs[] = {
        { 80, 0, MR_PICK_Z },    /* dwell at the pick */
        { 180, 0, MR_TRAVEL_Z }, /* lift */
        { 430, 1, MR_TRAVEL_Z }, /* over the place point */
        { 530, 1, MR_PLACE_Z },  /* down */
        { 580, 1, MR_PLACE_Z },  /* dwell at the place */
        { 680, 1, MR_TRAVEL_Z }, /* lift */
        { 900, 0, MR_TRAVEL_Z }, /* back over the pick point */
        { 1000, 0, MR_PICK_Z },  /* down */
    };
    const size_t n_legs = sizeof legs / sizeof legs[0];
    const MrRobot *r;
    double dx, dy, d, ux, uy, c, s, theta[3];
    size_t w;
    if (robot >= cell->n_robots || other >= cell->n_robots || robot == other) {
        return MR_NOT_FOUND;
    }
    if (cycles < 1 || 1 + (size_t)cycles * n_legs > MR_MAX_WAYPOINTS) {
        return MR_FULL;
    }
    r = &cell->robots[robot];
    dx = cell->robots[other].translation[0] - r->translation[0];
    dy = cell->robots[other].translation[1] - r->translation[1];
    d = sqrt(dx * dx + dy * dy);
    if (!(d > 0.0)) {
        return MR_NOT_FOUND;
    }
    /* The direction to the other base in this robot's MCS: Rz(-alpha) applied. */
    c = cos(r->alpha);
    s = sin(r->alpha);
    ux = (c * dx + s * dy) / d;
    uy = (-s * dx + c * dy) / d;
    memset(out, 0, sizeof *out);
    out->n_waypoints = 1 + (size_t)cycles * n_legs;
    out->tick[0] = 0;
    out->tcp[0][0] = -MR_PICK_FAR_MM * ux;
    out->tcp[0][1] = -MR_PICK_FAR_MM * uy;
    out->tcp[0][2] = MR_PICK_Z;
    for (w = 1; w < out->n_waypoints; ++w) {
        size_t leg = (w - 1) % n_legs;
        double along = legs[leg].at_place ? 0.5 * d : -MR_PICK_FAR_MM;
        out->tick[w] = (long)((w - 1) / n_legs) * MR_PICK_PLACE_TICKS + legs[leg].tick;
        out->tcp[w][0] = along * ux;
        out->tcp[w][1] = along * uy;
        out->tcp[w][2] = legs[leg].z;
    }
    for (w = 0; w < out->n_waypoints; ++w) {
        MrStatus st = mr_inverse_kinematics(&r->geometry, out->tcp[w], theta);
        if (st != MR_OK) {
            return st;
        }
    }
    return MR_OK;
}

MrStatus mr_load_scenario(const char *path, const char *cell, const char *name, size_t n_robots,
                          MrScenario *out)
{
    FILE *file;
    char line[256];
    long line_no = 0;
    size_t j;
    MrStatus status = MR_OK;
    if (n_robots == 0 || n_robots > MR_MAX_ROBOTS) {
        return MR_FULL;
    }
    file = fopen(path, "r");
    if (file == NULL) {
        return MR_IO;
    }
    memset(out, 0, sizeof *out);
    copy_name(out->cell, cell);
    copy_name(out->name, name);
    out->n_robots = n_robots;
    while (fgets(line, sizeof line, file) != NULL) {
        char c_cell[MR_NAME_LEN], c_case[MR_NAME_LEN], extra[2];
        char *hash = strchr(line, '#');
        int robot, fields;
        long tick;
        double x, y, z;
        MrTrajectory *traj;
        ++line_no;
        if (hash != NULL) {
            *hash = '\0';
        }
        if (sscanf(line, " %1s", extra) != 1) {
            continue; /* blank or comment */
        }
        fields = sscanf(line, "%31s %31s %d %ld %lf %lf %lf %1s", c_cell, c_case, &robot, &tick, &x, &y,
                        &z, extra);
        if (fields != 7) {
            fprintf(stderr, "%s:%ld: expected `CELL CASE ROBOT TICK X Y Z`\n", path, line_no);
            status = MR_PARSE;
            break;
        }
        if (strcmp(c_cell, cell) != 0 || strcmp(c_case, name) != 0) {
            continue;
        }
        if (robot < 0 || (size_t)robot >= n_robots || tick < 0 || !isfinite(x) || !isfinite(y)
            || !isfinite(z)) {
            fprintf(stderr, "%s:%ld: robot index or waypoint out of range\n", path, line_no);
            status = MR_PARSE;
            break;
        }
        traj = &out->robots[robot];
        if (traj->n_waypoints == MR_MAX_WAYPOINTS) {
            status = MR_FULL;
            break;
        }
        if (traj->n_waypoints > 0 && tick <= traj->tick[traj->n_waypoints - 1]) {
            fprintf(stderr, "%s:%ld: ticks of a robot must increase\n", path, line_no);
            status = MR_PARSE;
            break;
        }
        traj->tick[traj->n_waypoints] = tick;
        traj->tcp[traj->n_waypoints][0] = x;
        traj->tcp[traj->n_waypoints][1] = y;
        traj->tcp[traj->n_waypoints][2] = z;
        traj->n_waypoints++;
    }
    fclose(file);
    if (status != MR_OK) {
        return status;
    }
    for (j = 0; j < n_robots; ++j) {
        if (out->robots[j].n_waypoints == 0) {
            return MR_NOT_FOUND;
        }
    }
    return MR_OK;
}

MrStatus mr_robot_state(const MrCell *cell, const MrScenario *scenario, long tick,
                        const int stopped[MR_MAX_ROBOTS],
                        const double held_tcp[MR_MAX_ROBOTS][3], MrTickState *state)
{
    MrStatus first = MR_OK;
    size_t j;
    int k;
    for (j = 0; j < cell->n_robots; ++j) {
        MrStatus s;
        if (stopped != NULL && stopped[j]) {
            for (k = 0; k < 3; ++k) {
                state->commanded[j][k] = held_tcp[j][k];
            }
        } else {
            mr_trajectory_tcp(&scenario->robots[j], tick, state->commanded[j]);
        }
        s = mr_inverse_kinematics(&cell->robots[j].geometry, state->commanded[j], state->theta[j]);
        if (s == MR_OK) {
            s = mr_forward_kinematics(&cell->robots[j].geometry, state->theta[j], state->tcp[j]);
        }
        if (s != MR_OK) {
            for (k = 0; k < 3; ++k) {
                state->tcp[j][k] = state->commanded[j][k];
            }
            if (first == MR_OK) {
                first = s;
            }
        }
        state->status[j] = s;
    }
    return first;
}

/* ---------------------------------------------------------------- clock */

void mr_clock_start(MrClock *clock)
{
    clock->tick = 0;
    clock->period_us = MR_TICK_PERIOD_US;
}

void mr_clock_advance(MrClock *clock)
{
    clock->tick += 1;
}
