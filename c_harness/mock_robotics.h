/*
 * mock_robotics.h: a mock of the controller's robotics API (thesis appendix A.1).
 *
 * On the NJ-controller the collision project reaches the kinematics engine and the robot
 * set-up through a small "robotics API". This mock stands in for it on a desktop:
 *   - a robot registry: robots with their Delta3 geometry, box sizes and placement
 *     (SPEC section 1, 2, 3), filled from a hard-coded table of the reference cells
 *     T1, T2, T3 (SPEC section 5) and the four-robot line of cells/line4.toml;
 *   - its own kinematics engine in C (SPEC section 2), written independently of the Rust
 *     one so that the harness can cross-check the two;
 *   - a trajectory generator: linear moves between waypoints with the minimum-jerk
 *     profile s(tau) = 10 tau^3 - 15 tau^4 + 6 tau^5, read from c_harness/scenarios.txt,
 *     or generated (pick-and-place programmes for the coordination);
 *   - a 1 ms tick clock.
 * Units: mm and rad everywhere. TCPs are in each robot's own MCS.
 * C99, no VLAs, no dynamic allocation: every buffer is a fixed-size array.
 */
#ifndef MOCK_ROBOTICS_H
#define MOCK_ROBOTICS_H

#include <stddef.h>

#define MR_MAX_ROBOTS 4
#define MR_MAX_WAYPOINTS 64
#define MR_TICKS_PER_RUN 6000
#define MR_TICK_PERIOD_US 1000
#define MR_NAME_LEN 32

/* Status of a mock call. */
typedef enum MrStatus {
    MR_OK = 0,
    MR_NON_FINITE = 1,   /* an input is NaN or infinite */
    MR_OUT_OF_REACH = 2, /* an arm cannot close its loop (b^2 > re^2 or |K| > R) */
    MR_MOTOR_LIMIT = 3,  /* the elbow-out angle is outside the motor limits */
    MR_NO_SOLUTION = 4,  /* forward kinematics: the three spheres do not meet */
    MR_NOT_FOUND = 5,    /* unknown cell, case or robot */
    MR_IO = 6,           /* a file could not be read */
    MR_PARSE = 7,        /* a line of a file is malformed */
    MR_FULL = 8          /* a fixed-size table is full */
} MrStatus;

/* Delta3 geometry (SPEC section 2). */
typedef struct MrGeometry {
    double f, rf, re, e;
    double theta_min, theta_max;
} MrGeometry;

/* One registered robot: geometry, box model sizes and placement p_wcs = Rz(alpha) p_mcs + t. */
typedef struct MrRobot {
    char name[MR_NAME_LEN];
    MrGeometry geometry;
    double half_height; /* H of a lower link box */
    double half_depth;  /* D of a lower link box */
    double margin;
    double alpha;
    double translation[3];
} MrRobot;

/* A cell: the registry of robots the controller drives. */
typedef struct MrCell {
    char name[MR_NAME_LEN];
    size_t n_robots;
    MrRobot robots[MR_MAX_ROBOTS];
} MrCell;

/* The trajectory of one robot: waypoints (tick, TCP in its MCS) in increasing tick order. */
typedef struct MrTrajectory {
    size_t n_waypoints;
    long tick[MR_MAX_WAYPOINTS];
    double tcp[MR_MAX_WAYPOINTS][3];
} MrTrajectory;

/* A scenario: one cell and case, one trajectory per robot. */
typedef struct MrScenario {
    char cell[MR_NAME_LEN];
    char name[MR_NAME_LEN];
    size_t n_robots;
    MrTrajectory robots[MR_MAX_ROBOTS];
} MrScenario;

/* The tick clock of the controller's motion task. */
typedef struct MrClock {
    long tick;
    long period_us;
} MrClock;

/* Short text for a status. */
const char *mr_status_str(MrStatus status);

/* Registry: fills *out with the reference cell "T1", "T2" or "T3", or the line "line4". */
MrStatus mr_register_cell(const char *name, MrCell *out);

/* The thesis robot (f 100, rf 150, re 400, e 40, limits [-pi/2, 2pi/3], H 70, D 17.5). */
MrRobot mr_thesis_robot(const char *name, double alpha, double tx, double ty, double tz);

/* Elbow-out inverse kinematics: motor angles theta[3] in (-pi, pi] for a TCP in the MCS. */
MrStatus mr_inverse_kinematics(const MrGeometry *g, const double tcp[3], double theta[3]);

/* Forward kinematics: the lower intersection of the three spheres, the TCP in the MCS. */
MrStatus mr_forward_kinematics(const MrGeometry *g, const double theta[3], double tcp[3]);

/* Minimum-jerk profile s(tau) = 10 tau^3 - 15 tau^4 + 6 tau^5, tau clamped to [0, 1]. */
double mr_min_jerk(double tau);

/* Commanded TCP of a trajectory at a tick: holds the first waypoint before its tick, moves
 * linearly (min-jerk in time) between consecutive waypoints, holds the last one after it. */
void mr_trajectory_tcp(const MrTrajectory *traj, long tick, double out[3]);

/* The commanded TCP at a fractional tick: mr_trajectory_tcp's profile in continuous time. */
void mr_trajectory_tcp_at(const MrTrajectory *traj, double tick, double out[3]);

/* The tick `tick` moved forward by `distance_mm` along the straight segment it lies on, never
 * past the segment's end (the next waypoint); unchanged where the robot holds a waypoint. */
double mr_trajectory_advance(const MrTrajectory *traj, double tick, double distance_mm);

/* Speed override of one robot (SPEC section 8, "What physics allows"): the robot follows its
 * programmed path, but its progress along it is a parameter of its own (path_tick, in
 * programmed ticks) that advances at the programmed speed or at the override's speed cap,
 * whichever is lower. The cap moves toward the speed the controller asks for by at most
 * `ramp_mm_s2` per second, so slowing down and speeding up stay within the robot's
 * acceleration limit. */
typedef struct MrOverride {
    double path_tick; /* progress along the programmed path (programmed ticks) */
    double speed;     /* TCP speed over the last step (mm/s) */
    double cap;       /* speed cap of the next step (mm/s) */
    double tcp[3];    /* TCP now (MCS, mm) */
} MrOverride;

/* A robot standing at its first waypoint, its cap at 0. */
void mr_override_start(const MrTrajectory *traj, MrOverride *o);

/* Sets the cap of the next step toward `wanted_mm_s` (>= 0), at most `ramp_mm_s2 * dt_s`
 * away from the current speed. */
void mr_override_request(MrOverride *o, double wanted_mm_s, double ramp_mm_s2, double dt_s);

/* One step of `dt_ticks` programmed ticks (`dt_s` seconds): the programmed motion when its
 * displacement is within `cap * dt_s`, else `cap * dt_s` along the path (never past the
 * segment's end). */
void mr_override_step(const MrTrajectory *traj, MrOverride *o, double dt_ticks, double dt_s);

/* The programmed path ahead of `tick`, as a controller performing a path-maintaining stop
 * knows it: the commanded TCP at `tick`, then the following waypoints until `capacity` points
 * are written or the path is at least `length_mm` long. Returns the number of points. */
size_t mr_path_ahead(const MrTrajectory *traj, double tick, double length_mm, double out[][3], size_t capacity);

/* A path-maintaining stop of one robot (SPEC section 8): from the STOP it keeps its motion for
 * reaction_ms (the programmed motion, capped at the override cap it had: INFINITY for none),
 * then brakes along its path, its speed falling by decel_mm_s2 per second, until it stands
 * still; it never passes the end of the straight segment it brakes on (the next waypoint). */
typedef struct MrStop {
    MrOverride o;       /* the robot now; o.speed is the speed braking starts from */
    double reaction_ms; /* from the STOP to the start of braking */
    double decel_mm_s2;
    double elapsed_ms;  /* since the STOP */
    int moving;
} MrStop;

/* A stop starting from the robot's state `now` (copied). */
void mr_stop_start(const MrOverride *now, double reaction_ms, double decel_mm_s2, MrStop *stop);

/* Advances the stop by dt_ms; returns nonzero while the robot still moves. */
int mr_stop_step(const MrTrajectory *traj, MrStop *stop, double dt_ms);

/* Pick-and-place programmes for the coordination (coordination.c): cycles of
 * MR_PICK_PLACE_TICKS ticks, every robot at the same ticks. Robot `robot` picks on its far side
 * from robot `other` (MR_PICK_FAR_MM from its base axis, away from the other base, at
 * MR_PICK_Z), lifts to MR_TRAVEL_Z, moves over the midpoint between the two bases, places there
 * (MR_PLACE_Z, a dwell), lifts, moves back and picks again; it ends at its pick point. Two
 * robots given each other as `other` thus place at the same point at the same ticks: executed
 * as programmed they collide. On T1 no move accelerates faster than 45 m/s^2 (min-jerk: 5.77
 * times the distance over the duration squared), leaving room within the stopping model's
 * max_accel_mm_s2 for the override's own changes. Returns MR_FULL when `cycles` do not fit MR_MAX_WAYPOINTS, the
 * kinematics status of a waypoint the robot cannot reach, else MR_OK. */
#define MR_PICK_PLACE_TICKS 1000
#define MR_PICK_FAR_MM 150.0
#define MR_PICK_Z (-470.0)
#define MR_TRAVEL_Z (-400.0)
#define MR_PLACE_Z (-440.0)
MrStatus mr_pick_place_programme(const MrCell *cell, size_t robot, size_t other, int cycles, MrTrajectory *out);

/* Reads the scenario (cell, case) from a scenarios file (format at the top of the file).
 * Every robot 0..n_robots-1 must have at least one waypoint. */
MrStatus mr_load_scenario(const char *path, const char *cell, const char *name, size_t n_robots,
                          MrScenario *out);

/* Robotics API view of one tick: for each robot, the commanded TCP from its trajectory,
 * the motor angles from the C inverse kinematics, and the TCP the forward kinematics
 * delivers back (what the collision project reads). Robots with stopped[j] != 0 hold
 * held_tcp[j] instead of following the trajectory. */
typedef struct MrTickState {
    double commanded[MR_MAX_ROBOTS][3];
    double theta[MR_MAX_ROBOTS][3];
    double tcp[MR_MAX_ROBOTS][3];
    MrStatus status[MR_MAX_ROBOTS];
} MrTickState;

/* Fills *state for one tick; returns the first non-OK status of any robot (MR_OK if none). */
MrStatus mr_robot_state(const MrCell *cell, const MrScenario *scenario, long tick,
                        const int stopped[MR_MAX_ROBOTS],
                        const double held_tcp[MR_MAX_ROBOTS][3], MrTickState *state);

/* Clock: starts at tick 0 with a 1 ms period; advance moves one tick. */
void mr_clock_start(MrClock *clock);
void mr_clock_advance(MrClock *clock);

#endif /* MOCK_ROBOTICS_H */
